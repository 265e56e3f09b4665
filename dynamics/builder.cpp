#include "dynamics/builder.hpp"

#include <Eigen/Eigenvalues>
#include <functional>
#include <map>
#include <sstream>

namespace saltus::dynamics {

const char* toString(BaseType base) {
  switch (base) {
    case BaseType::Fixed: return "fixed";
    case BaseType::Planar: return "planar";
    case BaseType::Free: return "free";
    case BaseType::FreeQuaternion: return "free_quaternion";
  }
  return "?";
}

const char* toString(JointType type) {
  switch (type) {
    case JointType::Revolute: return "revolute";
    case JointType::Prismatic: return "prismatic";
    case JointType::Planar: return "planar";
    case JointType::Free: return "free";
    case JointType::FreeQuaternion: return "free_quaternion";
  }
  return "?";
}

std::string checkInertia(double mass, const Eigen::Matrix3d& Ic, bool allow_point_mass) {
  std::ostringstream why;
  if (!(mass > 0) || !std::isfinite(mass)) {
    why << "mass must be positive and finite, got " << mass;
    return why.str();
  }
  if (!Ic.allFinite()) return "inertia has non-finite entries";
  if ((Ic - Ic.transpose()).cwiseAbs().maxCoeff() > 1e-12 * std::max(1.0, Ic.cwiseAbs().maxCoeff()))
    return "inertia matrix is not symmetric";
  if (allow_point_mass && Ic.isZero(0)) return "";
  const Eigen::Vector3d e = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Ic).eigenvalues();
  const double tol = 1e-12 * std::max(1.0, e.cwiseAbs().maxCoeff());
  if (e.minCoeff() <= 0) {
    why << "inertia is not positive definite (principal moments " << e.transpose() << ")";
    return why.str();
  }
  // Principal moments of a physical body satisfy I1 + I2 ≥ I3 for every ordering.
  if (e[0] + e[1] < e[2] - tol) {
    why << "inertia breaks the triangle inequality (principal moments " << e.transpose()
        << ": " << e[0] << " + " << e[1] << " < " << e[2] << ")";
    return why.str();
  }
  return "";
}

ModelBuilder& ModelBuilder::addLink(const std::string& name) {
  LinkSpec link;
  link.name = name;
  return addLink(std::move(link));
}

ModelBuilder& ModelBuilder::addLink(const std::string& name, double mass, const Eigen::Vector3d& com,
                                    const Eigen::Matrix3d& inertia_com) {
  LinkSpec link;
  link.name = name;
  link.has_inertial = true;
  link.mass = mass;
  link.com = com;
  link.inertia_com = inertia_com;
  return addLink(std::move(link));
}

ModelBuilder& ModelBuilder::addLink(LinkSpec link) {
  links_.push_back(std::move(link));
  return *this;
}

ModelBuilder& ModelBuilder::addJoint(JointSpec joint) {
  joints_.push_back(std::move(joint));
  return *this;
}

ModelBuilder& ModelBuilder::addVisual(const std::string& link, Visual visual) {
  const int l = linkIndex(link);
  if (l < 0) fail("visual refers to unknown link '" + link + "'");
  visual.link = link;
  links_[l].visuals.push_back(std::move(visual));
  return *this;
}

ModelBuilder& ModelBuilder::setSource(std::string source) {
  source_ = std::move(source);
  return *this;
}

ModelBuilder& ModelBuilder::requireInertials(bool require) {
  require_inertials_ = require;
  return *this;
}

void ModelBuilder::fail(const std::string& what) const { throw ModelError(source_ + ": " + what); }

int ModelBuilder::linkIndex(const std::string& name) const {
  for (int i = 0; i < static_cast<int>(links_.size()); ++i)
    if (links_[i].name == name) return i;
  return -1;
}

namespace {
struct BodyInProgress {
  int parent;
  JointType type;
  Eigen::Vector3d axis;
  Eigen::Matrix3d R_PJ;  // joint frame in the parent body frame
  Eigen::Vector3d p_PJ;
  std::string body_name;
  std::vector<std::string> coordinate_names;  // one, or those of a base joint
  JointLimits limits;
};
}  // namespace

Model<double> ModelBuilder::build(BaseType base, const Eigen::Vector3d& gravity) const {
  const int nl = static_cast<int>(links_.size());
  std::map<std::string, int> link_of;
  for (int l = 0; l < nl; ++l) {
    if (links_[l].name.empty()) fail("a link has an empty name");
    if (!link_of.emplace(links_[l].name, l).second) fail("link '" + links_[l].name + "' is defined twice");
    if (links_[l].has_inertial && !links_[l].declared_massless) {
      const std::string why = checkInertia(links_[l].mass, links_[l].inertia_com, true);
      if (!why.empty()) fail("link '" + links_[l].name + "': " + why);
      if (!links_[l].com.allFinite()) fail("link '" + links_[l].name + "': centre of mass is not finite");
    }
  }
  if (nl == 0) fail("the model has no links");

  // Topology: each link has at most one parent joint; exactly one root; no cycles.
  std::vector<int> parent_joint(nl, -1);
  std::vector<std::vector<int>> child_joints(nl);
  std::map<std::string, int> joint_names;
  for (int j = 0; j < static_cast<int>(joints_.size()); ++j) {
    const JointSpec& js = joints_[j];
    if (!joint_names.emplace(js.name, j).second) fail("joint '" + js.name + "' is defined twice");
    const auto p = link_of.find(js.parent), c = link_of.find(js.child);
    if (p == link_of.end()) fail("joint '" + js.name + "': parent link '" + js.parent + "' does not exist");
    if (c == link_of.end()) fail("joint '" + js.name + "': child link '" + js.child + "' does not exist");
    if (p->second == c->second) fail("joint '" + js.name + "' connects link '" + js.parent + "' to itself (kinematic loop)");
    if (parent_joint[c->second] >= 0)
      fail("kinematic loop: link '" + js.child + "' is the child of both joint '" +
           joints_[parent_joint[c->second]].name + "' and joint '" + js.name + "'");
    parent_joint[c->second] = j;
    child_joints[p->second].push_back(j);
    if (js.type != LinkJointType::Fixed && !(js.axis.norm() > 1e-12) )
      fail("joint '" + js.name + "': axis must be a non-zero vector");
    if (!js.R_PJ.allFinite() || !js.p_PJ.allFinite() || !js.axis.allFinite())
      fail("joint '" + js.name + "': origin or axis is not finite");
    if ((js.type == LinkJointType::Revolute || js.type == LinkJointType::Prismatic) &&
        js.limits.lower > js.limits.upper)
      fail("joint '" + js.name + "': lower limit " + std::to_string(js.limits.lower) +
           " exceeds upper limit " + std::to_string(js.limits.upper));
  }
  int root = -1;
  for (int l = 0; l < nl; ++l) {
    if (parent_joint[l] >= 0) continue;
    if (root >= 0) fail("links '" + links_[root].name + "' and '" + links_[l].name +
                        "' both have no parent joint: the model must be one connected tree");
    root = l;
  }
  if (root < 0) fail("kinematic loop: every link has a parent joint, so there is no root link");

  // Walk the tree depth first: assign each link a body and its pose in that body.
  Model<double> model;
  model.name = name_;
  model.source = source_;
  model.base = base;
  model.gravity = gravity;
  std::vector<BodyInProgress> bodies;
  auto addBody = [&](int parent, JointType type, const Eigen::Vector3d& axis, const std::string& body,
                     std::vector<std::string> coordinates) {
    bodies.push_back({parent, type, axis, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), body,
                      std::move(coordinates), JointLimits{}});
    return static_cast<int>(bodies.size()) - 1;
  };
  std::vector<int> body_of(nl, -2);
  std::vector<Eigen::Matrix3d> R_BL(nl, Eigen::Matrix3d::Identity());
  std::vector<Eigen::Vector3d> p_BL(nl, Eigen::Vector3d::Zero());
  const std::string& root_name = links_[root].name;
  // A floating base is one multi-coordinate joint from the world to the root link (model.hpp).
  switch (base) {
    case BaseType::Fixed:
      body_of[root] = -1;
      break;
    case BaseType::Planar:
      body_of[root] = addBody(-1, JointType::Planar, Eigen::Vector3d::Zero(), root_name,
                              {"base_x", "base_z", "base_theta"});
      model.n_base = 3;
      break;
    case BaseType::Free:
      body_of[root] = addBody(-1, JointType::Free, Eigen::Vector3d::Zero(), root_name,
                              {"base_x", "base_y", "base_z", "base_yaw", "base_pitch", "base_roll"});
      model.n_base = 6;
      break;
    case BaseType::FreeQuaternion:
      body_of[root] = addBody(-1, JointType::FreeQuaternion, Eigen::Vector3d::Zero(), root_name,
                              {"base_x", "base_y", "base_z", "base_wx", "base_wy", "base_wz"});
      model.n_base = 6;
      break;
  }
  std::vector<int> moving_link_of_body(bodies.size(), -1);
  if (base != BaseType::Fixed) moving_link_of_body[body_of[root]] = root;

  std::function<void(int)> visit = [&](int l) {
    for (int j : child_joints[l]) {
      const JointSpec& js = joints_[j];
      const int c = link_of.at(js.child);
      const Eigen::Matrix3d R_BJ = R_BL[l] * js.R_PJ;
      const Eigen::Vector3d p_BJ = p_BL[l] + R_BL[l] * js.p_PJ;
      if (js.type == LinkJointType::Fixed) {
        body_of[c] = body_of[l];
        R_BL[c] = R_BJ;
        p_BL[c] = p_BJ;
      } else {
        const JointType type = js.type == LinkJointType::Prismatic ? JointType::Prismatic : JointType::Revolute;
        const int b = addBody(body_of[l], type, js.axis.normalized(), js.child, {js.name});
        bodies[b].R_PJ = R_BJ;
        bodies[b].p_PJ = p_BJ;
        bodies[b].limits = js.limits;
        if (js.type == LinkJointType::Continuous) bodies[b].limits.lower = -kInf, bodies[b].limits.upper = kInf;
        moving_link_of_body.push_back(c);
        body_of[c] = b;
      }
      visit(c);
    }
  };
  visit(root);
  for (int l = 0; l < nl; ++l)
    if (body_of[l] == -2)
      fail("kinematic loop: link '" + links_[l].name + "' is not connected to the root link '" + root_name + "'");

  const int nb = static_cast<int>(bodies.size());
  model.inertia.assign(nb, RigidInertia<double>::Zero());
  std::vector<bool> has_inertial(nb, false);
  for (int l = 0; l < nl; ++l) {
    const LinkSpec& ls = links_[l];
    const int b = body_of[l];
    Frame frame;
    frame.name = ls.name;
    frame.body = b;
    frame.R_BF = R_BL[l];
    frame.p_BF = p_BL[l];
    model.frames.push_back(frame);
    for (Visual v : ls.visuals) {
      v.link = ls.name;
      v.body = b;
      v.p_BG = p_BL[l] + R_BL[l] * v.p_BG;
      v.R_BG = R_BL[l] * v.R_BG;
      model.visuals.push_back(v);
    }
    if (b < 0 || !ls.has_inertial) continue;
    const Eigen::Vector3d c_B = p_BL[l] + R_BL[l] * ls.com;
    const Eigen::Matrix3d Ic_B = R_BL[l] * ls.inertia_com * R_BL[l].transpose();
    model.inertia[b] += RigidInertia<double>::FromCom(ls.mass, c_B, Ic_B);
    has_inertial[b] = true;
  }
  std::vector<double> subtree_mass(nb, 0.0);
  for (int b = nb - 1; b >= 0; --b) {
    subtree_mass[b] += model.inertia[b].m;
    if (bodies[b].parent >= 0) subtree_mass[bodies[b].parent] += subtree_mass[b];
  }
  for (int b = 0; b < nb; ++b) {
    const int l = moving_link_of_body[b];
    if (l < 0) continue;
    if (!has_inertial[b] && require_inertials_)
      fail("link '" + links_[l].name + "' moves (joint '" + bodies[b].coordinate_names.front() +
           "') but neither it nor any link fixed to it has an <inertial> element");
    // A massless moving body (no inertial, or one declared with mass 0) needs mass below it: a
    // massless leaf would make the mass matrix singular.
    if (!(subtree_mass[b] > 0))
      fail("link '" + links_[l].name + "' moves (joint '" + bodies[b].coordinate_names.front() +
           "') but " + (has_inertial[b] ? "its <inertial> has no mass" : "has no <inertial> element") +
           ", and no body below it has mass");
  }

  for (int b = 0; b < nb; ++b) {
    const BodyInProgress& bp = bodies[b];
    model.parent.push_back(bp.parent);
    model.joint_type.push_back(bp.type);
    model.axis.push_back(bp.axis);
    model.axis_kind.push_back(axisKind(bp.axis));
    const RigidInertia<double>& I = model.inertia[b];
    model.massless.push_back(I.m == 0 && I.h.isZero(0) && I.I.isZero(0));
    // Parent coordinates -> joint coordinates; multiples of π/2 made exact (snapToSignedPermutation).
    model.X_tree.push_back({snapToSignedPermutation(bp.R_PJ.transpose()), bp.p_PJ});
    model.body_name.push_back(bp.body_name);
    model.num_coordinates.push_back(static_cast<int>(bp.coordinate_names.size()));
    for (const std::string& c : bp.coordinate_names) {
      model.coordinate_name.push_back(c);
      model.limits.push_back(bp.limits);
    }
  }
  model.numberCoordinates();
  model.position_name = model.coordinate_name;
  if (base == BaseType::FreeQuaternion) {  // (x, y, z, w_x, w_y, w_z) -> (x, y, z, q_w, q_x, q_y, q_z)
    const std::vector<std::string> quaternion{"base_qw", "base_qx", "base_qy", "base_qz"};
    model.position_name.erase(model.position_name.begin() + 3, model.position_name.begin() + 6);
    model.position_name.insert(model.position_name.begin() + 3, quaternion.begin(), quaternion.end());
  }
  prepareKernels(model);
  const int n = model.nv();
  for (int b = 0; b < n; ++b)
    for (int c = b + 1; c < n; ++c)
      if (model.coordinate_name[b] == model.coordinate_name[c])
        fail("coordinate name '" + model.coordinate_name[b] + "' is used twice (a joint clashes with a base coordinate)");
  for (int b = 3; b < 7 && base == BaseType::FreeQuaternion; ++b)
    for (int c = 0; c < n; ++c)
      if (model.position_name[b] == model.coordinate_name[c])
        fail("coordinate name '" + model.coordinate_name[c] + "' is used twice (a joint clashes with a base coordinate)");
  return model;
}

Model<double> pointMassModel(double mass, const Eigen::Vector3d& axis, const std::string& coordinate,
                             const Eigen::Vector3d& gravity) {
  ModelBuilder b("point_mass");
  b.addLink("world");
  b.addLink("mass", mass, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  JointSpec j;
  j.name = coordinate;
  j.type = LinkJointType::Prismatic;
  j.parent = "world";
  j.child = "mass";
  j.axis = axis;
  b.addJoint(j);
  return b.build(BaseType::Fixed, gravity);
}

void argumentSizeError(const char* function, const char* argument, long size, int expected) {
  throw std::invalid_argument(std::string(function) + ": " + argument + " has " + std::to_string(size) +
                              " entries; the model has " + std::to_string(expected) + " coordinates");
}

}  // namespace saltus::dynamics
