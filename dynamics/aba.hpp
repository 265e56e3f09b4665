// Articulated-body algorithm for forward dynamics q̈ = FD(q, q̇, τ) (RBDA Table 7.1).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

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

// In-place Cholesky factor L (lower triangle) of the leading n × n block of a symmetric
// positive definite A; and solves with it. For the n_i × n_i block D_i of a multi-coordinate
// joint (RBDA 7.44).
template <class S>
void choleskyInPlace(Mat6<S>& A, int n) {
  using std::sqrt;
  for (int j = 0; j < n; ++j) {
    S d = A(j, j);
    for (int k = 0; k < j; ++k) d -= A(j, k) * A(j, k);
    A(j, j) = sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      S x = A(i, j);
      for (int k = 0; k < j; ++k) x -= A(i, k) * A(j, k);
      A(i, j) = x / A(j, j);
    }
  }
}
template <class S>
void solveLower(const Mat6<S>& L, int n, S* x) {  // x ← L⁻¹ x
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < i; ++k) x[i] -= L(i, k) * x[k];
    x[i] /= L(i, i);
  }
}
template <class S>
void solveUpper(const Mat6<S>& L, int n, S* x) {  // x ← L⁻ᵀ x
  for (int i = n - 1; i >= 0; --i) {
    for (int k = i + 1; k < n; ++k) x[i] -= L(k, i) * x[k];
    x[i] /= L(i, i);
  }
}
// Passes 2 and 3 of aba() for a multi-coordinate joint, out of line: they run once per call
// (the base), and inlined they slow the one-coordinate loops.
//
// Pass 2 (RBDA 7.43–7.45): U = IA S, D = Sᵀ U = L Lᵀ, u = τ − Sᵀ p^A.
template <class S>
[[gnu::noinline]] void abaMultiJointInward(const Model<S>& model, Data<S>& data, int i, const VecRef<S>& tau) {
  const Mat6<S>& IA = data.IA[i];
  const int p = model.parent[i], k = model.first_coordinate[i];
  const int nc = model.num_coordinates[i];
  const Motion<S>* Scol = &data.S_joint[k];
  Mat6<S>& L = data.D_chol[i];
  for (int c = 0; c < nc; ++c) data.U[k + c] = detail::times(IA, Scol[c]);
  for (int c = 0; c < nc; ++c)
    for (int r = c; r < nc; ++r) L(r, c) = Scol[r].vector().dot(data.U[k + c]);
  detail::choleskyInPlace(L, nc);
  for (int c = 0; c < nc; ++c) data.u[k + c] = tau[k + c] - dot(Scol[c], data.pA[i]);
  if (p >= 0) {
    // Ia = IA − U D⁻¹ Uᵀ = IA − W Wᵀ and U D⁻¹ u = W y, with W = U L⁻ᵀ and y = L⁻¹ u.
    Eigen::Matrix<S, 6, 6> W;
    S y[6];
    for (int c = 0; c < nc; ++c) y[c] = data.u[k + c];
    detail::solveLower(L, nc, y);
    for (int r = 0; r < 6; ++r) {
      S w[6];
      for (int c = 0; c < nc; ++c) w[c] = data.U[k + c][r];
      detail::solveLower(L, nc, w);  // row r of W: L⁻¹ (row r of U)ᵀ
      for (int c = 0; c < nc; ++c) W(r, c) = w[c];
    }
    Mat6<S> Ia = IA;
    Vec6<S> Wy = Vec6<S>::Zero();
    for (int c = 0; c < nc; ++c) {
      Ia -= W.col(c) * W.col(c).transpose();
      Wy += W.col(c) * y[c];
    }
    const Vec6<S> pa = data.pA[i].vector() + detail::times(Ia, data.c[i]) + Wy;
    data.IA[p] += detail::transformArticulatedInertia(Ia, data.X_up[i]);
    data.pA[p] += data.X_up[i].applyTranspose(Force<S>::FromVector(pa));
  }
}

// Pass 3 (RBDA 7.46, 7.47): q̈_i = D⁻¹ (u − Uᵀ a'), a_i = a' + S q̈_i, given a' = ^iX_λ a_λ + c_i.
template <class S>
[[gnu::noinline]] Motion<S> abaMultiJointOutward(const Model<S>& model, Data<S>& data, int i, const Motion<S>& ap) {
  const int k = model.first_coordinate[i], nc = model.num_coordinates[i];
  const Vec6<S> apv = ap.vector();
  S* x = data.qdd.data() + k;
  for (int c = 0; c < nc; ++c) x[c] = data.u[k + c] - data.U[k + c].dot(apv);
  solveLower(data.D_chol[i], nc, x);
  solveUpper(data.D_chol[i], nc, x);
  return ap + multiJointVelocity(model, i, &data.S_joint[k], x);
}

// Pass 3 for a free joint from the world (RBDA 7.46, 7.47 with a square, invertible S): the
// joint force f_J = S⁻ᵀ τ balances the root's articulated body, f_J = I^A a + p^A, so
// a = (I^A)⁻¹ (f_J − p^A) and q̈ = S⁻¹ (a − a'). Both S solves are closed form: the translation
// columns (0; s_k) are orthonormal, and the Euler columns s_ψ = (−sθ, cθ sφ, cθ cφ),
// s_θ = (0, cφ, −sφ), s_φ = x invert directly. Pass 2 has nothing to do for this joint.
template <class S>
[[gnu::noinline]] Motion<S> abaFreeRoot(const Model<S>& model, Data<S>& data, int i, const VecRef<S>& tau,
                                        const Motion<S>& ap) {
  const int k = model.first_coordinate[i];
  const Motion<S>* Scol = &data.S_joint[k];
  const S* t = tau.data() + k;
  const S cr = Scol[4].w[1], sr = -Scol[4].w[2], sp = -Scol[3].w[0];
  const S cp = Scol[3].w[1] * sr + Scol[3].w[2] * cr;
  // f_J = S⁻ᵀ τ.
  const S A = (t[3] + sp * t[5]) / cp;
  Vec6<S> rhs;
  rhs << t[5], sr * A + cr * t[4], cr * A - sr * t[4],
         Scol[0].v * t[0] + Scol[1].v * t[1] + Scol[2].v * t[2];
  rhs -= data.pA[i].vector();
  // a = (I^A)⁻¹ (f_J − p^A), by Cholesky.
  Mat6<S>& L = data.D_chol[i];
  L = data.IA[i];
  choleskyInPlace(L, 6);
  solveLower(L, 6, rhs.data());
  solveUpper(L, 6, rhs.data());
  const Motion<S> a = Motion<S>::FromVector(rhs);
  // q̈ = S⁻¹ (a − a').
  const Motion<S> d = a - ap;
  S* x = data.qdd.data() + k;
  for (int c = 0; c < 3; ++c) x[c] = Scol[c].v.dot(d.v);
  x[3] = (sr * d.w[1] + cr * d.w[2]) / cp;
  x[4] = cr * d.w[1] - sr * d.w[2];
  x[5] = d.w[0] + sp * x[3];
  return a;
}
}  // namespace detail

namespace detail {
// Pass 1 for body 0's multi-coordinate joint from the world, out of line (see above).
template <class S>
[[gnu::noinline]] void abaMultiJointOutwardVelocity(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                                                   const VecRef<S>& v) {
  updateJointTransform(model, data, 0, q);
  data.v[0] = jointVelocity(model, data, 0, v, &data.c[0]);  // v = v_J, c = c_J
  const RigidInertia<S>& I = model.inertia[0];
  data.IA[0] = I.matrix();
  data.pA[0] = data.v[0].crossForce(I * data.v[0]);
}
}  // namespace detail

// Fills data.qdd (and X_up, v, c, IA, pA, U, D, u; D_chol for multi-coordinate joints; for a
// free joint from the world D_chol holds the Cholesky factor of I^A and U, D, u are not set).
// A multi-coordinate joint can only be body 0's (model.hpp): it is handled before (passes 1, 3)
// or after (pass 2) the loops over the one-coordinate joints, out of line.
template <class S>
const VecX<S>& aba(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                   const VecRef<S>& v, const VecRef<S>& tau) {
  const int nb = model.nbodies();
  const int b = nb > 0 && model.num_coordinates[0] > 1 ? 1 : 0;  // first one-coordinate body
  const int off = model.nv() - nb;                                // its coordinate k = i + off
  // Pass 1: velocities, velocity-product accelerations c_i = c_J + v_i × v_J, bias forces p_i
  // (RBDA 7.1, 7.2).
  if (b) detail::abaMultiJointOutwardVelocity(model, data, q, v);
  for (int i = b; i < nb; ++i) {
    const int p = model.parent[i], k = i + off;
    data.X_up[i] = jointTransformUp(model, i, q[k]);
    const Motion<S> vJ = jointVelocity(model, i, v[k]);
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
  for (int i = nb - 1; i >= b; --i) {
    const Mat6<S>& IA = data.IA[i];
    const int p = model.parent[i], k = i + off;
    Vec6<S>& U = data.U[k];
    const Vec3<S>& ax = model.axis[i];
    U = model.joint_type[i] == JointType::Revolute ? Vec6<S>(IA.template leftCols<3>() * ax)
                                                   : Vec6<S>(IA.template rightCols<3>() * ax);  // U = IA S
    const Vec3<S> Utop = model.joint_type[i] == JointType::Revolute ? Vec3<S>(U.template head<3>())
                                                                      : Vec3<S>(U.template tail<3>());
    data.D[k] = ax.dot(Utop);                                  // D = Sᵀ U
    data.u[k] = tau[k] - jointForce(model, i, data.pA[i]);     // u = τ − Sᵀ p^A
    if (p >= 0) {
      const Mat6<S> Ia = IA - U * (U.transpose() / data.D[k]);  // RBDA 7.43
      const Vec6<S> pa = data.pA[i].vector() + detail::times(Ia, data.c[i]) + U * (data.u[k] / data.D[k]);
      data.IA[p] += detail::transformArticulatedInertia(Ia, data.X_up[i]);
      data.pA[p] += data.X_up[i].applyTranspose(Force<S>::FromVector(pa));
    }
  }
  const bool free_root = b && model.joint_type[0] == JointType::Free;
  if (b && !free_root) detail::abaMultiJointInward(model, data, 0, tau);  // a free root: pass 3 only
  // Pass 3: accelerations, root to leaves (RBDA 7.46, 7.47).
  const Motion<S> a0{Vec3<S>::Zero(), -model.gravity};
  if (b) {
    const Motion<S> ap = data.X_up[0].apply(a0) + data.c[0];
    data.a_gf[0] = free_root ? detail::abaFreeRoot(model, data, 0, tau, ap) : detail::abaMultiJointOutward(model, data, 0, ap);
  }
  for (int i = b; i < nb; ++i) {
    const int p = model.parent[i], k = i + off;
    const Motion<S> ap = data.X_up[i].apply(p < 0 ? a0 : data.a_gf[p]) + data.c[i];
    data.qdd[k] = (data.u[k] - data.U[k].dot(ap.vector())) / data.D[k];
    data.a_gf[i] = ap + jointVelocity(model, i, data.qdd[k]);
  }
  return data.qdd;
}

}  // namespace saltus::dynamics
