#include "collocation/solution.hpp"

#include <stdexcept>

#include "collocation/interpolation.hpp"
#include "dynamics/aba.hpp"

namespace saltus::collocation {

namespace {

// The inputs at s ∈ [0, 1] of an element: the polynomial through their values at the
// collocation points (first order: the step's one value).
Eigen::VectorXd inputsAt(const Transcription& t, const ElementLayout& L, const Eigen::VectorXd& x, int nu, double s) {
  if (L.collocation.size() == 1) return x.segment(L.points[L.collocation[0]].u, nu);
  const Eigen::VectorXd l = t.lg().basis(s);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(nu);
  for (std::size_t j = 0; j < L.collocation.size(); ++j) out += l[j] * x.segment(L.points[L.collocation[j]].u, nu);
  return out;
}

}  // namespace

std::vector<Sample> trajectory(const Transcription& t, const Eigen::VectorXd& x) {
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  const int nv = model.nv(), nu = static_cast<int>(t.problem().inputs.size());
  const bool impulsive = t.method() == Method::Impulsive;
  const bool first_order = t.method() == Method::FirstOrder;
  std::vector<Sample> rows;
  double t0 = 0;
  for (int n = 0; n < t.elements(); ++n) {
    const ElementLayout& L = t.layout()[n];
    const double h = x[L.h];
    const int element = first_order ? n / t.problem().first_order_steps_per_element : n;
    for (std::size_t p = 0; p < L.points.size(); ++p) {
      if (p == 0 && n > 0 && !impulsive) continue;  // continuous velocity: one row per mesh point
      const auto& pt = L.points[p];
      Sample s;
      s.t = t0 + h * L.tau[p];
      s.element = n;
      s.point = static_cast<int>(p);
      s.q = x.segment(pt.q, nv);
      s.v = x.segment(pt.v, nv);
      s.u = nu == 0 ? Eigen::VectorXd() : pt.u >= 0 ? Eigen::VectorXd(x.segment(pt.u, nu))
                                                    : inputsAt(t, L, x, nu, L.tau[p]);
      dynamics::forwardKinematics(model, data, s.q, s.v);
      for (std::size_t c = 0; c < t.contacts().size(); ++c) {
        const ContactPair& cp = t.contacts()[c];
        const auto& C = L.contacts[c];
        ContactSample cs;
        cs.gap = t.gapValue(x, n, static_cast<int>(c), static_cast<int>(p));
        cs.vn = contact::normalVelocity(cp, data, s.v.data());
        const bool impulse = impulsive && p == 0;
        // On a body's plane: a free point's variables (where its reaction acts) at a point with a
        // reaction, else the point's projection.
        if (C.s[p] >= 0) {
          for (int i = 0; i < cp.freeAxes(); ++i) cs.s[cp.free_axes[i]] = x[C.s[p] + i];
        } else if (contact::hasExtent(cp)) {
          cs.s = contact::planeCoordinates(cp, data);
        }
        if (!cp.isStop()) {
          const Eigen::Matrix<double, 3, 2> T = contact::planeFrame(cp, data).tangents;
          cs.vt = T.transpose() * (C.s[p] >= 0 ? contact::relativeVelocityAt(cp, data, x.data() + C.s[p])
                                                : contact::relativeVelocity(cp, data, t.surfaceVelocity(cp.surface, element)));
          if (C.rn[p] >= 0) {
            const double rn = x[C.rn[p]];
            const double* tangential = cp.k() > 0 ? x.data() + C.tangential[p] : nullptr;
            (impulse ? cs.pn : cs.rn) = rn;
            (impulse ? cs.pt : cs.rt) = T.transpose() * contactForce(cp, data, t.frictionForm(), rn, tangential, true);
          }
        } else if (C.rn[p] >= 0) {
          (impulse ? cs.pn : cs.rn) = x[C.rn[p]];
        }
        s.contacts.push_back(cs);
      }
      rows.push_back(std::move(s));
    }
    t0 += h;
  }
  return rows;
}

void writeTrajectoryCsv(const std::string& path, const Transcription& t, const std::vector<Sample>& samples) {
  // The scene's columns (the transcription's contacts are the scene's pairs), with inputs and forces.
  const auto& model = t.problem().scene.model;
  scene::TrajectoryLayout layout = scene::trajectoryLayout(t.problem().scene);
  for (int i : t.problem().inputs) layout.inputs.push_back(model.coordinate_name[i]);
  layout.forces = true;
  try {
    scene::TrajectoryCsvWriter writer(path, std::move(layout));
    for (const Sample& s : samples) {
      writer.beginRow(s.t, s.q, s.v, s.u);
      for (const ContactSample& c : s.contacts) writer.contact(c);
      writer.endRow();
    }
    writer.commit();
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": cannot write the trajectory (" + e.what() + ")");
  }
}

double meanLocalError(const Transcription& t, const Eigen::VectorXd& x) {
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  const int nv = model.nv(), nu = static_cast<int>(t.problem().inputs.size());
  const int P = static_cast<int>(t.layout()[0].collocation.size());
  const bool first_order = t.method() == Method::FirstOrder;
  const CollocationTrajectory polynomials(t, x);
  Eigen::VectorXd gx, gw;
  gaussLegendre(P + 1, gx, gw);
  double total = 0;
  long count = 0;
  // Scale floors: a variable that stays near zero on an element (a mass at rest) would turn
  // round-off into a huge relative error; floor each element's scale at 1 % of the variable's
  // largest magnitude over the trajectory.
  Eigen::VectorXd q_max = Eigen::VectorXd::Constant(nv, 1e-9), v_max = Eigen::VectorXd::Constant(nv, 1e-9);
  for (const ElementLayout& L : t.layout())
    for (const auto& pt : L.points)
      for (int i = 0; i < nv; ++i)
        q_max[i] = std::max(q_max[i], std::abs(x[pt.q + i])), v_max[i] = std::max(v_max[i], std::abs(x[pt.v + i]));
  Eigen::VectorXd qd(nv), tau(nv);
  const Eigen::VectorXd tau_0 = t.constantInput().size() == nv ? t.constantInput() : Eigen::VectorXd::Zero(nv);
  for (int n = 0; n < t.elements(); ++n) {
    const ElementLayout& L = t.layout()[n];
    const double h = x[L.h];
    Eigen::VectorXd err_q = Eigen::VectorXd::Zero(nv), err_v = Eigen::VectorXd::Zero(nv);
    for (int m = 0; m < gx.size(); ++m) {
      const double s = (gx[m] + 1) / 2;
      // The state polynomials (interpolation.hpp) and the derivative of q(s), Σ_j ℓ_j(s) q̇[n, j]
      // (first order: the end point's rate).
      const TrajectoryPoint state = polynomials.atElement(n, s);
      const Eigen::VectorXd ls = first_order ? Eigen::VectorXd::Ones(1) : t.lg().basis(s);
      qd.setZero();
      for (int j = 0; j < P; ++j) qd += ls[j] * x.segment(L.points[L.collocation[j]].v, nv);
      // The EOM's q̈ for the interpolated state, inputs and reactions.
      tau = tau_0;
      for (int i = 0; i < nu; ++i) tau[t.problem().inputs[i]] += state.u[i];
      dynamics::forwardKinematics(model, data, state.q);
      for (std::size_t c = 0; c < t.contacts().size(); ++c) {
        const ContactPair& cp = t.contacts()[c];
        const auto& C = L.contacts[c];
        for (int j = 0; j < P; ++j) {
          const int p = L.collocation[j];
          const double rn = x[C.rn[p]];
          const double* tangential = cp.k() > 0 ? x.data() + C.tangential[p] : nullptr;
          const Eigen::Vector3d f_t = cp.isStop() ? Eigen::Vector3d::Zero().eval()
                                                  : contactForce(cp, data, t.frictionForm(), rn, tangential, true);
          if (C.s[p] >= 0)  // a free point: on B at its plane coordinates
            contact::addReactionAt(model, data, cp, ls[j] * rn, Eigen::Vector3d(ls[j] * f_t), x.data() + C.s[p],
                                   tau.data());
          else
            contact::addReaction(model, data, cp, ls[j] * rn, Eigen::Vector3d(ls[j] * f_t), tau.data());
        }
      }
      const Eigen::VectorXd& qdd = dynamics::aba(model, data, state.q, state.v, tau);
      // ∫ over the element: dt = h ds, and the Gauss rule on [0, 1] has weights w / 2.
      err_q += (h * gw[m] / 2) * (qd - state.v).cwiseAbs();
      err_v += (h * gw[m] / 2) * (state.a - qdd).cwiseAbs();
    }
    // Scale by the largest magnitude of each variable on the element.
    for (int i = 0; i < nv; ++i) {
      double sq = 0, sv = 0;
      for (const auto& pt : L.points) sq = std::max(sq, std::abs(x[pt.q + i])), sv = std::max(sv, std::abs(x[pt.v + i]));
      total += err_q[i] / std::max(sq, 0.01 * q_max[i]) + err_v[i] / std::max(sv, 0.01 * v_max[i]);
      count += 2;
    }
  }
  return count ? total / count : 0.0;
}

}  // namespace saltus::collocation
