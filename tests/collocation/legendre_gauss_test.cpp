// Legendre–Gauss roots, Ω and quadrature weights (collocation/legendre_gauss.hpp) for P = 1 … 8,
// checked by what they must integrate exactly.
#include "collocation/legendre_gauss.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace saltus::collocation {
namespace {

class LegendreGaussOrder : public ::testing::TestWithParam<int> {};

TEST_P(LegendreGaussOrder, QuadratureIsExactToDegree2PMinus1) {
  const int P = GetParam();
  const LegendreGauss lg(P);
  ASSERT_EQ(lg.tau.size(), P);
  for (int p = 0; p < P; ++p) {
    EXPECT_GT(lg.tau[p], 0.0);
    EXPECT_LT(lg.tau[p], 1.0);
    if (p > 0) {
      EXPECT_GT(lg.tau[p], lg.tau[p - 1]);
    }
  }
  for (int k = 0; k <= 2 * P - 1; ++k) {
    double sum = 0;
    for (int j = 0; j < P; ++j) sum += lg.b[j] * std::pow(lg.tau[j], k);
    EXPECT_NEAR(sum, 1.0 / (k + 1), 1e-13) << "degree " << k;
  }
  // One degree more is not integrated exactly (the rule has order 2P).
  double sum = 0;
  for (int j = 0; j < P; ++j) sum += lg.b[j] * std::pow(lg.tau[j], 2 * P);
  EXPECT_GT(std::abs(sum - 1.0 / (2 * P + 1)), 1e-12);  // the error term shrinks fast with P, round-off is ~1e-16
}

TEST_P(LegendreGaussOrder, OmegaIntegratesPolynomialsOfDegreePMinus1) {
  // Eq. (3): x(τ_p) = x(0) + Σ_j Ω(p, j) ẋ(τ_j) holds exactly when ẋ has degree ≤ P − 1.
  const int P = GetParam();
  const LegendreGauss lg(P);
  for (int k = 0; k <= P - 1; ++k)
    for (int p = 0; p < P; ++p) {
      double sum = 0;
      for (int j = 0; j < P; ++j) sum += lg.Omega(p, j) * std::pow(lg.tau[j], k);
      EXPECT_NEAR(sum, std::pow(lg.tau[p], k + 1) / (k + 1), 1e-13) << "p " << p << " degree " << k;
    }
}

TEST_P(LegendreGaussOrder, RootsAreZerosOfTheLegendrePolynomial) {
  const int P = GetParam();
  Eigen::VectorXd x, w;
  gaussLegendre(P, x, w);
  for (int i = 0; i < P; ++i) {
    // P_P by its explicit sum: P_n(x) = 2⁻ⁿ Σ_k C(n,k)² (x−1)^(n−k) (x+1)^k.
    double v = 0;
    for (int k = 0; k <= P; ++k) {
      const double c = std::tgamma(P + 1) / (std::tgamma(k + 1) * std::tgamma(P - k + 1));
      v += c * c * std::pow(x[i] - 1, P - k) * std::pow(x[i] + 1, k);
    }
    EXPECT_NEAR(v / std::pow(2.0, P), 0.0, 1e-12);
  }
  EXPECT_NEAR(w.sum(), 2.0, 1e-13);
}

TEST_P(LegendreGaussOrder, BasisInterpolates) {
  const int P = GetParam();
  const LegendreGauss lg(P);
  for (int p = 0; p < P; ++p) {
    const Eigen::VectorXd l = lg.basis(lg.tau[p]);
    for (int j = 0; j < P; ++j) EXPECT_NEAR(l[j], p == j ? 1.0 : 0.0, 1e-12);
  }
  EXPECT_TRUE(lg.basisIntegral(1.0).isApprox(lg.b, 1e-14));
}

INSTANTIATE_TEST_SUITE_P(P1to8, LegendreGaussOrder, ::testing::Range(1, 9));

TEST(LegendreGauss, RejectsOrderZero) { EXPECT_THROW(LegendreGauss(0), std::invalid_argument); }

}  // namespace
}  // namespace saltus::collocation
