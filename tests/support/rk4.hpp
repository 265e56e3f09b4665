// A reference solution for smooth, contact-free motion: classical RK4 on q̈ = ABA(q, q̇, τ) with
// many small steps, for convergence-order tests.
#pragma once

#include <utility>

#include "dynamics/aba.hpp"
#include "dynamics/data.hpp"

namespace saltus::testing {

// (q, q̇) at time T from (q0, v0) under constant τ, in `steps` RK4 steps.
inline std::pair<Eigen::VectorXd, Eigen::VectorXd> rk4Reference(const dynamics::Model<double>& model,
                                                                Eigen::VectorXd q, Eigen::VectorXd v,
                                                                const Eigen::VectorXd& tau, double T, int steps) {
  dynamics::Data<double> data(model);
  auto acc = [&](const Eigen::VectorXd& qq, const Eigen::VectorXd& vv) {
    return Eigen::VectorXd(dynamics::aba(model, data, qq, vv, tau));
  };
  const double h = T / steps;
  for (int i = 0; i < steps; ++i) {
    const Eigen::VectorXd k1q = v, k1v = acc(q, v);
    const Eigen::VectorXd k2q = v + h / 2 * k1v, k2v = acc(q + h / 2 * k1q, v + h / 2 * k1v);
    const Eigen::VectorXd k3q = v + h / 2 * k2v, k3v = acc(q + h / 2 * k2q, v + h / 2 * k2v);
    const Eigen::VectorXd k4q = v + h * k3v, k4v = acc(q + h * k3q, v + h * k3v);
    q += h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  return {q, v};
}

}  // namespace saltus::testing
