// The configuration space: positions q (nq) and the velocities v (nv) that move them. For every
// joint but a FreeQuaternion base the coordinates are a vector space with v = q̇, and these are
// q + v dt and q1 − q0. A FreeQuaternion base's orientation is a unit quaternion Q (scalar first)
// with angular velocity ω_B in body axes, Q̇ = ½ Q ⊗ (0, ω_B); over a step with ω_B constant the
// orientation moves along the exponential map, Q ⊕ ω_B dt = Q ⊗ exp(½ ω_B dt) with
// exp(½ θ) = (cos(|θ|/2), sin(|θ|/2) θ/|θ|) (Solà, "Quaternion kinematics for the error-state
// Kalman filter", arXiv:1711.02508, eq. 101 and 108; Pinocchio's and Drake's integrate): the
// result stays on the unit sphere up to rounding, which integrate() removes.
#pragma once

#include <cmath>

#include "dynamics/model.hpp"

namespace saltus::dynamics {

using QuaternionWxyz = Eigen::Matrix<double, 4, 1>;

// Q ⊗ P (Hamilton product, scalar first).
inline QuaternionWxyz quaternionProduct(const QuaternionWxyz& Q, const QuaternionWxyz& P) {
  return {Q[0] * P[0] - Q[1] * P[1] - Q[2] * P[2] - Q[3] * P[3],
          Q[0] * P[1] + Q[1] * P[0] + Q[2] * P[3] - Q[3] * P[2],
          Q[0] * P[2] - Q[1] * P[3] + Q[2] * P[0] + Q[3] * P[1],
          Q[0] * P[3] + Q[1] * P[2] - Q[2] * P[1] + Q[3] * P[0]};
}

// exp(½ θ) for a rotation vector θ: the unit quaternion of the rotation by |θ| about θ.
inline QuaternionWxyz quaternionExp(const Eigen::Vector3d& theta) {
  const double angle = theta.norm(), half = 0.5 * angle;
  // sin(|θ|/2)/|θ| by its series below 1e-4 rad (error under 1e-18).
  const double k = angle < 1e-4 ? 0.5 - angle * angle / 48.0 : std::sin(half) / angle;
  return {std::cos(half), k * theta[0], k * theta[1], k * theta[2]};
}

// The rotation vector θ of a unit quaternion, |θ| ≤ π (log, the inverse of quaternionExp; Q and
// −Q give the same θ).
inline Eigen::Vector3d quaternionLog(QuaternionWxyz Q) {
  if (Q[0] < 0) Q = -Q;
  const Eigen::Vector3d u = Q.tail<3>();
  const double s = u.norm(), angle = 2.0 * std::atan2(s, Q[0]);
  // |θ|/sin(|θ|/2) → 2 + |θ|²/12 as |θ| → 0.
  const double k = s < 1e-8 ? 2.0 / Q[0] : angle / s;
  return k * u;
}

// The rotation R (body to world) of a unit quaternion.
inline Eigen::Matrix3d quaternionToRotation(const QuaternionWxyz& Q) {
  return Eigen::Quaterniond(Q[0], Q[1], Q[2], Q[3]).toRotationMatrix();
}
inline QuaternionWxyz rotationToQuaternion(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  QuaternionWxyz Q(q.w(), q.x(), q.y(), q.z());
  return Q[0] < 0 ? QuaternionWxyz(-Q) : Q;
}

// The configuration with every coordinate zero and the identity orientation.
inline VecX<double> neutralConfiguration(const Model<double>& model) {
  VecX<double> q = VecX<double>::Zero(model.nq());
  if (model.base == BaseType::FreeQuaternion) q[3] = 1.0;
  return q;
}

// q ⊕ v dt into q_next (q_next may be q). No allocation.
inline void integrate(const Model<double>& model, const VecRef<double>& q, const VecRef<double>& v, double dt,
                      Eigen::Ref<VecX<double>> q_next) {
  checkConfigurationSize(model, q.size(), "integrate", "q");
  checkArgumentSize(model, v.size(), "integrate", "v");
  checkConfigurationSize(model, q_next.size(), "integrate", "q_next");
  if (model.base != BaseType::FreeQuaternion) {
    q_next = q + dt * v;
    return;
  }
  const QuaternionWxyz Q = q.segment<4>(3);
  QuaternionWxyz Q_next = quaternionProduct(Q, quaternionExp(dt * v.segment<3>(3)));
  Q_next /= Q_next.norm();
  for (int k = 0; k < 3; ++k) q_next[k] = q[k] + dt * v[k];
  q_next.segment<4>(3) = Q_next;
  const int n = model.nv() - 6;
  q_next.tail(n) = q.tail(n) + dt * v.tail(n);
}

// The velocity v with q0 ⊕ v = q1 over a unit time (the inverse of integrate: q1 ⊖ q0), the
// shortest rotation for a quaternion base.
inline VecX<double> difference(const Model<double>& model, const VecRef<double>& q0, const VecRef<double>& q1) {
  checkConfigurationSize(model, q0.size(), "difference", "q0");
  checkConfigurationSize(model, q1.size(), "difference", "q1");
  if (model.base != BaseType::FreeQuaternion) return q1 - q0;
  VecX<double> v(model.nv());
  const QuaternionWxyz Q0 = q0.segment<4>(3) / q0.segment<4>(3).norm();
  const QuaternionWxyz Q1 = q1.segment<4>(3) / q1.segment<4>(3).norm();
  const QuaternionWxyz Q0_inverse(Q0[0], -Q0[1], -Q0[2], -Q0[3]);
  v.head<3>() = q1.head<3>() - q0.head<3>();
  v.segment<3>(3) = quaternionLog(quaternionProduct(Q0_inverse, Q1));
  const int n = model.nv() - 6;
  v.tail(n) = q1.tail(n) - q0.tail(n);
  return v;
}

// q with its quaternion scaled to unit length (other coordinates as they are). Throws
// std::invalid_argument when the quaternion is zero or not finite.
inline void normalizeConfiguration(const Model<double>& model, Eigen::Ref<VecX<double>> q) {
  checkConfigurationSize(model, q.size(), "normalizeConfiguration", "q");
  if (model.base != BaseType::FreeQuaternion) return;
  const double n = q.segment<4>(3).norm();
  if (!(n > 0) || !std::isfinite(n))
    throw std::invalid_argument("the base quaternion (base_qw, base_qx, base_qy, base_qz) must be non-zero and finite");
  q.segment<4>(3) /= n;
}

}  // namespace saltus::dynamics
