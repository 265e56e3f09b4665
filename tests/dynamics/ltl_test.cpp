// The branch-sparse factorisation M = Lᵀ L against the dense Cholesky factorisation: the same
// solves, Lᵀ L = M, L zero off each coordinate's path to the root, on random trees of every base.
#include "dynamics/ltl.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "dynamics/configuration.hpp"
#include "dynamics/crba.hpp"
#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

TEST(Ltl, FactorsTheMassMatrixWithItsSparsity) {
  std::mt19937 rng(23);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free, BaseType::FreeQuaternion}) {
    for (int trial = 0; trial < 6; ++trial) {
      const Model<double> model = testing::randomTreeBuilder(rng, 2 + 4 * trial).build(base);
      Data<double> data(model);
      const int n = model.nv();
      Eigen::VectorXd q = testing::randomVector(rng, model.nq(), 1.2);
      if (base == BaseType::FreeQuaternion) normalizeConfiguration(model, q);
      const Eigen::MatrixXd M = crba(model, data, q);
      Eigen::MatrixXd F = M;
      ASSERT_TRUE(factorLtl(model, F)) << toString(base);
      Eigen::MatrixXd L = F.triangularView<Eigen::Lower>();
      EXPECT_LT((L.transpose() * L - M).norm(), 1e-12 * (1 + M.norm())) << toString(base) << " " << trial;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < i; ++j) {
          bool ancestor = false;
          for (int k = model.parent_coordinate[i]; k >= 0; k = model.parent_coordinate[k]) ancestor |= k == j;
          if (!ancestor) { EXPECT_EQ(L(i, j), 0.0) << i << " " << j; }
        }
      // Solves against the dense Cholesky factorisation.
      const Eigen::VectorXd b = testing::randomVector(rng, n, 2.0);
      Eigen::VectorXd x = b;
      solveMassLtl(model, F, x.data());
      const Eigen::VectorXd expected = M.llt().solve(b);
      EXPECT_LT((x - expected).norm(), 1e-10 * (1 + expected.norm()));
      Eigen::VectorXd y = b;  // L⁻ᵀ b: its squared norm is bᵀ M⁻¹ b
      solveLtlTranspose(model, F, y.data());
      EXPECT_NEAR(y.squaredNorm(), b.dot(expected), 1e-10 * (1 + std::abs(b.dot(expected))));
      // A vector on one body's path stays on it.
      Eigen::VectorXd path = Eigen::VectorXd::Zero(n);
      const int leaf = n - 1;
      for (int k = leaf; k >= 0; k = model.parent_coordinate[k]) path[k] = 1.0;
      Eigen::VectorXd z = path;
      solveLtlTranspose(model, F, z.data());
      for (int k = 0; k < n; ++k)
        if (path[k] == 0) { EXPECT_EQ(z[k], 0.0); }
    }
  }
}

TEST(Ltl, ANonPositivePivotIsReported) {
  std::mt19937 rng(4);
  const Model<double> model = testing::randomTreeBuilder(rng, 3).build(BaseType::Fixed);
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(3, 3);
  M(1, 1) = -1;
  EXPECT_FALSE(factorLtl(model, M));
}

}  // namespace
}  // namespace saltus::dynamics
