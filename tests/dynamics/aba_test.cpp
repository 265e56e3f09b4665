// ABA against M⁻¹(τ − h), free fall and Euler's torque-free equations.
#include "dynamics/aba.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "dynamics/crba.hpp"
#include "dynamics/rnea.hpp"
#include "tests/support/free_body.hpp"
#include "tests/support/random_model.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

TEST(Aba, EqualsMassMatrixSolve) {
  std::mt19937 rng(31);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int k = 0; k < 8; ++k) {
      const Model<double> model = testing::randomTreeBuilder(rng, 2 + 3 * k).build(base);
      Data<double> data(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n, 1.2), v = testing::randomVector(rng, n),
                            tau = testing::randomVector(rng, n, 3);
      const Eigen::VectorXd h = nonLinearEffects(model, data, q, v);
      const Eigen::VectorXd expected = crba(model, data, q).llt().solve(tau - h);
      EXPECT_LT((aba(model, data, q, v, tau) - expected).norm(), 1e-9 * (1 + expected.norm())) << toString(base);
    }
  }
}

TEST(Aba, FreeBodyFallsWithGravity) {
  std::mt19937 rng(32);
  double m;
  Eigen::Vector3d c;
  Eigen::Matrix3d Ic;
  testing::randomInertia(rng, m, c, Ic);
  const Model<double> model = testing::freeBodyModel(m, c, Ic);
  Data<double> data(model);
  const Eigen::VectorXd q = testing::randomVector(rng, 6), zero = Eigen::VectorXd::Zero(6);
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(6);
  expected[2] = -9.81;
  EXPECT_LT((aba(model, data, q, zero, zero) - expected).norm(), 1e-12);
}

TEST(Aba, FreeBodyObeysEulersEquations) {
  // Torque-free rotation about the centre of mass: I ω̇ + ω × I ω = 0 (body axes).
  std::mt19937 rng(33);
  double m;
  Eigen::Vector3d c;
  Eigen::Matrix3d Ic;
  testing::randomInertia(rng, m, c, Ic);
  const Model<double> model = testing::freeBodyModel(m, Eigen::Vector3d::Zero(), Ic, Eigen::Vector3d::Zero());
  Data<double> data(model);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd q = testing::randomVector(rng, 6, 1.0), v = testing::randomVector(rng, 6, 3);
    const Eigen::VectorXd qdd = aba(model, data, q, v, Eigen::VectorXd::Zero(6));
    // World angular acceleration by central differences along the motion.
    const double eps = 1e-6;
    const Eigen::Vector3d alpha_W = (testing::eulerAngularVelocity(q + eps * v, v + eps * qdd) -
                                     testing::eulerAngularVelocity(q - eps * v, v - eps * qdd)) / (2 * eps);
    const Eigen::Matrix3d R = testing::eulerRotation(q);
    const Eigen::Vector3d w_B = R.transpose() * testing::eulerAngularVelocity(q, v);
    const Eigen::Vector3d alpha_B = Ic.ldlt().solve(-w_B.cross(Ic * w_B));
    EXPECT_LT((alpha_W - R * alpha_B).norm(), 1e-6 * (1 + alpha_B.norm()));
    EXPECT_LT(qdd.head<3>().norm(), 1e-10);  // the centre of mass at the origin does not accelerate
  }
}

TEST(Aba, WrongArgumentSizesAreErrors) {
  testing::ArgumentSizes a;
  const auto& [model, data, ok, bad] = std::tie(a.model, a.data, a.ok, a.bad);
  auto error = [](const std::function<void()>& f) { return testing::invalidArgumentOf(f); };
  EXPECT_NE(error([&] { aba(model, data, bad, ok, ok); }).find("aba: q has 4"), std::string::npos);
  EXPECT_NE(error([&] { aba(model, data, ok, bad, ok); }).find("aba: v has 4"), std::string::npos);
  EXPECT_NE(error([&] { aba(model, data, ok, ok, bad); }).find("aba: tau has 4"), std::string::npos);
  EXPECT_EQ(error([&] { aba(model, data, ok, ok, ok); }), "");
}

}  // namespace
}  // namespace saltus::dynamics
