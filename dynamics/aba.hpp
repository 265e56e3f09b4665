// Articulated-body algorithm for forward dynamics q̈ = FD(q, q̇, τ) (RBDA Table 7.1).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

namespace detail {
// IA_λ += ^iX_λᵀ Ia ^iX_λ for a symmetric 6×6 articulated inertia in (angular; linear) blocks
// [A B; Bᵀ C] (RBDA 7.43 and Table 2.5), for the transform forms of withJoint. With
// X = rot(E) xlt(r) and xlt(r) = [1 0; −r× 1] (RBDA 2.8): rotate each block (M ← Eᵀ M E, as the
// rotation of the columns, then of the rows, of M), then shift by r:
//   C' = C,  B' = B + r× C,  A' = A + r× Bᵀ − B' r×.
// Entry by entry: the products with r× are taken as cross products, and the sums go straight
// into IA_λ (only the lower triangle of the symmetric A' is formed).
template <class S, class XForm>
SALTUS_INLINE void addArticulatedInertiaToParent(const XForm& X, const Mat6<S>& Ia, Mat6<S>& IA_parent) {
  Mat3<S> A, B, C;  // rotated blocks
  auto rotateBlock = [&X](const Mat6<S>& M, int r0, int c0, Mat3<S>& out) SALTUS_LAMBDA_INLINE {
    Vec3<S> EtM[3];  // rows of Eᵀ M
    for (int c = 0; c < 3; ++c) {
      const Vec3<S> col = X.rotateInverse(Vec3<S>(M(r0, c0 + c), M(r0 + 1, c0 + c), M(r0 + 2, c0 + c)));
      EtM[0][c] = col[0], EtM[1][c] = col[1], EtM[2][c] = col[2];
    }
    for (int r = 0; r < 3; ++r) {  // row r of Eᵀ M E = (Eᵀ (row r of Eᵀ M)ᵀ)ᵀ
      const Vec3<S> row = X.rotateInverse(EtM[r]);
      out(r, 0) = row[0], out(r, 1) = row[1], out(r, 2) = row[2];
    }
  };
  rotateBlock(Ia, 0, 0, A);
  rotateBlock(Ia, 0, 3, B);
  rotateBlock(Ia, 3, 3, C);
  const Vec3<S>& r = X.r;
  Mat3<S> Bn;  // B' = B + r× C, column by column
  for (int j = 0; j < 3; ++j) {
    const Vec3<S> x = cross3(r, Vec3<S>(C(0, j), C(1, j), C(2, j)));
    for (int i = 0; i < 3; ++i) Bn(i, j) = B(i, j) + x[i];
  }
  Mat3<S> rxBt, Bnrx;  // r× Bᵀ: column j is r × (row j of B); B' r×: row i is −(r × row i of B')ᵀ
  for (int j = 0; j < 3; ++j) {
    const Vec3<S> x = cross3(r, Vec3<S>(B(j, 0), B(j, 1), B(j, 2)));
    const Vec3<S> y = cross3(r, Vec3<S>(Bn(j, 0), Bn(j, 1), Bn(j, 2)));
    for (int i = 0; i < 3; ++i) rxBt(i, j) = x[i], Bnrx(j, i) = -y[i];
  }
  for (int c = 0; c < 3; ++c) {
    for (int k = c; k < 3; ++k) {
      const S a = A(k, c) + rxBt(k, c) - Bnrx(k, c);
      const S cc = C(k, c);
      IA_parent(k, c) += a;
      IA_parent(k + 3, c + 3) += cc;
      if (k != c) {
        IA_parent(c, k) += a;
        IA_parent(c + 3, k + 3) += cc;
      }
    }
    for (int k = 0; k < 3; ++k) {
      IA_parent(k, c + 3) += Bn(k, c);
      IA_parent(c + 3, k) += Bn(k, c);
    }
  }
}

// The 6 × 6 matrix of a rigid-body inertia (RBDA 2.62), entry by entry.
template <class S>
SALTUS_INLINE void setInertiaMatrix(const RigidInertia<S>& I, Mat6<S>& M) {
  const S zero(0);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) {
      M(k, c) = I.I(k, c);
      M(k + 3, c + 3) = k == c ? I.m : zero;
    }
  // [Ī h×; h×ᵀ m1]: h× = [0 −h_z h_y; h_z 0 −h_x; −h_y h_x 0].
  const Vec3<S>& h = I.h;
  M(0, 3) = zero, M(0, 4) = -h[2], M(0, 5) = h[1];
  M(1, 3) = h[2], M(1, 4) = zero, M(1, 5) = -h[0];
  M(2, 3) = -h[1], M(2, 4) = h[0], M(2, 5) = zero;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) M(c + 3, k) = M(k, c + 3);
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
    detail::addArticulatedInertiaToParent(GeneralTransform<S>{data.X_up[i]}, Ia, data.IA[p]);
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
// s_θ = (0, cφ, −sφ), s_φ = x invert directly (a quaternion base's rotation columns are e_k).
// Pass 2 has nothing to do for this joint.
template <class S>
[[gnu::noinline]] Motion<S> abaFreeRoot(const Model<S>& model, Data<S>& data, int i, const VecRef<S>& tau,
                                        const Motion<S>& ap) {
  const int k = model.first_coordinate[i];
  const Motion<S>* Scol = &data.S_joint[k];
  const S* t = tau.data() + k;
  const bool quaternion = model.joint_type[i] == JointType::FreeQuaternion;
  // f_J = S⁻ᵀ τ. A quaternion base's rotation columns are e_k: its moment is τ_ω itself.
  S cr(0), sr(0), sp(0), cp(1);
  Vec6<S> rhs;
  if (quaternion) {
    rhs << t[3], t[4], t[5], Scol[0].v * t[0] + Scol[1].v * t[1] + Scol[2].v * t[2];
  } else {
    cr = Scol[4].w[1], sr = -Scol[4].w[2], sp = -Scol[3].w[0];
    cp = Scol[3].w[1] * sr + Scol[3].w[2] * cr;
    const S A = (t[3] + sp * t[5]) / cp;
    rhs << t[5], sr * A + cr * t[4], cr * A - sr * t[4], Scol[0].v * t[0] + Scol[1].v * t[1] + Scol[2].v * t[2];
  }
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
  if (quaternion) {
    for (int c = 0; c < 3; ++c) x[3 + c] = d.w[c];
  } else {
    x[3] = (sr * d.w[1] + cr * d.w[2]) / cp;
    x[4] = cr * d.w[1] - sr * d.w[2];
    x[5] = d.w[0] + sp * x[3];
  }
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
// or after (pass 2) the loops over the one-coordinate joints, out of line. In the loops each
// joint is taken in the forms of its kernel (withJoint): for an axis joint U = IA S is a column
// of IA, D = Sᵀ U a component, and ^iX_λ a plane rotation and a cross product.
template <class S>
const VecX<S>& aba(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                   const VecRef<S>& v, const VecRef<S>& tau) {
  checkConfigurationSize(model, q.size(), "aba", "q");
  checkArgumentSize(model, v.size(), "aba", "v");
  checkArgumentSize(model, tau.size(), "aba", "tau");
  const int nb = model.nbodies();
  const int b = nb > 0 && model.num_coordinates[0] > 1 ? 1 : 0;  // first one-coordinate body
  const int off = model.nv() - nb;                                // its coordinate k = i + off
  // Pass 1: velocities, velocity-product accelerations c_i = c_J + v_i × v_J, bias forces p_i
  // (RBDA 7.1, 7.2).
  if (b) detail::abaMultiJointOutwardVelocity(model, data, q, v);
  // Joint transforms (jcalc) in a loop of their own (its libm calls would otherwise spill the
  // registers of the loop below).
  updateOneCoordinateJointTransforms(model, data, q);
  for (int i = b; i < nb; ++i) {
    const int p = model.parent[i], k = i + off;
    withEvaluatedJoint(model, data.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
      Motion<S> vi;
      if (p < 0) {
        vi = Si.velocity(v[k]);
        data.c[i] = Motion<S>{Vec3<S>(S(0), S(0), S(0)), Vec3<S>(S(0), S(0), S(0))};
      } else {
        vi = X.apply(data.v[p]);
        Si.addTo(vi, v[k]);
        data.c[i] = Si.crossVelocity(vi, v[k]);  // v_i × S_i q̇_i
      }
      data.v[i] = vi;
      const RigidInertia<S>& I = model.inertia[i];
      detail::setInertiaMatrix(I, data.IA[i]);
      data.pA[i] = vi.crossForce(I * vi);
    });
  }
  // Pass 2: articulated inertias and bias forces, leaves to root (RBDA 7.43–7.45).
  for (int i = nb - 1; i >= b; --i) {
    const int p = model.parent[i], k = i + off;
    withEvaluatedJoint(model, data.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
      const Mat6<S>& IA = data.IA[i];
      Vec6<S>& U = data.U[k];
      Si.matrixTimes(IA, U);                             // U = IA S
      const S D = Si.project6(U);                        // D = Sᵀ U
      const S u = tau[k] - Si.project(data.pA[i]);       // u = τ − Sᵀ p^A
      data.D[k] = D;
      data.u[k] = u;
      if (p < 0) return;
      // Ia = IA − U D⁻¹ Uᵀ,  pa = p^A + Ia c + U D⁻¹ u.
      const S Dinv = S(1) / D;
      S UD[6];
      for (int r = 0; r < 6; ++r) UD[r] = U[r] * Dinv;
      Mat6<S> Ia;
      for (int c = 0; c < 6; ++c)
        for (int r = c; r < 6; ++r) Ia(r, c) = Ia(c, r) = IA(r, c) - UD[r] * U[c];
      const Motion<S>& ci = data.c[i];
      const S cv[6] = {ci.w[0], ci.w[1], ci.w[2], ci.v[0], ci.v[1], ci.v[2]};
      S pa[6];
      const Force<S>& pA = data.pA[i];
      const S pAv[6] = {pA.n[0], pA.n[1], pA.n[2], pA.f[0], pA.f[1], pA.f[2]};
      for (int r = 0; r < 6; ++r) {
        S x = pAv[r] + UD[r] * u;
        for (int c = 0; c < 6; ++c) x += Ia(r, c) * cv[c];
        pa[r] = x;
      }
      detail::addArticulatedInertiaToParent(X, Ia, data.IA[p]);
      data.pA[p] += X.applyTranspose(Force<S>{Vec3<S>(pa[0], pa[1], pa[2]), Vec3<S>(pa[3], pa[4], pa[5])});
    });
  }
  const bool free_root = b && (model.joint_type[0] == JointType::Free || model.joint_type[0] == JointType::FreeQuaternion);
  if (b && !free_root) detail::abaMultiJointInward(model, data, 0, tau);  // a free root: pass 3 only
  // Pass 3: accelerations, root to leaves (RBDA 7.46, 7.47).
  const Motion<S> a0{Vec3<S>(S(0), S(0), S(0)), Vec3<S>(S(-model.gravity[0]), S(-model.gravity[1]), S(-model.gravity[2]))};
  if (b) {
    const Motion<S> ap = data.X_up[0].apply(a0) + data.c[0];
    data.a_gf[0] = free_root ? detail::abaFreeRoot(model, data, 0, tau, ap) : detail::abaMultiJointOutward(model, data, 0, ap);
  }
  for (int i = b; i < nb; ++i) {
    const int p = model.parent[i], k = i + off;
    withEvaluatedJoint(model, data.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
      Motion<S> ap = X.apply(p < 0 ? a0 : data.a_gf[p]) + data.c[i];  // a' = ^iX_λ a_λ + c_i
      const Vec6<S>& U = data.U[k];
      const S Ua = U[0] * ap.w[0] + U[1] * ap.w[1] + U[2] * ap.w[2] + U[3] * ap.v[0] + U[4] * ap.v[1] + U[5] * ap.v[2];
      const S qdd = (data.u[k] - Ua) / data.D[k];
      data.qdd[k] = qdd;
      Si.addTo(ap, qdd);
      data.a_gf[i] = ap;
    });
  }
  return data.qdd;
}

}  // namespace saltus::dynamics
