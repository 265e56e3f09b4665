#include <gtest/gtest.h>
#include "dynamics/dynamics.hpp"
#include "tests/support/random_model.hpp"
using namespace saltus::dynamics;
TEST(Smoke, RneaAbaInverse) {
  std::mt19937 rng(1);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    auto model = saltus::testing::randomTreeBuilder(rng, 8).build(base);
    Data<double> data(model);
    Eigen::VectorXd q = saltus::testing::randomVector(rng, model.nv()), v = saltus::testing::randomVector(rng, model.nv()),
                    tau = saltus::testing::randomVector(rng, model.nv());
    Eigen::VectorXd qdd = aba(model, data, q, v, tau);
    Eigen::VectorXd tau2 = rnea(model, data, q, v, qdd);
    EXPECT_LT((tau - tau2).norm(), 1e-9) << toString(base);
    Eigen::MatrixXd M = crba(model, data, q);
    Eigen::VectorXd h = nonLinearEffects(model, data, q, v);
    EXPECT_LT((M * qdd + h - tau).norm(), 1e-9);
  }
}
