// Articulated-body algorithm for forward dynamics q̈ = FD(q, q̇, τ) (RBDA Table 7.1).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"

namespace saltus::dynamics {

namespace detail {
// Eᵀ S E for a symmetric 3×3 S: one triangle computed, mirrored.
template <class S, class Block>
SALTUS_INLINE Mat3<S> symmetricSandwich(const Mat3<S>& E, const Block& Sym) {
  Mat3<S> SE, out;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) SE(k, c) = Sym(k, 0) * E(0, c) + Sym(k, 1) * E(1, c) + Sym(k, 2) * E(2, c);
  for (int c = 0; c < 3; ++c)
    for (int k = c; k < 3; ++k) out(k, c) = out(c, k) = E(0, k) * SE(0, c) + E(1, k) * SE(1, c) + E(2, k) * SE(2, c);
  return out;
}

// Xᵀ IA X for a symmetric 6×6 articulated inertia in (angular; linear) blocks [A B; Bᵀ C] and
// X = rot(E) xlt(r), xlt(r) = [1 0; −r× 1] (RBDA 2.8): rotate each block, then shift by r:
//   C' = C,  B' = B + r× C,  A' = A + r× Bᵀ − B' r×   (A', C' symmetric).
// The products with r× are taken as cross products.
template <class S>
Mat6<S> transformArticulatedInertia(const Mat6<S>& IA, const Transform<S>& X) {
  const Mat3<S>& E = X.E;
  const Vec3<S>& r = X.r;
  const Mat3<S> A = symmetricSandwich(E, IA.template topLeftCorner<3, 3>());
  const Mat3<S> C = symmetricSandwich(E, IA.template bottomRightCorner<3, 3>());
  const Mat3<S> B = E.transpose() * IA.template topRightCorner<3, 3>() * E;
  Mat3<S> Bn;  // B + r× C, column by column
  for (int j = 0; j < 3; ++j) Bn.col(j) = B.col(j) + r.cross(Vec3<S>(C.col(j)));
  Mat6<S> out;
  // r× Bᵀ: column j is r × (row j of B); B' r×: row i is −(r × row i of B')ᵀ.
  Mat3<S> rxBt, Bnrx;
  for (int j = 0; j < 3; ++j) rxBt.col(j) = r.cross(Vec3<S>(B.row(j).transpose()));
  for (int i = 0; i < 3; ++i) Bnrx.row(i) = -r.cross(Vec3<S>(Bn.row(i).transpose())).transpose();
  for (int c = 0; c < 3; ++c)
    for (int k = c; k < 3; ++k) out(k, c) = out(c, k) = A(k, c) + rxBt(k, c) - Bnrx(k, c);
  out.template topRightCorner<3, 3>() = Bn;
  out.template bottomLeftCorner<3, 3>() = Bn.transpose();
  out.template bottomRightCorner<3, 3>() = C;
  return out;
}

template <class S>
Vec6<S> times(const Mat6<S>& I, const Motion<S>& m) {
  return I.template leftCols<3>() * m.w + I.template rightCols<3>() * m.v;
}
}  // namespace detail

// Fills data.qdd (and X_up, v, c, IA, pA, U, D, u).
template <class S>
const VecX<S>& aba(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                   const VecRef<S>& v, const VecRef<S>& tau) {
  const int n = model.nv();
  // Pass 1: velocities, velocity-product accelerations c_i, bias forces p_i (RBDA 7.1, 7.2).
  for (int i = 0; i < n; ++i) {
    const int p = model.parent[i];
    data.X_up[i] = jointTransformUp(model, i, q[i]);
    const Motion<S> vJ = jointVelocity(model, i, v[i]);
    if (p < 0) {
      data.v[i] = vJ;
      data.c[i] = Motion<S>::Zero();
    } else {
      data.v[i] = data.X_up[i].apply(data.v[p]) + vJ;
      data.c[i] = data.v[i].cross(vJ);
    }
    const RigidInertia<S>& I = model.inertia[i];
    data.IA[i] = I.matrix();
    data.pA[i] = data.v[i].crossForce(I * data.v[i]);
  }
  // Pass 2: articulated inertias and bias forces, leaves to root.
  for (int i = n - 1; i >= 0; --i) {
    const Mat6<S>& IA = data.IA[i];
    Vec6<S>& U = data.U[i];
    const Vec3<S>& ax = model.axis[i];
    U = model.joint_type[i] == JointType::Revolute ? Vec6<S>(IA.template leftCols<3>() * ax)
                                                   : Vec6<S>(IA.template rightCols<3>() * ax);  // U = IA S
    const Vec3<S> Utop = model.joint_type[i] == JointType::Revolute ? Vec3<S>(U.template head<3>())
                                                                      : Vec3<S>(U.template tail<3>());
    data.D[i] = ax.dot(Utop);                                  // D = Sᵀ U
    data.u[i] = tau[i] - jointForce(model, i, data.pA[i]);     // u = τ − Sᵀ p^A
    const int p = model.parent[i];
    if (p >= 0) {
      const Mat6<S> Ia = IA - U * (U.transpose() / data.D[i]);  // RBDA 7.43
      const Vec6<S> pa = data.pA[i].vector() + detail::times(Ia, data.c[i]) + U * (data.u[i] / data.D[i]);
      data.IA[p] += detail::transformArticulatedInertia(Ia, data.X_up[i]);
      data.pA[p] += data.X_up[i].applyTranspose(Force<S>::FromVector(pa));
    }
  }
  // Pass 3: accelerations, root to leaves.
  const Motion<S> a0{Vec3<S>::Zero(), -model.gravity};
  for (int i = 0; i < n; ++i) {
    const int p = model.parent[i];
    const Motion<S> ap = data.X_up[i].apply(p < 0 ? a0 : data.a_gf[p]) + data.c[i];
    data.qdd[i] = (data.u[i] - data.U[i].dot(ap.vector())) / data.D[i];
    data.a_gf[i] = ap + jointVelocity(model, i, data.qdd[i]);
  }
  return data.qdd;
}

}  // namespace saltus::dynamics
