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
        g_f(model.nbodies(), Eigen::Matrix<double, 3, N>::Zero()), touched(model.nbodies(), false) {
    // subtree_end[i]: one past the largest body index in the subtree of body i.
    for (int i = 0; i < model.nbodies(); ++i) subtree_end[i] = i + 1;
    for (int i = model.nbodies() - 1; i >= 0; --i)
      if (model.parent[i] >= 0) subtree_end[model.parent[i]] = std::max(subtree_end[model.parent[i]], subtree_end[i]);
  }

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
}  // namespace detail

// ∂τ/∂q and ∂τ/∂q̇ of τ = RNEA(q, q̇, q̈) into dd.dtau_dq, dd.dtau_dv; ∂τ/∂q̈ = M(q) into
// dd.data.M (CRBA: RNEA is linear in q̈).
//
// A direction q_j or q̇_j changes the outward recursion only in the subtree of j's body and the
// inward one only there and along its ancestors. Each chunk takes N/2 consecutive coordinates
// with both of their directions, runs the outward and inward steps in dual numbers over the
// bodies the chunk reaches, and carries the derivative of the force transmitted to the
// ancestors as a plain 6 × N matrix; everything else keeps the values of one double RNEA pass.
template <int N>
void rneaDerivatives(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                     const VecRef<double>& v, const VecRef<double>& a) {
  static_assert(N % 2 == 0, "a chunk holds (q_j, q̇_j) pairs");
  using D = Dual<N>;
  using DerN = Eigen::Matrix<double, 3, N>;
  using RowN = Eigen::Matrix<double, 1, N>;
  constexpr int K = N / 2;
  const int n = model.nv();
  Data<double>& dat = dd.data;
  Data<D>& dual = dd.data_dual;
  const Model<D>& mdual = dd.model_dual;
  rnea(model, dat, q, v, a);  // values of every body
  dd.dtau_dq.setZero();
  dd.dtau_dv.setZero();
  const Motion<D> a0{Vec3<D>::Zero(), -mdual.gravity};
  auto promote = [](const Motion<double>& m) { return Motion<D>{m.w.template cast<D>(), m.v.template cast<D>()}; };
  for (int first = 0; first < n; first += K) {
    const int last = std::min(first + K, n);
    // Bodies [b0, end): those of the chunk's coordinates and their subtrees.
    const int b0 = model.coordinate_body[first], b1 = model.coordinate_body[last - 1];
    int end = b1 + 1;
    for (int b = b0; b <= b1; ++b) end = std::max(end, dd.subtree_end[b]);
    // Outward, over the bodies the chunk reaches.
    for (int i = b0; i < end; ++i) {
      const int p = model.parent[i], k0 = model.first_coordinate[i], nc = model.num_coordinates[i];
      D qi[6], vi[6], ai[6];
      for (int c = 0; c < nc; ++c) {
        const int k = k0 + c;
        qi[c] = D(q[k]);
        vi[c] = D(v[k]);
        ai[c] = D(a[k]);
        if (k >= first && k < last) {
          qi[c].derivatives()[2 * (k - first)] = 1.0;
          vi[c].derivatives()[2 * (k - first) + 1] = 1.0;
        }
      }
      if (p >= b0) {
        rneaForwardStep(mdual, dual, i, qi, vi, ai, &dual.v[p], dual.a_gf[p]);
      } else if (p >= 0) {
        const Motion<D> vp = promote(dat.v[p]);
        rneaForwardStep(mdual, dual, i, qi, vi, ai, &vp, promote(dat.a_gf[p]));
      } else {
        rneaForwardStep<D>(mdual, dual, i, qi, vi, ai, nullptr, a0);
      }
    }
    // Inward over the same bodies; forces leaving the range go to dd.g_n/g_f of the ancestor.
    auto store = [&](int k, const RowN& dtau) {
      for (int c = 0; c < last - first; ++c) {
        dd.dtau_dq(k, first + c) = dtau[2 * c];
        dd.dtau_dv(k, first + c) = dtau[2 * c + 1];
      }
    };
    for (int i = end - 1; i >= b0; --i) {
      D tau_i[6];
      jointForces(mdual, dual, i, dual.f[i], tau_i);
      for (int c = 0; c < model.num_coordinates[i]; ++c)
        store(model.first_coordinate[i] + c, tau_i[c].derivatives().transpose());
      const int p = model.parent[i];
      if (p < 0) continue;
      const Force<D> F = dual.X_up[i].applyTranspose(dual.f[i]);
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
  crba(model, dat, q);
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
