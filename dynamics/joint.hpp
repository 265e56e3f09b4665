// Joint calculations (RBDA 4.4, Table 4.1 "jcalc"): the transform across a one-coordinate joint
// and its motion subspace S_i.
#pragma once

#include "dynamics/model.hpp"

namespace saltus::dynamics {

// ^iX_λ(i) = X_J(q_i) X_T(i)  (RBDA 4.32).
// Revolute:  X_J = rot(R(axis, q)ᵀ), so E = R(axis, q)ᵀ E_T and r = r_T.
// Prismatic: X_J = xlt(axis q),       so E = E_T and r = r_T + E_Tᵀ axis q.
// For an axis along a coordinate axis k, R(axis, q)ᵀ mixes only the two other rows of E_T.
template <class S>
SALTUS_INLINE Transform<S> jointTransformUp(const Model<S>& model, int i, const S& qi) {
  using std::cos;
  using std::sin;
  const Transform<S>& XT = model.X_tree[i];
  const int k = model.axis_kind[i];
  if (model.joint_type[i] == JointType::Revolute) {
    if (k < 0) return {axisAngle(model.axis[i], qi).transpose() * XT.E, XT.r};
    const S c = cos(qi), s = sin(qi);
    const int r1 = (k + 1) % 3, r2 = (k + 2) % 3;  // rotation about k: rows (k+1, k+2) turn by −q
    Transform<S> X{XT.E, XT.r};
    X.E.row(r1) = c * XT.E.row(r1) + s * XT.E.row(r2);
    X.E.row(r2) = c * XT.E.row(r2) - s * XT.E.row(r1);
    return X;
  }
  if (k < 0) return {XT.E, XT.r + XT.E.transpose() * (model.axis[i] * qi)};
  return {XT.E, XT.r + XT.E.row(k).transpose() * qi};
}

// S_i (RBDA Table 4.1): (axis; 0) for revolute, (0; axis) for prismatic, in body coordinates.
template <class S>
SALTUS_INLINE Motion<S> motionSubspace(const Model<S>& model, int i) {
  if (model.joint_type[i] == JointType::Revolute) return {model.axis[i], Vec3<S>::Zero()};
  return {Vec3<S>::Zero(), model.axis[i]};
}

// axis * x, without multiplications for a coordinate axis.
template <class S>
SALTUS_INLINE Vec3<S> alongAxis(const Model<S>& model, int i, const S& x) {
  const int k = model.axis_kind[i];
  if (k < 0) return model.axis[i] * x;
  Vec3<S> out = Vec3<S>::Zero();
  out[k] = x;
  return out;
}

// S_i q̇_i without forming S_i.
template <class S>
SALTUS_INLINE Motion<S> jointVelocity(const Model<S>& model, int i, const S& qdi) {
  if (model.joint_type[i] == JointType::Revolute) return {alongAxis(model, i, qdi), Vec3<S>::Zero()};
  return {Vec3<S>::Zero(), alongAxis(model, i, qdi)};
}

// S_iᵀ f.
template <class S>
SALTUS_INLINE S jointForce(const Model<S>& model, int i, const Force<S>& f) {
  const Vec3<S>& x = model.joint_type[i] == JointType::Revolute ? f.n : f.f;
  const int k = model.axis_kind[i];
  return k < 0 ? model.axis[i].dot(x) : x[k];
}

}  // namespace saltus::dynamics
