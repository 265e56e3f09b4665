#include "verify/mujoco_world.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <mutex>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "contact/kinematics.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::verify {

namespace {

// MuJoCo's error handler would exit the process and its warning handler print to standard
// output: an error becomes an exception, a warning is counted from mjData::warning instead.
void onMujocoError(const char* message) { throw std::runtime_error(std::string("MuJoCo: ") + message); }
void onMujocoWarning(const char*) {}

void installMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = onMujocoError;
    mju_user_warning = onMujocoWarning;
  });
}

std::string numbers(std::initializer_list<double> values) {
  std::ostringstream s;
  s.precision(17);
  bool first = true;
  for (double x : values) {
    s << (first ? "" : " ") << x;
    first = false;
  }
  return s.str();
}

std::string vec(const Eigen::Vector3d& x) { return numbers({x[0], x[1], x[2]}); }

// MuJoCo's quaternion (w x y z) of a rotation matrix.
std::string quat(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return numbers({q.w(), q.x(), q.y(), q.z()});
}

long warningCount(const mjData* d) {
  long n = 0;
  for (int i = 0; i < mjNWARNING; ++i) n += d->warning[i].number;
  return n;
}

}  // namespace

double dampingRatioForRestitution(double e) {
  if (!(e >= 0 && e <= 1)) throw std::invalid_argument("restitution must be in [0, 1]");
  if (e <= 0) return 1.0;
  if (e >= 1) return 0.0;
  const double l = std::log(e);
  return -l / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
}

MujocoWorld::MujocoWorld(const scene::Scene& scene, MujocoWorldOptions options)
    : scene_(scene), pairs_(contact::contactPairs(scene)), options_(options), data_(scene.model) {
  installMujocoHandlers();
  const dynamics::Model<double>& model = scene.model;
  const std::string where = "MujocoWorld: scene " + scene.name + ": ";
  if (!(options.dt > 0) || !std::isfinite(options.dt)) throw std::invalid_argument(where + "dt must be positive");
  if (model.base == dynamics::BaseType::Free)
    throw std::invalid_argument(where + "a free base of Euler angles has no MuJoCo joint; use base: free_quaternion "
                                        "(MuJoCo's free joint: the same quaternion and velocities)");
  for (const scene::Surface& s : scene.surfaces)
    if (!s.velocity_schedule.empty())
      throw std::invalid_argument(where + "surface '" + s.name + "' moves (a belt); MuJoCo has no moving-plane contact");

  // The contact spring, per unit of effective mass (MuJoCo's solref given as (−k, −b)): natural
  // frequency ω = 1 / (timeconst_steps · dt), damping b = 2 ζ ω for the restitution's ζ.
  const double r = options.contact_radius, tau = options.timeconst_steps * options.dt, d = options.impedance;
  const double omega = 1 / tau;
  const auto solref = [&](double e) { return numbers({-omega * omega, -2 * dampingRatioForRestitution(e) * omega}); };
  const std::string solimp = numbers({d, d, 0.001});

  // Bodies as nested MJCF, each with its joints, inertia and contact spheres.
  std::vector<std::vector<int>> children(static_cast<std::size_t>(model.nbodies()));
  std::vector<int> roots;
  for (int i = 0; i < model.nbodies(); ++i) (model.parent[i] < 0 ? roots : children[model.parent[i]]).push_back(i);
  std::ostringstream xml;
  xml.precision(17);
  const auto joint = [&](int k, const char* type, const Eigen::Vector3d& axis) {
    xml << "<joint name=\"" << model.coordinate_name[k] << "\" type=\"" << type << "\" axis=\"" << vec(axis) << "\"";
    // The stops of this coordinate (joint_limits: true): MuJoCo's range, one spring for both sides.
    double lower = -std::numeric_limits<double>::infinity(), upper = std::numeric_limits<double>::infinity(), e = 0;
    for (const scene::LimitStop& s : scene.limits)
      if (s.coordinate == k) {
        (s.upper ? upper : lower) = s.limit;
        e = std::max(e, s.restitution);
      }
    if (std::isfinite(lower) || std::isfinite(upper))
      xml << " limited=\"true\" range=\"" << numbers({std::isfinite(lower) ? lower : -1e10, std::isfinite(upper) ? upper : 1e10})
          << "\" solreflimit=\"" << solref(e) << "\" solimplimit=\"" << solimp << "\"";
    xml << "/>";
  };
  const std::function<void(int)> body = [&](int i) {
    const dynamics::Transform<double>& X = model.X_tree[i];
    xml << "<body name=\"" << model.body_name[i] << "\" pos=\"" << vec(X.r) << "\" quat=\"" << quat(X.E.transpose()) << "\">";
    const int k0 = model.first_coordinate[i];
    switch (model.joint_type[i]) {
      case dynamics::JointType::Revolute: joint(k0, "hinge", model.axis[i]); break;
      case dynamics::JointType::Prismatic: joint(k0, "slide", model.axis[i]); break;
      case dynamics::JointType::Planar:
        joint(k0, "slide", Eigen::Vector3d::UnitX());
        joint(k0 + 1, "slide", Eigen::Vector3d::UnitZ());
        joint(k0 + 2, "hinge", Eigen::Vector3d::UnitY());
        break;
      case dynamics::JointType::FreeQuaternion:  // qpos (p, quaternion), qvel (ṗ world, ω body): saltus' own
        xml << "<freejoint name=\"base\"/>";
        break;
      case dynamics::JointType::Free: break;  // refused above
    }
    const dynamics::RigidInertia<double>& I = model.inertia[i];
    double mass = I.m;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    Eigen::Matrix3d Ic = Eigen::Matrix3d::Identity() * 1e-12;
    if (mass > 0) {
      c = I.h / mass;
      const Eigen::Matrix3d cx = dynamics::skew(c);
      Ic = I.I + mass * cx * cx;
    } else {
      mass = 1e-9;
      approximations_.push_back("massless body '" + model.body_name[i] + "' given 1e-9 kg (MuJoCo needs mass on moving bodies)");
    }
    // A point mass has no rotational inertia, which MuJoCo refuses: 1e-9 kg m² about each axis
    // (felt only if the body turns).
    if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Ic).eigenvalues().minCoeff() < 1e-9) {
      Ic += Eigen::Matrix3d::Identity() * 1e-9;
      approximations_.push_back("body '" + model.body_name[i] + "' given 1e-9 kg m^2 of rotational inertia (a point mass)");
    }
    xml << "<inertial pos=\"" << vec(c) << "\" mass=\"" << mass << "\" fullinertia=\""
        << numbers({Ic(0, 0), Ic(1, 1), Ic(2, 2), Ic(0, 1), Ic(0, 2), Ic(1, 2)}) << "\"/>";
    for (std::size_t c_i = 0; c_i < scene.contacts.size(); ++c_i) {
      const scene::Contact& contact = scene.contacts[c_i];
      if (contact.body == i)
        xml << "<geom name=\"contact" << c_i << "\" type=\"sphere\" size=\"" << r << "\" pos=\"" << vec(contact.p_B)
            << "\" contype=\"0\" conaffinity=\"0\" mass=\"0\"/>";
      // A plane fixed in this body: a box whose top face is the plane moved back by the radius,
      // as large as the plane's extent (a point beyond it meets the box's rounded edge).
      if (contact.surface < 0 && contact.plane.body == i) {
        const scene::BodyPlane& p = contact.plane;
        const double depth = std::max({p.extent.x(), p.extent.y(), 10 * r});  // half-thickness
        Eigen::Matrix3d R;
        R << p.tangents.col(0), p.tangents.col(1), p.normal;
        xml << "<geom name=\"plane" << c_i << "\" type=\"box\" size=\"" << numbers({p.extent.x(), p.extent.y(), depth})
            << "\" pos=\"" << vec(p.point - (r + depth) * p.normal) << "\" quat=\"" << quat(R)
            << "\" contype=\"0\" conaffinity=\"0\" mass=\"0\"/>";
      }
    }
    for (int child : children[i]) body(child);
    xml << "</body>";
  };

  const Eigen::Vector3d g = model.gravity;
  xml << "<mujoco model=\"" << scene.name << "\"><compiler angle=\"radian\" inertiafromgeom=\"false\"/>"
      << "<option timestep=\"" << options.dt << "\" gravity=\"" << vec(g) << "\" integrator=\"Euler\" cone=\"pyramidal\""
      << " solver=\"Newton\" iterations=\"" << options.iterations << "\" tolerance=\"" << options.tolerance << "\"/>"
      << "<worldbody>";
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const scene::Surface& surface = scene.surfaces[s];
    xml << "<geom name=\"surface" << s << "\" type=\"plane\" size=\"0 0 1\" pos=\"" << vec(surface.point - r * surface.normal)
        << "\" zaxis=\"" << vec(surface.normal) << "\" contype=\"0\" conaffinity=\"0\"/>";
  }
  for (int root : roots) body(root);
  xml << "</worldbody><contact>";
  for (std::size_t c = 0; c < scene.contacts.size(); ++c) {
    const scene::Contact& contact = scene.contacts[c];
    const bool friction = contact.friction > 0 && contact.directions > 0;
    const std::string other = contact.surface >= 0 ? "surface" + std::to_string(contact.surface) : "plane" + std::to_string(c);
    xml << "<pair geom1=\"contact" << c << "\" geom2=\"" << other << "\" condim=\"" << (friction ? 3 : 1)
        << "\" friction=\"" << numbers({contact.friction, contact.friction, 0, 0, 0}) << "\" solref=\"" << solref(contact.restitution)
        << "\" solimp=\"" << solimp << "\"/>";
  }
  xml << "</contact></mujoco>\n";
  mjcf_ = xml.str();

  // Compiled from memory (a virtual file system of one file).
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), "scene.xml", static_cast<int>(mjcf_.size())) != 0)
    throw std::runtime_error(where + "cannot hold the MJCF model in MuJoCo's virtual file system");
  std::memcpy(vfs->filedata[vfs->nfile - 1], mjcf_.data(), mjcf_.size());
  char error[1000] = "";
  m_ = mj_loadXML("scene.xml", vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!m_) throw std::runtime_error(where + "MuJoCo refused the model: " + error);
  d_ = mj_makeData(m_);

  // Saltus' position and velocity coordinates in qpos and qvel: one each per hinge or slide, seven
  // and six for the free joint (in saltus' order).
  for (int k = 0; k < model.nv(); ++k) {
    if (model.base == dynamics::BaseType::FreeQuaternion && k < 6) {
      const int j = mj_name2id(m_, mjOBJ_JOINT, "base");
      if (k == 0)
        for (int c = 0; c < 7; ++c) qpos_address_.push_back(m_->jnt_qposadr[j] + c);
      dof_address_.push_back(m_->jnt_dofadr[j] + k);
      continue;
    }
    const int j = mj_name2id(m_, mjOBJ_JOINT, model.coordinate_name[k].c_str());
    qpos_address_.push_back(m_->jnt_qposadr[j]);
    dof_address_.push_back(m_->jnt_dofadr[j]);
  }
  for (std::size_t c = 0; c < scene.contacts.size(); ++c)
    pair_geom_.push_back(mj_name2id(m_, mjOBJ_GEOM, ("contact" + std::to_string(c)).c_str()));
  reports_.resize(scene.contacts.size());
  approximations_.push_back("contacts are MuJoCo's soft constraints (a spring of natural frequency " + numbers({omega}) +
                            " rad/s per unit mass, impedance " + numbers({d}) +
                            "): a resting contact sinks, an impact lasts a few steps");
  approximations_.push_back("restitution as the damping ratio of a contact spring (e = exp(-pi zeta / sqrt(1 - zeta^2))), "
                            "not Newton's law");
  approximations_.push_back("friction cone: MuJoCo's pyramid of 4 faces (saltus: the contact's directions)");
  reset(scene.q0, scene.v0, 0);
}

MujocoWorld::~MujocoWorld() {
  if (d_) mj_deleteData(d_);
  if (m_) mj_deleteModel(m_);
}

void MujocoWorld::reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) {
  const int n = scene_.model.nv(), nq = scene_.model.nq();
  if (q.size() != nq || v.size() != n) throw std::invalid_argument("MujocoWorld::reset: state of the wrong size");
  mj_resetData(m_, d_);
  for (int k = 0; k < nq; ++k) d_->qpos[qpos_address_[k]] = q[k];
  for (int k = 0; k < n; ++k) d_->qvel[dof_address_[k]] = v[k];
  d_->time = t;
  mj_forward(m_, d_);
  q_ = q;
  v_ = v;
  t_ = t;
  stats_ = {};
  measure();
  stats_.max_penetration = 0;
}

void MujocoWorld::step() { step(scene_.tau.size() ? scene_.tau : Eigen::VectorXd::Zero(scene_.model.nv())); }

void MujocoWorld::step(const Eigen::VectorXd& tau) {
  const int n = scene_.model.nv();
  if (tau.size() != n) throw std::invalid_argument("MujocoWorld::step: tau of the wrong size");
  mju_zero(d_->qfrc_applied, m_->nv);
  for (int k = 0; k < n; ++k) d_->qfrc_applied[dof_address_[k]] = tau[k];
  // A number that is not finite in qpos, qvel or qacc: MuJoCo warns and resets the state.
  const auto bad = [&] {
    return d_->warning[mjWARN_BADQPOS].number + d_->warning[mjWARN_BADQVEL].number + d_->warning[mjWARN_BADQACC].number;
  };
  const int bad_before = bad();
  mj_step(m_, d_);
  ++stats_.steps;
  stats_.warnings = warningCount(d_);
  t_ = d_->time;
  readState();
  if (bad() > bad_before || !q_.allFinite() || !v_.allFinite()) {
    std::ostringstream s;
    s << "MuJoCo: a position, velocity or acceleration that is not finite at t = " << t_ << " s (MuJoCo reset its state)";
    throw timestepper::SimulationError(s.str(), t_, {}, std::nan(""));
  }
  measure();
}

void MujocoWorld::readState() {
  for (int k = 0; k < scene_.model.nq(); ++k) q_[k] = d_->qpos[qpos_address_[k]];
  for (int k = 0; k < scene_.model.nv(); ++k) v_[k] = d_->qvel[dof_address_[k]];
}

// Gaps and velocities from saltus' kinematics of (q, v); impulses from MuJoCo's contacts.
void MujocoWorld::measure() {
  dynamics::forwardKinematics(scene_.model, data_, q_, v_);
  stats_.max_penetration =
      std::max(stats_.max_penetration, measureContactKinematics(scene_, pairs_, data_, q_.data(), t_, reports_));
  for (std::size_t l = scene_.contacts.size(); l < pairs_.size(); ++l)
    stats_.max_penetration = std::max(stats_.max_penetration, -contact::gap(pairs_[l], data_, q_.data()));

  // mj_contactForce: the force in the contact frame, whose first axis points from geom1 to geom2,
  // on geom2 (geom1 gets the opposite). MuJoCo orders a pair by geom type: the plane first.
  for (int i = 0; i < d_->ncon; ++i) {
    const mjContact& con = d_->contact[i];
    auto it = std::find(pair_geom_.begin(), pair_geom_.end(), con.geom2);
    double sign = 1;
    if (it == pair_geom_.end()) {
      it = std::find(pair_geom_.begin(), pair_geom_.end(), con.geom1);
      sign = -1;
    }
    if (it == pair_geom_.end()) continue;
    const std::size_t c = static_cast<std::size_t>(it - pair_geom_.begin());
    mjtNum f[6];
    mj_contactForce(m_, d_, i, f);
    const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> frame(con.frame);
    const Eigen::Vector3d on_body = sign * (frame.transpose() * Eigen::Vector3d(f[0], f[1], f[2])) * options_.dt;
    const contact::PlaneFrame<double> pf = contact::planeFrame(pairs_[c], data_);
    MujocoContactReport& r = reports_[c];
    r.active = true;
    r.pn += pf.normal.dot(on_body);
    r.pt1 += pf.tangents.col(0).dot(on_body);
    r.pt2 += pf.tangents.col(1).dot(on_body);
  }
}

double MujocoWorld::energy() {
  dynamics::forwardKinematics(scene_.model, data_, q_, v_);
  return dynamics::kineticEnergy(scene_.model, data_) + dynamics::potentialEnergy(scene_.model, data_);
}

}  // namespace saltus::verify
