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
        dqdd_dq(model.nv(), model.nv()), dqdd_dv(model.nv(), model.nv()), dqdd_dtau(model.nv(), model.nv()) {}

  Model<Dual<N>> model_dual;
  Data<Dual<N>> data_dual;
  Data<double> data;            // double workspace (M for ∂τ/∂q̈)
  VecX<Dual<N>> q, v, w;        // seeded inputs (w: q̈ for RNEA, τ for ABA)
  MatX<double> dtau_dq, dtau_dv;               // RNEA: ∂τ/∂q, ∂τ/∂q̇ (∂τ/∂q̈ = M is data.M)
  MatX<double> dqdd_dq, dqdd_dv, dqdd_dtau;    // ABA: ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ (= M⁻¹)
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
template <int N>
void rneaDerivatives(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                     const VecRef<double>& v, const VecRef<double>& a) {
  const int n = model.nv();
  MatX<double>* blocks[3] = {&dd.dtau_dq, &dd.dtau_dv, nullptr};
  for (int first = 0; first < 2 * n; first += N) {
    detail::seed<N>(dd.q, dd.v, dd.w, q, v, a, first);
    rnea(dd.model_dual, dd.data_dual, dd.q, dd.v, dd.w);
    detail::extract<N>(dd.data_dual.tau, first, 2 * n, blocks);
  }
  crba(model, dd.data, q);
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
