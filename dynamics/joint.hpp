// Joint calculations (RBDA 4.4, Table 4.1 "jcalc"): the transform across a joint, its motion
// subspace S_i and, for the multi-coordinate base joints, the velocity-product term c_J = Ṡ_i q̇_i.
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

// S_i (RBDA Table 4.1) of a one-coordinate joint: (axis; 0) for revolute, (0; axis) for
// prismatic, in body coordinates.
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

// ---------------------------------------------------------------------------------------------
// Multi-coordinate joints: the floating bases (model.hpp, BaseType), with v = q̇, so the motion
// subspace S_i(q) (6 × n_i, body coordinates) depends on the configuration (RBDA 4.4: v_J = S q̇,
// c_J = Ṡ q̇ with the derivative taken component-wise in body coordinates, eq. 4.40/4.41).
//
// Free (x, y, z, ψ, θ, φ): body pose p = (x, y, z), R = Rz(ψ) Ry(θ) Rx(φ), so X_J has E = Rᵀ,
// r = p. The body-coordinate velocity is v_B = Rᵀ ṗ and
//   ω_B = s_ψ ψ̇ + s_θ θ̇ + s_φ φ̇,  s_ψ = Rᵀ z = (−sθ, cθ sφ, cθ cφ),  s_θ = Rx(φ)ᵀ y = (0, cφ, −sφ),
//   s_φ = x;
// the translation columns are (0; Rᵀ e_k). Differentiating in body coordinates (Ṙᵀ = −ω_B× Rᵀ,
// Ṙx(φ)ᵀ = −(φ̇ x)× Rx(φ)ᵀ, likewise for Ry) gives
//   c_J = (ω_B × s_φ φ̇ + s_ψ ψ̇ × s_θ θ̇ ;  v_B × ω_B).
// Planar (x, z, θ): p = (x, 0, z), R = Ry(θ); columns (0; Rᵀ x), (0; Rᵀ z), (y; 0), and
// c_J = (0; v_B × ω_B).

// ^iX_λ(i) = X_J(q_i) X_T(i) (RBDA 4.32) for a multi-coordinate joint; writes the columns of S_i
// to Scol[0 .. n_i). q points at the joint's first coordinate.
template <class S>
[[gnu::noinline]] Transform<S> multiJointTransformUp(const Model<S>& model, int i, const S* q, Motion<S>* Scol) {
  using std::cos;
  using std::sin;
  const Vec3<S> zero = Vec3<S>::Zero();
  Transform<S> XJ;
  if (model.joint_type[i] == JointType::Free) {
    const S cy = cos(q[3]), sy = sin(q[3]), cp = cos(q[4]), sp = sin(q[4]), cr = cos(q[5]), sr = sin(q[5]);
    // E = Rᵀ; R = Rz(ψ) Ry(θ) Rx(φ).
    const S spcr = sp * cr, spsr = sp * sr;
    XJ.E << cy * cp, sy * cp, -sp,
            cy * spsr - sy * cr, sy * spsr + cy * cr, cp * sr,
            cy * spcr + sy * sr, sy * spcr - cy * sr, cp * cr;
    XJ.r << q[0], q[1], q[2];
    for (int k = 0; k < 3; ++k) Scol[k] = {zero, XJ.E.col(k)};
    Scol[3] = {XJ.E.col(2), zero};
    Scol[4] = {Vec3<S>(S(0), cr, -sr), zero};
    Scol[5] = {Vec3<S>(S(1), S(0), S(0)), zero};
  } else {  // Planar
    const S c = cos(q[2]), s = sin(q[2]);
    XJ.E << c, S(0), -s, S(0), S(1), S(0), s, S(0), c;
    XJ.r << q[0], S(0), q[1];
    Scol[0] = {zero, XJ.E.col(0)};
    Scol[1] = {zero, XJ.E.col(2)};
    Scol[2] = {Vec3<S>(S(0), S(1), S(0)), zero};
  }
  return XJ * model.X_tree[i];
}

// v_J = S_i q̇_i.
template <class S>
[[gnu::noinline]] Motion<S> multiJointVelocity(const Model<S>& model, int i, const Motion<S>* Scol, const S* qd) {
  if (model.joint_type[i] == JointType::Free)
    return {Scol[3].w * qd[3] + Scol[4].w * qd[4] + Scol[5].w * qd[5],
            Scol[0].v * qd[0] + Scol[1].v * qd[1] + Scol[2].v * qd[2]};
  return {Scol[2].w * qd[2], Scol[0].v * qd[0] + Scol[1].v * qd[1]};
}

// c_J = Ṡ_i q̇_i, given v_J = S_i q̇_i (see above).
template <class S>
[[gnu::noinline]] Motion<S> multiJointBias(const Model<S>& model, int i, const Motion<S>* Scol, const S* qd,
                                       const Motion<S>& vJ) {
  const Vec3<S> lin = vJ.v.cross(vJ.w);
  if (model.joint_type[i] == JointType::Free) {
    const Vec3<S> w_roll(qd[5], S(0), S(0));
    return {vJ.w.cross(w_roll) + (Scol[3].w * qd[3]).cross(Scol[4].w * qd[4]), lin};
  }
  return {Vec3<S>::Zero(), lin};
}

// S_iᵀ f into out[0 .. n_i).
template <class S>
[[gnu::noinline]] void multiJointForce(const Model<S>& model, int i, const Motion<S>* Scol, const Force<S>& f, S* out) {
  if (model.joint_type[i] == JointType::Free) {
    for (int k = 0; k < 3; ++k) out[k] = Scol[k].v.dot(f.f);
    out[3] = Scol[3].w.dot(f.n);
    out[4] = Scol[4].w.dot(f.n);
    out[5] = f.n[0];
  } else {
    out[0] = Scol[0].v.dot(f.f);
    out[1] = Scol[1].v.dot(f.f);
    out[2] = f.n[1];
  }
}

}  // namespace saltus::dynamics
