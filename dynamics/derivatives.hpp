// Derivatives of inverse and forward dynamics by forward-mode automatic differentiation
// through the same scalar-templated algorithms (rnea.hpp, aba.hpp).
//
// Directions are propagated in chunks of N at a time with fixed-size derivative vectors
// (Eigen::AutoDiffScalar<Matrix<double, N, 1>>), so no heap is touched inside a call: generic
// dynamic-size AD is what makes AD dynamics slow (Drake issue #8482: ~140× for M(q)).
#pragma once

#include "dynamics/aba.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/data.hpp"
#include "dynamics/rnea.hpp"

#include <unsupported/Eigen/AutoDiff>  // after Eigen/Core

#include <algorithm>
#include <vector>

namespace saltus::dynamics {

template <int N>
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;

// Workspace for the derivative algorithms: the model cast to dual numbers once, its Data, and
// the results.
template <int N = 8>
struct DerivativeData {
  explicit DerivativeData(const Model<double>& model)
      : model_dual(model.template cast<Dual<N>>()),
        data_dual(model_dual),
        data(model),
        q(model.nv()), v(model.nv()), w(model.nv()),
        dtau_dq(model.nv(), model.nv()), dtau_dv(model.nv(), model.nv()),
        dqdd_dq(model.nv(), model.nv()), dqdd_dv(model.nv(), model.nv()), dqdd_dtau(model.nv(), model.nv()),
        subtree_end(model.nbodies()), g_n(model.nbodies(), Eigen::Matrix<double, 3, N>::Zero()),
        g_f(model.nbodies(), Eigen::Matrix<double, 3, N>::Zero()), touched(model.nbodies(), false),
        active(model.nbodies(), false) {
    // subtree_end[i]: one past the largest body index in the subtree of body i.
    for (int i = 0; i < model.nbodies(); ++i) subtree_end[i] = i + 1;
    for (int i = model.nbodies() - 1; i >= 0; --i)
      if (model.parent[i] >= 0) subtree_end[model.parent[i]] = std::max(subtree_end[model.parent[i]], subtree_end[i]);
    // The directions of rneaDerivatives in coordinate order, q_k then q̇_k, N to a chunk. The base
    // translation coordinates (x, y, z of a free base; x, z of a planar one) have none: RNEA does
    // not depend on where the robot is (uniform gravity) nor, by Galilean invariance, on the
    // world velocity ṗ of the base origin (ṗ drops out of every classical acceleration), so
    // those columns of ∂τ/∂q and ∂τ/∂q̇ are zero.
    const bool floating = model.nbodies() > 0 && model.parent[0] < 0 &&
                          (model.joint_type[0] == JointType::Free || model.joint_type[0] == JointType::Planar);
    const int invariant = floating ? (model.joint_type[0] == JointType::Free ? 3 : 2) : 0;
    Chunk chunk;
    auto add = [&](int k, bool velocity) {
      chunk.coordinate[chunk.size] = k;
      chunk.velocity[chunk.size] = velocity;
      if (++chunk.size == N) chunks.push_back(chunk), chunk = Chunk{};
    };
    for (int k = invariant; k < model.nv(); ++k) {
      add(k, false);
      add(k, true);
    }
    if (chunk.size > 0) chunks.push_back(chunk);
  }

  // A chunk of rneaDerivatives: directions (coordinate, q or q̇), consecutive in coordinate order.
  struct Chunk {
    int size = 0;
    int coordinate[N] = {};
    bool velocity[N] = {};
  };
  std::vector<Chunk> chunks;

  Model<Dual<N>> model_dual;
  Data<Dual<N>> data_dual;
  Data<double> data;            // double workspace (M for ∂τ/∂q̈)
  VecX<Dual<N>> q, v, w;        // seeded inputs (w: q̈ for RNEA, τ for ABA)
  MatX<double> dtau_dq, dtau_dv;               // RNEA: ∂τ/∂q, ∂τ/∂q̇ (∂τ/∂q̈ = M is data.M)
  MatX<double> dqdd_dq, dqdd_dv, dqdd_dtau;    // ABA: ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ (= M⁻¹)

  // rneaDerivatives' scratch, per body: subtree extents and the derivative of the force each
  // ancestor receives from the current chunk (moment and force rows, one column per direction).
  std::vector<int> subtree_end;
  std::vector<Eigen::Matrix<double, 3, N>, Eigen::aligned_allocator<Eigen::Matrix<double, 3, N>>> g_n, g_f;
  std::vector<bool> touched;
  std::vector<bool> active;  // body reached by the current chunk
};

namespace detail {
// Sets the inputs' values and seeds directions [first, first + N) of the stacked input
// (x0; x1; x2), each of size n.
template <int N>
void seed(VecX<Dual<N>>& x0, VecX<Dual<N>>& x1, VecX<Dual<N>>& x2, const VecRef<double>& v0,
          const VecRef<double>& v1, const VecRef<double>& v2, int first) {
  const int n = static_cast<int>(x0.size());
  VecX<Dual<N>>* xs[3] = {&x0, &x1, &x2};
  const VecRef<double>* vs[3] = {&v0, &v1, &v2};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < n; ++i) {
      Dual<N>& d = (*xs[k])[i];
      d.value() = (*vs[k])[i];
      d.derivatives().setZero();
      const int dir = k * n + i - first;
      if (dir >= 0 && dir < N) d.derivatives()[dir] = 1.0;
    }
}

// Copies the derivative columns [first, first + N) of y into the stacked Jacobian blocks.
template <int N>
void extract(const VecX<Dual<N>>& y, int first, int ndir, MatX<double>* blocks[3]) {
  const int n = static_cast<int>(y.size());
  for (int c = 0; c < N && first + c < ndir; ++c) {
    const int dir = first + c;
    MatX<double>& J = *blocks[dir / n];
    for (int i = 0; i < n; ++i) J(i, dir % n) = y[i].derivatives()[c];
  }
}

// Mixed double × dual spatial operations: the model's constants (transforms of bodies whose
// coordinates are not seeded, inertias, joint axes) stay double, so each product with a dual
// vector costs one scaled derivative instead of the two of a dual × dual product.
template <class D>
SALTUS_INLINE Motion<D> apply(const Transform<double>& X, const Motion<D>& m) {  // X m
  const Vec3<D> v = m.v - X.r.cross(m.w);
  return {X.E * m.w, X.E * v};
}
template <class D>
SALTUS_INLINE Force<D> applyTranspose(const Transform<double>& X, const Force<D>& f) {  // Xᵀ f
  const Vec3<D> ff = X.E.transpose() * f.f;
  const Vec3<D> n = X.E.transpose() * f.n;
  return {n + X.r.cross(ff), ff};
}
template <class D>
SALTUS_INLINE Motion<D> plus(const Motion<D>& a, const Motion<double>& b) {
  return {a.w + b.w, a.v + b.v};
}
template <class D>
SALTUS_INLINE Motion<D> cross(const Motion<D>& a, const Motion<double>& b) {  // crm(a) b
  return {a.w.cross(b.w), a.w.cross(b.v) + a.v.cross(b.w)};
}
template <class D>
SALTUS_INLINE Force<D> times(const RigidInertia<double>& I, const Motion<D>& v) {  // I v (RBDA 2.62)
  return {I.I * v.w + I.h.cross(v.v), I.m * v.v - I.h.cross(v.w)};
}
// f = I a + v ×* I v (RBDA 5.9) with a double inertia.
template <class D>
SALTUS_INLINE Force<D> bodyForce(const RigidInertia<double>& I, const Motion<D>& a, const Motion<D>& v) {
  const Force<D> Iv = times(I, v);
  const Force<D> Ia = times(I, a);
  return {Ia.n + v.w.cross(Iv.n) + v.v.cross(Iv.f), Ia.f + v.w.cross(Iv.f)};
}
// Derivative row of S_iᵀ f for a one-coordinate joint with the double model's axis.
template <int N>
SALTUS_INLINE Eigen::Matrix<double, 1, N> jointForceDerivative(const Model<double>& model, int i, const Force<Dual<N>>& f) {
  const Vec3<Dual<N>>& x = model.joint_type[i] == JointType::Revolute ? f.n : f.f;
  const int k = model.axis_kind[i];
  if (k >= 0) return x[k].derivatives().transpose();
  const Vec3<double>& a = model.axis[i];
  return (a[0] * x[0].derivatives() + a[1] * x[1].derivatives() + a[2] * x[2].derivatives()).transpose();
}
}  // namespace detail

// ∂τ/∂q and ∂τ/∂q̇ of τ = RNEA(q, q̇, q̈) into dd.dtau_dq, dd.dtau_dv; ∂τ/∂q̈ = M(q) into
// dd.data.M (CRBA: RNEA is linear in q̈).
//
// A direction q_j or q̇_j changes the outward recursion only in the subtree of j's body and the
// inward one only there and along its ancestors. Each chunk takes N consecutive directions
// (dd.chunks), runs the outward and inward steps in dual numbers over the bodies the chunk
// reaches, and carries the derivative of the force transmitted to the ancestors as a plain
// 6 × N matrix; everything else keeps the values of one double RNEA pass.
template <int N>
void rneaDerivatives(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                     const VecRef<double>& v, const VecRef<double>& a) {
  using D = Dual<N>;
  using DerN = Eigen::Matrix<double, 3, N>;
  using RowN = Eigen::Matrix<double, 1, N>;
  Data<double>& dat = dd.data;
  Data<D>& dual = dd.data_dual;
  const Model<D>& mdual = dd.model_dual;
  rnea(model, dat, q, v, a);  // values of every body
  dd.dtau_dq.setZero();
  dd.dtau_dv.setZero();
  const Motion<double> a0{Vec3<double>::Zero(), -model.gravity};
  auto promote = [](const Motion<double>& m) { return Motion<D>{m.w.template cast<D>(), m.v.template cast<D>()}; };
  for (const auto& chunk : dd.chunks) {
    // Bodies [b0, b1] hold the chunk's coordinates; the active bodies are those and their
    // subtrees, [b0, end) less the bodies below an ancestor of b0 (their derivatives are zero).
    const int b0 = model.coordinate_body[chunk.coordinate[0]];
    const int b1 = model.coordinate_body[chunk.coordinate[chunk.size - 1]];
    int end = b1 + 1;
    for (int b = b0; b <= b1; ++b) end = std::max(end, dd.subtree_end[b]);
    // Outward over the active bodies (RBDA 5.7–5.9 in dual numbers).
    for (int i = b0; i < end; ++i) {
      if (i > b1 && !(model.parent[i] >= b0 && dd.active[model.parent[i]])) {
        dd.active[i] = false;
        continue;
      }
      dd.active[i] = true;
      const int p = model.parent[i], k0 = model.first_coordinate[i], nc = model.num_coordinates[i];
      Motion<D> vi, ai;
      if (i <= b1) {
        // A body holding seeded coordinates: its joint transform is dual (model_dual's jcalc).
        D qi[6], qdi[6];
        for (int c = 0; c < nc; ++c) {
          qi[c] = D(q[k0 + c]);
          qdi[c] = D(v[k0 + c]);
        }
        for (int d = 0; d < chunk.size; ++d) {
          const int c = chunk.coordinate[d] - k0;
          if (c >= 0 && c < nc) (chunk.velocity[d] ? qdi[c] : qi[c]).derivatives()[d] = 1.0;
        }
        Motion<D> vJ, aJ;
        if (nc == 1) {
          dual.X_up[i] = jointTransformUp(mdual, i, qi[0]);
          vJ = jointVelocity(mdual, i, qdi[0]);
          aJ = promote(jointVelocity(model, i, a[k0]));
        } else {
          Motion<D>* Scol = &dual.S_joint[k0];
          dual.X_up[i] = multiJointTransformUp(mdual, i, qi, Scol);
          vJ = multiJointVelocity(mdual, i, Scol, qdi);
          D ad[6];
          for (int c = 0; c < nc; ++c) ad[c] = D(a[k0 + c]);
          aJ = multiJointVelocity(mdual, i, Scol, ad) + multiJointBias(mdual, i, Scol, qdi, vJ);
        }
        const Transform<D>& X = dual.X_up[i];
        if (p < 0) {
          vi = vJ;
          ai = X.apply(promote(a0)) + aJ;
        } else {
          const bool dual_parent = p >= b0;
          vi = X.apply(dual_parent ? dual.v[p] : promote(dat.v[p])) + vJ;
          ai = X.apply(dual_parent ? dual.a_gf[p] : promote(dat.a_gf[p])) + aJ + vi.cross(vJ);
        }
      } else {
        // Below the chunk: the joint is constant (double transform and S), the parent is dual.
        const Transform<double>& X = dat.X_up[i];
        Motion<double> vJ, aJ;
        if (nc == 1) {
          vJ = jointVelocity(model, i, v[k0]);
          aJ = jointVelocity(model, i, a[k0]);
        } else {
          vJ = multiJointVelocity(model, i, &dat.S_joint[k0], v.data() + k0);
          aJ = multiJointVelocity(model, i, &dat.S_joint[k0], a.data() + k0) +
               multiJointBias(model, i, &dat.S_joint[k0], v.data() + k0, vJ);
        }
        vi = detail::plus(detail::apply(X, dual.v[p]), vJ);
        ai = detail::plus(detail::apply(X, dual.a_gf[p]), aJ) + detail::cross(vi, vJ);
      }
      dual.v[i] = vi;
      dual.a_gf[i] = ai;
      dual.f[i] = model.massless[i] ? Force<D>::Zero() : detail::bodyForce(model.inertia[i], ai, vi);
    }
    // Inward over the same bodies; forces leaving the range go to dd.g_n/g_f of the ancestor.
    auto store = [&](int k, const RowN& dtau) {
      for (int d = 0; d < chunk.size; ++d) (chunk.velocity[d] ? dd.dtau_dv : dd.dtau_dq)(k, chunk.coordinate[d]) = dtau[d];
    };
    for (int i = end - 1; i >= b0; --i) {
      if (!dd.active[i]) continue;
      const int p = model.parent[i];
      Force<D> F;
      if (i <= b1) {
        D tau_i[6];
        jointForces(mdual, dual, i, dual.f[i], tau_i);
        for (int c = 0; c < model.num_coordinates[i]; ++c)
          store(model.first_coordinate[i] + c, tau_i[c].derivatives().transpose());
        if (p < 0) continue;
        F = dual.X_up[i].applyTranspose(dual.f[i]);
      } else {
        if (model.num_coordinates[i] == 1) {
          store(model.first_coordinate[i], detail::jointForceDerivative<N>(model, i, dual.f[i]));
        } else {
          for (int c = 0, k = model.first_coordinate[i]; c < model.num_coordinates[i]; ++c, ++k) {
            const Motion<double>& sk = dat.S_joint[k];
            RowN row = RowN::Zero();
            for (int r = 0; r < 3; ++r)
              row += sk.w[r] * dual.f[i].n[r].derivatives().transpose() + sk.v[r] * dual.f[i].f[r].derivatives().transpose();
            store(k, row);
          }
        }
        F = detail::applyTranspose(dat.X_up[i], dual.f[i]);
      }
      if (p >= b0) {
        dual.f[p] += F;
      } else {
        for (int r = 0; r < 3; ++r) {
          dd.g_n[p].row(r) += F.n[r].derivatives().transpose();
          dd.g_f[p].row(r) += F.f[r].derivatives().transpose();
        }
        dd.touched[p] = true;
      }
    }
    // Ancestors: ∂τ_p = S_pᵀ ∂f_p, and ∂f_λ(p) += ^pX_λᵀ ∂f_p with the constant double transform.
    for (int p = b0 - 1; p >= 0; --p) {
      if (!dd.touched[p]) continue;
      const DerN& gn = dd.g_n[p];
      const DerN& gf = dd.g_f[p];
      if (model.num_coordinates[p] == 1) {
        const int k = model.axis_kind[p];
        const DerN& along = model.joint_type[p] == JointType::Revolute ? gn : gf;
        store(model.first_coordinate[p], k >= 0 ? RowN(along.row(k)) : RowN(model.axis[p].transpose() * along));
      } else {
        for (int c = 0, k = model.first_coordinate[p]; c < model.num_coordinates[p]; ++c, ++k) {
          const Motion<double>& s = dat.S_joint[k];
          store(k, s.w.transpose() * gn + s.v.transpose() * gf);
        }
      }
      const int pp = model.parent[p];
      if (pp >= 0) {
        const Transform<double>& X = dat.X_up[p];
        const DerN f_up = X.E.transpose() * gf;
        dd.g_f[pp] += f_up;
        dd.g_n[pp] += X.E.transpose() * gn + skew(X.r) * f_up;
        dd.touched[pp] = true;
      }
      dd.g_n[p].setZero();
      dd.g_f[p].setZero();
      dd.touched[p] = false;
    }
  }
  crba(model, dat, q);  // the base translation columns of dtau_dq, dtau_dv stay zero (DerivativeData)
}

// ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ of q̈ = ABA(q, q̇, τ), all by AD through aba().
template <int N>
void abaDerivatives(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                    const VecRef<double>& v, const VecRef<double>& tau) {
  const int n = model.nv();
  MatX<double>* blocks[3] = {&dd.dqdd_dq, &dd.dqdd_dv, &dd.dqdd_dtau};
  for (int first = 0; first < 3 * n; first += N) {
    detail::seed<N>(dd.q, dd.v, dd.w, q, v, tau, first);
    aba(dd.model_dual, dd.data_dual, dd.q, dd.v, dd.w);
    detail::extract<N>(dd.data_dual.qdd, first, 3 * n, blocks);
  }
}

extern template struct DerivativeData<8>;
extern template void rneaDerivatives<8>(const Model<double>&, DerivativeData<8>&, const VecRef<double>&,
                                        const VecRef<double>&, const VecRef<double>&);
extern template void abaDerivatives<8>(const Model<double>&, DerivativeData<8>&, const VecRef<double>&,
                                       const VecRef<double>&, const VecRef<double>&);

}  // namespace saltus::dynamics
