// The AD of the transcription's local functions (functions.hpp), instantiated here alone: this
// file is compiled with raised inlining limits (CMakeLists.txt), without which GCC leaves
// Eigen's AutoDiffScalar expression templates as calls and the nested-dual Hessians run about
// twice as slowly.
#include "collocation/functions.hpp"

namespace saltus::collocation {

void EquationOfMotion::addHessian(const double* x, const double* lambda, double* H) const {
  const int n = nv(), N = inputs();
  const int first_acceleration = (with_dynamics ? 2 : 1) * n;  // q̈ or Δq̇
  const int first_reaction = first_acceleration + n + inputs_count();
  auto h = [H, N](int i, int j) -> double& { return H[std::max(i, j) + std::min(i, j) * N]; };
  using VecD = Eigen::Matrix<Dual, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1>;
  const auto& model_d = models->modelWithoutGravity<Dual>();
  auto& data_d = models->data<Dual>();
  bool any_point = false;
  for (const ContactPoint& c : *contacts) any_point = any_point || !c.is_limit;
  // First-order passes with q seeded, a chunk of coordinates at a time.
  VecD q(n), zero = VecD::Zero(n), l(n);
  for (int i = 0; i < n; ++i) {
    q[i] = Dual(x[i], Eigen::Matrix<double, kChunk, 1>::Zero());
    l[i] = Dual(lambda[i], Eigen::Matrix<double, kChunk, 1>::Zero());
  }
  for (int first = 0; first < n; first += kChunk) {
    const int count = std::min(kChunk, n - first);
    for (int i = 0; i < n; ++i) q[i].derivatives().setZero();
    for (int c = 0; c < count; ++c) q[first + c].derivatives()[c] = 1.0;
    // (q, q̈): ∂(M(q) λ)_j/∂q_i.
    const auto& Ml = dynamics::rnea(model_d, data_d, ConstMap<Dual>(q.data(), n), ConstMap<Dual>(zero.data(), n),
                                    ConstMap<Dual>(l.data(), n));
    for (int j = 0; j < n; ++j)
      for (int c = 0; c < count; ++c) h(first_acceleration + j, first + c) += Ml[j].derivatives()[c];
    if (!any_point) continue;
    // (q, r) and (r_n, α): w_c(q) = J_c(q) λ.
    dynamics::forwardVelocities(model_d, data_d, ConstMap<Dual>(q.data(), n), ConstMap<Dual>(l.data(), n));
    int k = first_reaction;
    for (const ContactPoint& c : *contacts) {
      if (c.is_limit) {
        k += 1 + c.k();
        continue;
      }
      const dynamics::Vec3<Dual> w = dynamics::pointVelocity(data_d, c.body, dynamics::Vec3<Dual>(c.p_B.cast<Dual>()));
      const double rn = x[k];
      // ∂f/∂r_n and ∂f/∂(α_i or β_i).
      Eigen::Vector3d df_drn = c.normal;
      if (friction == FrictionForm::Activation)
        for (int i = 0; i < c.k(); ++i) df_drn -= c.directions.col(i) * (c.mu * x[k + 1 + i]);
      for (int col = 0; col < count; ++col) {
        const Eigen::Vector3d dw(w[0].derivatives()[col], w[1].derivatives()[col], w[2].derivatives()[col]);
        h(k, first + col) -= df_drn.dot(dw);
        for (int i = 0; i < c.k(); ++i) {
          const double df_dt = friction == FrictionForm::Activation ? -c.mu * rn : 1.0;
          h(k + 1 + i, first + col) -= df_dt * c.directions.col(i).dot(dw);
        }
      }
      if (first == 0 && friction == FrictionForm::Activation) {
        const Eigen::Vector3d wv(w[0].value(), w[1].value(), w[2].value());
        for (int i = 0; i < c.k(); ++i) h(k + 1 + i, k) += c.mu * c.directions.col(i).dot(wv);
      }
      k += 1 + c.k();
    }
  }
  if (!with_dynamics) return;
  // (q̇, q̇) by polarisation of ψ(q̇) = λᵀ RNEA(q, q̇, 0) without gravity.
  const auto& model = models->modelWithoutGravity<double>();
  auto& data = models->data<double>();
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1> v = Eigen::VectorXd::Zero(n), psi(n);
  const ConstMap<double> qv(x, n), lv(lambda, n);
  auto form = [&]() { return lv.dot(dynamics::nonLinearEffects(model, data, qv, ConstMap<double>(v.data(), n))); };
  for (int i = 0; i < n; ++i) {
    v[i] = 1.0;
    psi[i] = form();
    v[i] = 0.0;
    h(n + i, n + i) += 2.0 * psi[i];
  }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) {
      v[i] = v[j] = 1.0;
      h(n + i, n + j) += form() - psi[i] - psi[j];
      v[i] = v[j] = 0.0;
    }
}


template class AdFunction<EquationOfMotion>;
template class AdFunction<GapDefinition>;
template class AdFunction<RestitutionBalance>;
template class AdFunction<SlipSlack>;
template class AdFunction<Integration>;
template class AdFunction<Effort>;

}  // namespace saltus::collocation
