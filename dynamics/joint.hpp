// Joint calculations (RBDA 4.4, Table 4.1 "jcalc"): the transform across a one-coordinate joint
// and its motion subspace S_i.
#pragma once

#include "dynamics/model.hpp"

namespace saltus::dynamics {

// ^iX_λ(i) = X_J(q_i) X_T(i)  (RBDA 4.32).
// Revolute:  X_J = rot(R(axis, q)ᵀ), so E = R(axis, q)ᵀ E_T and r = r_T.
// Prismatic: X_J = xlt(axis q),       so E = E_T and r = r_T + E_Tᵀ axis q.
template <class S>
Transform<S> jointTransformUp(const Model<S>& model, int i, const S& qi) {
  const Transform<S>& XT = model.X_tree[i];
  if (model.joint_type[i] == JointType::Revolute)
    return {axisAngle(model.axis[i], qi).transpose() * XT.E, XT.r};
  return {XT.E, XT.r + XT.E.transpose() * (model.axis[i] * qi)};
}

// S_i (RBDA Table 4.1): (axis; 0) for revolute, (0; axis) for prismatic, in body coordinates.
template <class S>
Motion<S> motionSubspace(const Model<S>& model, int i) {
  if (model.joint_type[i] == JointType::Revolute) return {model.axis[i], Vec3<S>::Zero()};
  return {Vec3<S>::Zero(), model.axis[i]};
}

// S_i q̇_i without forming S_i.
template <class S>
Motion<S> jointVelocity(const Model<S>& model, int i, const S& qdi) {
  if (model.joint_type[i] == JointType::Revolute) return {model.axis[i] * qdi, Vec3<S>::Zero()};
  return {Vec3<S>::Zero(), model.axis[i] * qdi};
}

// S_iᵀ f.
template <class S>
S jointForce(const Model<S>& model, int i, const Force<S>& f) {
  return model.joint_type[i] == JointType::Revolute ? model.axis[i].dot(f.n) : model.axis[i].dot(f.f);
}

}  // namespace saltus::dynamics
