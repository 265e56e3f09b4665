#include "collocation/interpolation.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace saltus::collocation {

CollocationTrajectory::CollocationTrajectory(const Transcription& t, const Eigen::VectorXd& x)
    : t_(t), x_(x), nv_(t.problem().scene.model.nv()), nu_(static_cast<int>(t.problem().inputs.size())) {
  if (x.size() != t.variables())
    throw std::invalid_argument("CollocationTrajectory: " + std::to_string(x.size()) + " values for " +
                                std::to_string(t.variables()) + " variables");
  mesh_.push_back(0.0);
  for (const ElementLayout& L : t.layout()) mesh_.push_back(mesh_.back() + x[L.h]);
}

int CollocationTrajectory::elementAt(double t, Side side) const {
  const double T = endTime();
  const double slack = 1e-12 * std::max(1.0, T);
  if (!(t >= -slack && t <= T + slack))
    throw std::out_of_range("time " + std::to_string(t) + " lies outside the trajectory [0, " + std::to_string(T) + "]");
  // First boundary > t (After) or ≥ t (Before); the element ends there.
  const auto it = side == Side::After ? std::upper_bound(mesh_.begin(), mesh_.end(), t)
                                      : std::lower_bound(mesh_.begin(), mesh_.end(), t);
  const int n = static_cast<int>(it - mesh_.begin()) - 1;
  return std::clamp(n, 0, elements() - 1);
}

TrajectoryPoint CollocationTrajectory::at(double t, Side side) const {
  const int n = elementAt(t, side);
  const double h = mesh_[n + 1] - mesh_[n];
  return atElement(n, std::clamp((t - mesh_[n]) / h, 0.0, 1.0));
}

TrajectoryPoint CollocationTrajectory::atElement(int n, double s) const {
  const ElementLayout& L = t_.layout().at(n);
  const double h = x_[L.h];
  const int P = static_cast<int>(L.collocation.size());
  Eigen::VectorXd I, l;  // ∫_0^s ℓ_j and ℓ_j(s)
  if (t_.method() == Method::FirstOrder) {
    I = Eigen::VectorXd::Constant(1, s);
    l = Eigen::VectorXd::Ones(1);
  } else {
    I = t_.lg().basisIntegral(s);
    l = t_.lg().basis(s);
  }
  TrajectoryPoint out;
  out.q = x_.segment(L.points[0].q, nv_);
  out.v = x_.segment(L.points[0].v, nv_);
  out.a = Eigen::VectorXd::Zero(nv_);
  out.u = Eigen::VectorXd::Zero(nu_);
  for (int j = 0; j < P; ++j) {
    const auto& pt = L.points[L.collocation[j]];
    out.q += h * I[j] * x_.segment(pt.v, nv_);
    out.v += h * I[j] * x_.segment(pt.accel_or_jump, nv_);
    out.a += l[j] * x_.segment(pt.accel_or_jump, nv_);
    if (nu_ > 0) out.u += l[j] * x_.segment(pt.u, nu_);
  }
  return out;
}

std::vector<CollocationTrajectory::Jump> CollocationTrajectory::jumps(double threshold) const {
  std::vector<Jump> out;
  if (t_.method() != Method::Impulsive) return out;
  for (int n = 1; n < elements(); ++n) {
    const int a = t_.layout()[n].points[0].accel_or_jump;
    if (a < 0) continue;
    const Eigen::VectorXd dv = x_.segment(a, nv_);
    if (dv.cwiseAbs().maxCoeff() > threshold) out.push_back({mesh_[n], n, dv});
  }
  return out;
}

}  // namespace saltus::collocation
