// Forward-mode automatic differentiation with the spatial operations as its elementary
// operations (derivatives.hpp, rneaDerivatives).
//
// A dual spatial vector is split in two: its value, which a double pass of the algorithm has
// already computed, and its tangent, the derivatives along N directions at once. Each operation
// of spatial.hpp and joint.hpp that the recursions use has its derivative rule here (the product
// rule: d(X m) = X dm for a constant transform, d(a × b) = da × b + a × db, ...), so a
// recursion written with them propagates tangents the way a dual-number scalar would, without
// carrying a value and N derivatives in every scalar. The tangent of a 3-vector is a 3 × N block
// with one row per component: every rule is then a few N-wide multiply-adds on rows.
//
// The derivative of a joint transform itself, for the directions that move its coordinate, is
// the rule ∂(^iX_λ)/∂q_i = −(S_i×) ^iX_λ of a one-coordinate joint (RBDA 4.32 with
// X_J(q) = exp(−(S×) q), S_i constant in body coordinates); derivatives.hpp applies it.
#pragma once

#include "dynamics/joint.hpp"

namespace saltus::dynamics::tangent {

template <int N>
using Block3 = Eigen::Matrix<double, 3, N, Eigen::RowMajor>;  // row c: ∂x_c along the N directions
template <int N>
using Row = Eigen::Matrix<double, 1, N>;

// Tangent of a motion (ω; v) and of a force (n; f).
// addColumn(e_d, m) adds m to the column of direction d, given the unit row e_d (row-wide
// multiply-adds: a scalar store into a row that is then read whole would stall store forwarding).
template <int N>
struct MotionTangent {
  Block3<N> w, v;
  SALTUS_INLINE void setZero() { w.setZero(), v.setZero(); }
  SALTUS_INLINE void addColumn(const Row<N>& e_d, const Motion<double>& m) {
    for (int r = 0; r < 3; ++r) w.row(r) += m.w[r] * e_d, v.row(r) += m.v[r] * e_d;
  }
};
template <int N>
struct ForceTangent {
  Block3<N> n, f;
  SALTUS_INLINE void setZero() { n.setZero(), f.setZero(); }
  SALTUS_INLINE void addColumn(const Row<N>& e_d, const Force<double>& x) {
    for (int r = 0; r < 3; ++r) n.row(r) += x.n[r] * e_d, f.row(r) += x.f[r] * e_d;
  }
  SALTUS_INLINE ForceTangent& operator+=(const ForceTangent& o) {
    n += o.n, f += o.f;
    return *this;
  }
};

// a × dx for a constant a.
template <int N>
SALTUS_INLINE Block3<N> cross(const Vec3<double>& a, const Block3<N>& dx) {
  Block3<N> y;
  y.row(0) = a[1] * dx.row(2) - a[2] * dx.row(1);
  y.row(1) = a[2] * dx.row(0) - a[0] * dx.row(2);
  y.row(2) = a[0] * dx.row(1) - a[1] * dx.row(0);
  return y;
}

// E dx and Eᵀ dx for the rotation of a transform in the forms of joint.hpp: a plane rotation of
// two rows for an axis joint, a 3 × 3 product otherwise.
template <int N, int K>
SALTUS_INLINE Block3<N> rotate(const AxisTransform<double, K>& X, const Block3<N>& dx) {
  constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
  Block3<N> y;
  y.row(K) = dx.row(K);
  y.row(i1) = X.c * dx.row(i1) + X.s * dx.row(i2);
  y.row(i2) = X.c * dx.row(i2) - X.s * dx.row(i1);
  return y;
}
template <int N, int K>
SALTUS_INLINE Block3<N> rotateInverse(const AxisTransform<double, K>& X, const Block3<N>& dx) {
  constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
  Block3<N> y;
  y.row(K) = dx.row(K);
  y.row(i1) = X.c * dx.row(i1) - X.s * dx.row(i2);
  y.row(i2) = X.c * dx.row(i2) + X.s * dx.row(i1);
  return y;
}
template <int N>
SALTUS_INLINE Block3<N> rotate(const GeneralTransform<double>& X, const Block3<N>& dx) {
  const Mat3<double>& E = X.X.E;
  Block3<N> y;
  for (int r = 0; r < 3; ++r) y.row(r) = E(r, 0) * dx.row(0) + E(r, 1) * dx.row(1) + E(r, 2) * dx.row(2);
  return y;
}
template <int N>
SALTUS_INLINE Block3<N> rotateInverse(const GeneralTransform<double>& X, const Block3<N>& dx) {
  const Mat3<double>& E = X.X.E;
  Block3<N> y;
  for (int r = 0; r < 3; ++r) y.row(r) = E(0, r) * dx.row(0) + E(1, r) * dx.row(1) + E(2, r) * dx.row(2);
  return y;
}

// d(X m) = X dm and d(Xᵀ f) = Xᵀ df for a constant transform (RBDA 2.24, Table 2.5).
template <int N, class XForm>
SALTUS_INLINE MotionTangent<N> apply(const XForm& X, const MotionTangent<N>& dm) {
  return {rotate(X, dm.w), rotate<N>(X, Block3<N>(dm.v - cross<N>(X.r, dm.w)))};
}
template <int N, class XForm>
SALTUS_INLINE ForceTangent<N> applyTranspose(const XForm& X, const ForceTangent<N>& df) {
  const Block3<N> f = rotateInverse(X, df.f);
  return {rotateInverse(X, df.n) + cross<N>(X.r, f), f};
}

// d(m × vJ) = dm × vJ for the constant joint velocity vJ = S q̇ (RBDA 2.31); for an axis joint
// x × σq̇ e_K has components (σq̇ x_{K+2}, −σq̇ x_{K+1}) in (K+1, K+2).
template <int N, int K>
SALTUS_INLINE MotionTangent<N> crossJointVelocity(const MotionTangent<N>& dm, const AxisSubspace<double, K>& Si,
                                                  double qd) {
  constexpr int i1 = (K + 1) % 3, i2 = (K + 2) % 3;
  const double w = Si.sign * qd;
  MotionTangent<N> y;
  y.w.row(K).setZero();
  y.w.row(i1) = w * dm.w.row(i2);
  y.w.row(i2) = -w * dm.w.row(i1);
  y.v.row(K).setZero();
  y.v.row(i1) = w * dm.v.row(i2);
  y.v.row(i2) = -w * dm.v.row(i1);
  return y;
}
template <int N>
SALTUS_INLINE MotionTangent<N> crossJointVelocity(const MotionTangent<N>& dm, const GenericSubspace<double>& Si,
                                                  double qd) {  // dm × b = −(b × dm)
  const Motion<double> b = Si.velocity(qd);
  return {-cross<N>(b.w, dm.w), Block3<N>(-cross<N>(b.v, dm.w) - cross<N>(b.w, dm.v))};
}

// d(I m) = I dm for a constant rigid-body inertia (RBDA 2.62).
template <int N>
SALTUS_INLINE ForceTangent<N> inertiaTimes(const RigidInertia<double>& I, const MotionTangent<N>& dm) {
  ForceTangent<N> y;
  for (int r = 0; r < 3; ++r) y.n.row(r) = I.I(r, 0) * dm.w.row(0) + I.I(r, 1) * dm.w.row(1) + I.I(r, 2) * dm.w.row(2);
  y.n += cross<N>(I.h, dm.v);
  y.f = I.m * dm.v - cross<N>(I.h, dm.w);
  return y;
}

// d(v ×* I v) = dv ×* (I v) + v ×* (I dv) (RBDA 2.32): the force-cross product with a tangent on
// either side, for the body's bias force. Iv is the value I v.
template <int N>
SALTUS_INLINE ForceTangent<N> crossForceBoth(const Motion<double>& v, const MotionTangent<N>& dv,
                                             const Force<double>& Iv, const ForceTangent<N>& Idv) {
  // dv ×* Iv = (dω × n + dv × f, dω × f) = −(n × dω) − (f × dv), −(f × dω)
  ForceTangent<N> y;
  y.n = cross<N>(v.w, Idv.n) + cross<N>(v.v, Idv.f) - cross<N>(Iv.n, dv.w) - cross<N>(Iv.f, dv.v);
  y.f = cross<N>(v.w, Idv.f) - cross<N>(Iv.f, dv.w);
  return y;
}

// d(S_iᵀ f) = S_iᵀ df for a one-coordinate joint (S_i constant in body coordinates).
template <int N, int K>
SALTUS_INLINE Row<N> project(const AxisSubspace<double, K>& Si, const ForceTangent<N>& df) {
  return Si.sign * df.n.row(K);
}
template <int N>
SALTUS_INLINE Row<N> project(const GenericSubspace<double>& Si, const ForceTangent<N>& df) {
  const Vec3<double>& s = Si.model.axis[Si.i];
  const Block3<N>& x = Si.model.joint_type[Si.i] == JointType::Revolute ? df.n : df.f;
  return s[0] * x.row(0) + s[1] * x.row(1) + s[2] * x.row(2);
}
// sᵀ df for one column s of a multi-coordinate joint's S_i.
template <int N>
SALTUS_INLINE Row<N> project(const Motion<double>& s, const ForceTangent<N>& df) {
  return s.w[0] * df.n.row(0) + s.w[1] * df.n.row(1) + s.w[2] * df.n.row(2) + s.v[0] * df.f.row(0) +
         s.v[1] * df.f.row(1) + s.v[2] * df.f.row(2);
}

}  // namespace saltus::dynamics::tangent
