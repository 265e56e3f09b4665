// AD derivatives of RNEA and ABA against central finite differences.
#include "dynamics/derivatives.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

// Central differences of f: R^n -> R^n along each coordinate of x.
template <class F>
Eigen::MatrixXd finiteDifference(F f, const Eigen::VectorXd& x, double eps = 1e-6) {
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd J(f(x).size(), n);
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += eps;
    xm[j] -= eps;
    J.col(j) = (f(xp) - f(xm)) / (2 * eps);
  }
  return J;
}

double relativeError(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) { return (A - B).norm() / (1 + B.norm()); }

TEST(Derivatives, RneaMatchesFiniteDifferences) {
  std::mt19937 rng(71);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int nj : {1, 5, 11}) {  // 11 + 6 base coordinates: several chunks of 8 directions
      const Model<double> model = testing::randomTreeBuilder(rng, nj).build(base);
      Data<double> data(model);
      DerivativeData<8> dd(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                            a = testing::randomVector(rng, n);
      rneaDerivatives(model, dd, q, v, a);
      auto tau_q = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(rnea(model, data, x, v, a)); };
      auto tau_v = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(rnea(model, data, q, x, a)); };
      auto tau_a = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(rnea(model, data, q, v, x)); };
      EXPECT_LT(relativeError(dd.dtau_dq, finiteDifference(tau_q, q)), 1e-7) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.dtau_dv, finiteDifference(tau_v, v)), 1e-7) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.data.M, finiteDifference(tau_a, a)), 1e-7) << toString(base) << " n=" << n;
    }
  }
}

TEST(Derivatives, AbaMatchesFiniteDifferences) {
  std::mt19937 rng(72);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int nj : {2, 7}) {
      const Model<double> model = testing::randomTreeBuilder(rng, nj).build(base);
      Data<double> data(model);
      DerivativeData<8> dd(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                            tau = testing::randomVector(rng, n);
      abaDerivatives(model, dd, q, v, tau);
      auto f_q = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(aba(model, data, x, v, tau)); };
      auto f_v = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(aba(model, data, q, x, tau)); };
      auto f_t = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(aba(model, data, q, v, x)); };
      EXPECT_LT(relativeError(dd.dqdd_dq, finiteDifference(f_q, q)), 1e-6) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.dqdd_dv, finiteDifference(f_v, v)), 1e-6) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.dqdd_dtau, finiteDifference(f_t, tau)), 1e-6) << toString(base) << " n=" << n;
      // ∂q̈/∂τ = M⁻¹ exactly.
      EXPECT_LT(relativeError(dd.dqdd_dtau, crba(model, data, q).inverse()), 1e-10);
    }
  }
}

}  // namespace
}  // namespace saltus::dynamics
