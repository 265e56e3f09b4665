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
// Revolute joints about a coordinate axis ±e_K (Model::joint_kernel), in the forms the kernels'
// loops use. With c = cos q, s = σ sin q, the joint rotation is E_J = R_K(σq)ᵀ (RBDA Table 2.2,
// rx/ry/rz), which acts on a 3-vector with four multiplications:
//   (E_J x)_K = x_K,  (E_J x)_{K+1} = c x_{K+1} + s x_{K+2},  (E_J x)_{K+2} = c x_{K+2} − s x_{K+1}
// (indices mod 3), and E_Jᵀ with s → −s.

template <int K, class S>
SALTUS_INLINE Vec3<S> rotateAboutAxis(const S& c, const S& s, const Vec3<S>& x) {  // E_J x
  constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
  Vec3<S> y;
  y[K] = x[K];
  y[i1] = c * x[i1] + s * x[i2];
  y[i2] = c * x[i2] - s * x[i1];
  return y;
}
template <int K, class S>
SALTUS_INLINE Vec3<S> rotateAboutAxisInverse(const S& c, const S& s, const Vec3<S>& x) {  // E_Jᵀ x
  constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
  Vec3<S> y;
  y[K] = x[K];
  y[i1] = c * x[i1] - s * x[i2];
  y[i2] = c * x[i2] + s * x[i1];
  return y;
}

// ^iX_λ = rot(E_J) xlt(r_T) of an axis joint whose X_T has no rotation (RBDA 4.32 with E_T = 1).
template <class S, int K>
struct AxisTransform {
  S c, s;     // cos q, σ sin q
  Vec3<S> r;  // r_T: joint origin in parent coordinates

  // From the general form (E, r) of the same transform (data.X_up of an axis joint).
  static SALTUS_INLINE AxisTransform FromTransform(const Transform<S>& X) {
    return {X.E((K + 1) % 3, (K + 1) % 3), X.E((K + 1) % 3, (K + 2) % 3), X.r};
  }
  // Writes the general form (E, r) into X.
  SALTUS_INLINE void store(Transform<S>& X) const {
    constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
    X.E(K, K) = S(1);
    X.E(K, i1) = X.E(K, i2) = X.E(i1, K) = X.E(i2, K) = S(0);
    X.E(i1, i1) = X.E(i2, i2) = c;
    X.E(i1, i2) = s;
    X.E(i2, i1) = -s;
    X.r[0] = r[0], X.r[1] = r[1], X.r[2] = r[2];
  }
  SALTUS_INLINE Vec3<S> rotate(const Vec3<S>& x) const { return rotateAboutAxis<K>(c, s, x); }
  SALTUS_INLINE Vec3<S> rotateInverse(const Vec3<S>& x) const { return rotateAboutAxisInverse<K>(c, s, x); }
  SALTUS_INLINE Motion<S> apply(const Motion<S>& m) const {  // X m
    return {rotate(m.w), rotate(sub3(m.v, cross3(r, m.w)))};
  }
  SALTUS_INLINE Force<S> applyTranspose(const Force<S>& f) const {  // Xᵀ f
    const Vec3<S> ff = rotateInverse(f.f);
    return {add3(rotateInverse(f.n), cross3(r, ff)), ff};
  }
};

// The general transform plays the same role for the other joints (same interface).
template <class S>
struct GeneralTransform {
  const Transform<S>& X;
  const Vec3<S>& r = X.r;
  SALTUS_INLINE const Transform<S>& transform() const { return X; }
  SALTUS_INLINE Vec3<S> rotate(const Vec3<S>& x) const { return mul3(X.E, x); }
  SALTUS_INLINE Vec3<S> rotateInverse(const Vec3<S>& x) const { return mulT3(X.E, x); }
  SALTUS_INLINE Motion<S> apply(const Motion<S>& m) const { return X.apply(m); }
  SALTUS_INLINE Force<S> applyTranspose(const Force<S>& f) const { return X.applyTranspose(f); }
};

// Motion subspace S_i = (σ e_K; 0) of an axis joint (RBDA Table 4.1).
template <class S, int K>
struct AxisSubspace {
  static constexpr int axis = K;
  S sign;  // σ
  // S q̇ as a motion.
  SALTUS_INLINE Motion<S> velocity(const S& qd) const {
    const S x = sign * qd;
    return {Vec3<S>(K == 0 ? x : S(0), K == 1 ? x : S(0), K == 2 ? x : S(0)), Vec3<S>(S(0), S(0), S(0))};
  }
  // m += S x.
  SALTUS_INLINE void addTo(Motion<S>& m, const S& x) const { m.w[K] += sign * x; }
  // m × (S q̇) (RBDA 2.31), with x × e_K = (x_{K+2}, −x_{K+1}) in components (K+1, K+2).
  SALTUS_INLINE Motion<S> crossVelocity(const Motion<S>& m, const S& qd) const {
    constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
    const S w = sign * qd;
    Motion<S> out;
    out.w[K] = S(0);
    out.w[i1] = m.w[i2] * w;
    out.w[i2] = -(m.w[i1] * w);
    out.v[K] = S(0);
    out.v[i1] = m.v[i2] * w;
    out.v[i2] = -(m.v[i1] * w);
    return out;
  }
  // Sᵀ f.
  SALTUS_INLINE S project(const Force<S>& f) const { return sign * f.n[K]; }
  // Sᵀ x for a 6-vector x = (angular; linear), and U = A S for a 6 × 6 matrix A.
  SALTUS_INLINE S project6(const Vec6<S>& x) const { return sign * x[K]; }
  SALTUS_INLINE void matrixTimes(const Mat6<S>& A, Vec6<S>& U) const {
    for (int r = 0; r < 6; ++r) U[r] = sign * A(r, K);
  }
  // I S for a rigid-body inertia (RBDA 2.62): (Ī σe_K; σ e_K × h).
  SALTUS_INLINE Force<S> inertiaTimes(const RigidInertia<S>& I) const {
    constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
    Force<S> F;
    F.n = Vec3<S>(S(I.I(0, K) * sign), S(I.I(1, K) * sign), S(I.I(2, K) * sign));
    F.f[K] = S(0);
    F.f[i1] = -(I.h[i2] * sign);
    F.f[i2] = I.h[i1] * sign;
    return F;
  }
};

// S_i of any one-coordinate joint (same interface).
template <class S>
struct GenericSubspace {
  const Model<S>& model;
  int i;
  SALTUS_INLINE Motion<S> velocity(const S& qd) const { return jointVelocity(model, i, qd); }
  SALTUS_INLINE void addTo(Motion<S>& m, const S& x) const { m += jointVelocity(model, i, x); }
  SALTUS_INLINE Motion<S> crossVelocity(const Motion<S>& m, const S& qd) const { return m.cross(velocity(qd)); }
  SALTUS_INLINE S project(const Force<S>& f) const { return jointForce(model, i, f); }
  SALTUS_INLINE S project6(const Vec6<S>& x) const {
    const int o = model.joint_type[i] == JointType::Revolute ? 0 : 3;
    return model.axis[i][0] * x[o] + model.axis[i][1] * x[o + 1] + model.axis[i][2] * x[o + 2];
  }
  SALTUS_INLINE void matrixTimes(const Mat6<S>& A, Vec6<S>& U) const {
    const int o = model.joint_type[i] == JointType::Revolute ? 0 : 3;
    const Vec3<S>& s = model.axis[i];
    for (int r = 0; r < 6; ++r) U[r] = A(r, o) * s[0] + A(r, o + 1) * s[1] + A(r, o + 2) * s[2];
  }
  SALTUS_INLINE Force<S> inertiaTimes(const RigidInertia<S>& I) const { return I * motionSubspace(model, i); }
};

// E_J E_T for a revolute joint about σ e_K after the X_T rotation E_T: E_J mixes rows K+1, K+2.
template <class S, int K>
SALTUS_INLINE void storeRotatedAxisTransform(const Transform<S>& XT, const S& c, const S& s, Transform<S>& X) {
  constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
  for (int j = 0; j < 3; ++j) {
    X.E(K, j) = XT.E(K, j);
    X.E(i1, j) = c * XT.E(i1, j) + s * XT.E(i2, j);
    X.E(i2, j) = c * XT.E(i2, j) - s * XT.E(i1, j);
    X.r[j] = XT.r[j];
  }
}

// Evaluates body i's one-coordinate joint at q (jcalc, RBDA 4.4), stores ^iX_λ in data X_up[i]
// and calls fn(X, Si) with the transform and the motion subspace in the forms of its
// Model::joint_kernel. The switch on the kernel is taken once per body; fn is instantiated for
// each form. withJointAt takes cos q and sin q (used by the axis joints) computed beforehand.
template <class S, class Fn>
SALTUS_INLINE void withJointAt(const Model<S>& model, Transform<S>& X_up, int i, const S& q, const S& c,
                               const S& sin_q, Fn&& fn) {
  const int kernel = model.joint_kernel[i];
  if (kernel < kGenericJoint) {
    const S s = sin_q * model.axis_sign[i];
    const S& sign = model.axis_sign[i];
    switch (kernel) {
#define SALTUS_AXIS_CASE(K)                                                            \
  case kAxisJoint + K: {                                                               \
    const AxisTransform<S, K> X{c, s, model.X_tree[i].r};                              \
    X.store(X_up);                                                                     \
    fn(X, AxisSubspace<S, K>{sign});                                                   \
    return;                                                                            \
  }                                                                                    \
  case kRotatedAxisJoint + K: {                                                        \
    storeRotatedAxisTransform<S, K>(model.X_tree[i], c, s, X_up);                      \
    fn(GeneralTransform<S>{X_up}, AxisSubspace<S, K>{sign});                           \
    return;                                                                            \
  }
      SALTUS_AXIS_CASE(0)
      SALTUS_AXIS_CASE(1)
      SALTUS_AXIS_CASE(2)
#undef SALTUS_AXIS_CASE
    }
  }
  X_up = jointTransformUp(model, i, q);
  fn(GeneralTransform<S>{X_up}, GenericSubspace<S>{model, i});
}
template <class S, class Fn>
SALTUS_INLINE void withJoint(const Model<S>& model, Transform<S>& X_up, int i, const S& q, Fn&& fn) {
  S c(1), s(0);
  if (model.joint_kernel[i] < kGenericJoint) sinCos(q, s, c);
  withJointAt(model, X_up, i, q, c, s, fn);
}

// The same for a joint already evaluated: the forms are read back from X_up (^iX_λ).
template <class S, class Fn>
SALTUS_INLINE void withEvaluatedJoint(const Model<S>& model, const Transform<S>& X_up, int i, Fn&& fn) {
  const S& sign = model.axis_sign[i];
  switch (model.joint_kernel[i]) {
#define SALTUS_AXIS_CASE(K)                                                            \
  case kAxisJoint + K:                                                                 \
    fn(AxisTransform<S, K>::FromTransform(X_up), AxisSubspace<S, K>{sign});            \
    return;                                                                            \
  case kRotatedAxisJoint + K:                                                          \
    fn(GeneralTransform<S>{X_up}, AxisSubspace<S, K>{sign});                           \
    return;
    SALTUS_AXIS_CASE(0)
    SALTUS_AXIS_CASE(1)
    SALTUS_AXIS_CASE(2)
#undef SALTUS_AXIS_CASE
  }
  fn(GeneralTransform<S>{X_up}, GenericSubspace<S>{model, i});
}

// The same from the turned frame B'_λ of the parent to body i's B'_i (model.hpp, TurnedFrame): an
// axis joint whose X_T rotation is a signed permutation is the axis form about σ' e_K' with cos q
// and σ' sin q read off X_up (^iX_λ); any other joint is in the general form of ^iX_λ rot(Q_λᵀ)
// (just ^iX_λ when B'_λ = B_λ), with its S_i.
template <class S, class Fn>
SALTUS_INLINE void withTurnedJoint(const Model<S>& model, const Transform<S>& X_up, int i, Fn&& fn) {
  const TurnedFrame<S>& t = model.turned_frame[i];
  if (t.turned) {
    const S c = t.cos_sign * X_up.E(t.cos_row, t.cos_col), s = t.sin_sign * X_up.E(t.cos_row, t.sin_col);
    switch (t.kernel) {
#define SALTUS_AXIS_CASE(K)                                                            \
  case kAxisJoint + K:                                                                 \
    fn(AxisTransform<S, K>{c, s, t.r_T}, AxisSubspace<S, K>{t.sign});                  \
    return;
      SALTUS_AXIS_CASE(0)
      SALTUS_AXIS_CASE(1)
      SALTUS_AXIS_CASE(2)
#undef SALTUS_AXIS_CASE
    }
  }
  const Transform<S>* X = &X_up;
  Transform<S> X_turned;
  if (t.parent_turned) {  // ^iX_λ' = ^iX_λ ^λX_λ' with ^λX_λ' = rot(Q_λᵀ)
    X_turned = X_up * Transform<S>{model.turned_frame[model.parent[i]].Q.transpose(), Vec3<S>::Zero()};
    X = &X_turned;
  }
  const S& sign = model.axis_sign[i];
  switch (model.joint_kernel[i]) {
#define SALTUS_AXIS_CASE(K)                                                            \
  case kRotatedAxisJoint + K:                                                          \
    fn(GeneralTransform<S>{*X}, AxisSubspace<S, K>{sign});                             \
    return;
    SALTUS_AXIS_CASE(0)
    SALTUS_AXIS_CASE(1)
    SALTUS_AXIS_CASE(2)
#undef SALTUS_AXIS_CASE
  }
  fn(GeneralTransform<S>{*X}, GenericSubspace<S>{model, i});
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
// FreeQuaternion (x, y, z, q_w, q_x, q_y, q_z; velocities ṗ, ω_B): R = R(q/|q|) (the quaternion is
// normalised here, so a q off the unit sphere by rounding still gives a rotation), columns
// (0; Rᵀ e_k) for ṗ and (e_k; 0) for ω_B, so v ≠ q̇ and S does not depend on the orientation's
// coordinates; with Ṡ = (0; −ω_B × Rᵀ e_k) for the translation columns only,
// c_J = (0; v_B × ω_B).

// ^iX_λ(i) = X_J(q_i) X_T(i) (RBDA 4.32) for a multi-coordinate joint; writes the columns of S_i
// to Scol[0 .. n_i). q points at the joint's first position coordinate.
template <class S>
[[gnu::noinline]] Transform<S> multiJointTransformUp(const Model<S>& model, int i, const S* q, Motion<S>* Scol) {
  const S zero(0), one(1);
  Transform<S> XJ;
  if (model.joint_type[i] == JointType::FreeQuaternion) {
    using std::sqrt;
    const S n = sqrt(q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]);
    const S w = q[3] / n, x = q[4] / n, y = q[5] / n, z = q[6] / n;
    // E = Rᵀ with R the rotation of the unit quaternion (w, x, y, z).
    XJ.E << one - S(2) * (y * y + z * z), S(2) * (x * y + w * z), S(2) * (x * z - w * y),
            S(2) * (x * y - w * z), one - S(2) * (x * x + z * z), S(2) * (y * z + w * x),
            S(2) * (x * z + w * y), S(2) * (y * z - w * x), one - S(2) * (x * x + y * y);
    XJ.r[0] = q[0], XJ.r[1] = q[1], XJ.r[2] = q[2];
    for (int k = 0; k < 3; ++k) {
      Scol[k] = {Vec3<S>(zero, zero, zero), Vec3<S>(XJ.E(0, k), XJ.E(1, k), XJ.E(2, k))};
      Vec3<S> e(zero, zero, zero);
      e[k] = one;
      Scol[3 + k] = {e, Vec3<S>(zero, zero, zero)};
    }
  } else if (model.joint_type[i] == JointType::Free) {
    S cy, sy, cp, sp, cr, sr;
    sinCos(q[3], sy, cy);
    sinCos(q[4], sp, cp);
    sinCos(q[5], sr, cr);
    // E = Rᵀ; R = Rz(ψ) Ry(θ) Rx(φ).
    const S spcr = sp * cr, spsr = sp * sr;
    XJ.E << cy * cp, sy * cp, -sp,
            cy * spsr - sy * cr, sy * spsr + cy * cr, cp * sr,
            cy * spcr + sy * sr, sy * spcr - cy * sr, cp * cr;
    XJ.r[0] = q[0], XJ.r[1] = q[1], XJ.r[2] = q[2];
    for (int k = 0; k < 3; ++k) Scol[k] = {Vec3<S>(zero, zero, zero), Vec3<S>(XJ.E(0, k), XJ.E(1, k), XJ.E(2, k))};
    Scol[3] = {Vec3<S>(XJ.E(0, 2), XJ.E(1, 2), XJ.E(2, 2)), Vec3<S>(zero, zero, zero)};
    Scol[4] = {Vec3<S>(zero, cr, S(-sr)), Vec3<S>(zero, zero, zero)};
    Scol[5] = {Vec3<S>(one, zero, zero), Vec3<S>(zero, zero, zero)};
  } else {  // Planar
    S c, s;
    sinCos(q[2], s, c);
    XJ.E << c, zero, -s, zero, one, zero, s, zero, c;
    XJ.r[0] = q[0], XJ.r[1] = zero, XJ.r[2] = q[1];
    Scol[0] = {Vec3<S>(zero, zero, zero), Vec3<S>(c, zero, s)};
    Scol[1] = {Vec3<S>(zero, zero, zero), Vec3<S>(S(-s), zero, c)};
    Scol[2] = {Vec3<S>(zero, one, zero), Vec3<S>(zero, zero, zero)};
  }
  const Transform<S>& XT = model.X_tree[i];
  Transform<S> X;  // X_J X_T (RBDA Table 2.2): E = E_J E_T, r = r_T + E_Tᵀ r_J
  for (int c = 0; c < 3; ++c) {
    const Vec3<S> col = mul3(XJ.E, Vec3<S>(XT.E(0, c), XT.E(1, c), XT.E(2, c)));
    X.E(0, c) = col[0], X.E(1, c) = col[1], X.E(2, c) = col[2];
  }
  const Vec3<S> r = add3(XT.r, mulT3(XT.E, XJ.r));
  X.r[0] = r[0], X.r[1] = r[1], X.r[2] = r[2];
  return X;
}

// v_J = S_i q̇_i.
template <class S>
[[gnu::noinline]] Motion<S> multiJointVelocity(const Model<S>& model, int i, const Motion<S>* Scol, const S* qd) {
  if (model.joint_type[i] == JointType::FreeQuaternion)
    return {Vec3<S>(qd[3], qd[4], qd[5]),
            add3(add3(scale3(Scol[0].v, qd[0]), scale3(Scol[1].v, qd[1])), scale3(Scol[2].v, qd[2]))};
  if (model.joint_type[i] == JointType::Free)
    return {add3(add3(scale3(Scol[3].w, qd[3]), scale3(Scol[4].w, qd[4])), scale3(Scol[5].w, qd[5])),
            add3(add3(scale3(Scol[0].v, qd[0]), scale3(Scol[1].v, qd[1])), scale3(Scol[2].v, qd[2]))};
  return {scale3(Scol[2].w, qd[2]), add3(scale3(Scol[0].v, qd[0]), scale3(Scol[1].v, qd[1]))};
}

// c_J = Ṡ_i q̇_i, given v_J = S_i q̇_i (see above).
template <class S>
[[gnu::noinline]] Motion<S> multiJointBias(const Model<S>& model, int i, const Motion<S>* Scol, const S* qd,
                                           const Motion<S>& vJ) {
  const Vec3<S> lin = cross3(vJ.v, vJ.w);
  if (model.joint_type[i] == JointType::FreeQuaternion) return {Vec3<S>(S(0), S(0), S(0)), lin};
  if (model.joint_type[i] == JointType::Free) {
    const Vec3<S> w_roll(qd[5], S(0), S(0));
    return {add3(cross3(vJ.w, w_roll), cross3(scale3(Scol[3].w, qd[3]), scale3(Scol[4].w, qd[4]))), lin};
  }
  return {Vec3<S>(S(0), S(0), S(0)), lin};
}

// S_iᵀ f into out[0 .. n_i): inline, and out of line below.
template <class S>
SALTUS_INLINE void multiJointProject(const Model<S>& model, int i, const Motion<S>* Scol, const Force<S>& f, S* out) {
  if (model.joint_type[i] == JointType::FreeQuaternion) {
    for (int k = 0; k < 3; ++k) out[k] = dot3(Scol[k].v, f.f), out[3 + k] = f.n[k];
  } else if (model.joint_type[i] == JointType::Free) {
    for (int k = 0; k < 3; ++k) out[k] = dot3(Scol[k].v, f.f);
    out[3] = dot3(Scol[3].w, f.n);
    out[4] = dot3(Scol[4].w, f.n);
    out[5] = f.n[0];
  } else {
    out[0] = dot3(Scol[0].v, f.f);
    out[1] = dot3(Scol[1].v, f.f);
    out[2] = f.n[1];
  }
}
template <class S>
[[gnu::noinline]] void multiJointForce(const Model<S>& model, int i, const Motion<S>* Scol, const Force<S>& f, S* out) {
  multiJointProject(model, i, Scol, f, out);
}

}  // namespace saltus::dynamics
