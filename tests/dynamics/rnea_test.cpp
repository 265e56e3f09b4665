// RNEA against closed-form pendulums and against ABA and the potential energy on random trees.
#include "dynamics/rnea.hpp"

#include <gtest/gtest.h>

#include "dynamics/aba.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/random_model.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

TEST(Rnea, SinglePendulumClosedForm) {
  const double m = 1.3, L = 0.7, g = 9.81;
  const Model<double> model = testing::pendulumModel({m}, {L});
  Data<double> data(model);
  for (double th : {0.0, 0.4, -1.2, 2.5}) {
    const double thd = 0.8, thdd = -1.7;
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, th), v = Eigen::VectorXd::Constant(1, thd),
                          a = Eigen::VectorXd::Constant(1, thdd);
    // τ = (m L²/3) θ̈ + m g (L/2) sin θ for a uniform rod hanging from its end.
    EXPECT_NEAR(rnea(model, data, q, v, a)[0], m * L * L / 3 * thdd + m * g * L / 2 * std::sin(th), 1e-12);
  }
}

TEST(Rnea, DoublePendulumClosedForm) {
  const double m1 = 1.0, m2 = 1.4, L1 = 0.5, L2 = 0.6;
  const Model<double> model = testing::pendulumModel({m1, m2}, {L1, L2});
  Data<double> data(model);
  std::mt19937 rng(3);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd q = testing::randomVector(rng, 2, 3), v = testing::randomVector(rng, 2, 2),
                          a = testing::randomVector(rng, 2, 2);
    const Eigen::Matrix2d M = testing::doublePendulumMassMatrix(m1, m2, L1, L2, q[1]);
    const Eigen::Vector2d h = testing::doublePendulumBias(m1, m2, L1, L2, q, v);
    EXPECT_LT((rnea(model, data, q, v, a) - (M * a + h)).norm(), 1e-12);
    EXPECT_LT((nonLinearEffects(model, data, q, v) - h).norm(), 1e-12);
  }
}

TEST(Rnea, InvertsAbaOnRandomTrees) {
  std::mt19937 rng(11);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int k = 0; k < 10; ++k) {
      const Model<double> model = testing::randomTreeBuilder(rng, 2 + k).build(base);
      Data<double> data(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n, 1.2), v = testing::randomVector(rng, n),
                            tau = testing::randomVector(rng, n, 5);
      const Eigen::VectorXd qdd = aba(model, data, q, v, tau);
      EXPECT_LT((rnea(model, data, q, v, qdd) - tau).norm(), 1e-9 * (1 + tau.norm())) << toString(base);
    }
  }
}

TEST(Rnea, NonLinearEffectsReuseTheJointTransformsOfAnyKinematicsCall) {
  // After any call that evaluated the joints at q (and a call at another q in between would break
  // it), h at other velocities without jcalc equals nonLinearEffects(q, v): exactly after crba and
  // aba (the same joint kernels), to round-off after forwardKinematics (the general jcalc).
  std::mt19937 rng(21);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free})
    for (const bool axis_tree : {false, true}) {
      const Model<double> model =
          (axis_tree ? testing::randomAxisTreeBuilder(rng, 7) : testing::randomTreeBuilder(rng, 7)).build(base);
      Data<double> data(model), reference(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n, 1.2), v1 = testing::randomVector(rng, n),
                            v2 = testing::randomVector(rng, n);
      for (int evaluator = 0; evaluator < 3; ++evaluator) {
        nonLinearEffects(model, data, Eigen::VectorXd(q + Eigen::VectorXd::Ones(n)), v1);  // other poses first
        if (evaluator == 0) forwardKinematics(model, data, q);
        if (evaluator == 1) crba(model, data, q);
        if (evaluator == 2) aba(model, data, q, v1, v2);
        for (const Eigen::VectorXd* v : {&v1, &v2}) {
          const Eigen::VectorXd h = nonLinearEffectsAtCurrentPoses(model, data, *v);
          const Eigen::VectorXd h_ref = nonLinearEffects(model, reference, q, *v);
          if (evaluator == 0)
            EXPECT_LT((h - h_ref).norm(), 1e-12 * (1 + h_ref.norm())) << toString(base);
          else
            EXPECT_EQ(h, h_ref) << toString(base) << " evaluator " << evaluator;
        }
      }
    }
}

TEST(Rnea, GravityTermIsGradientOfPotential) {
  std::mt19937 rng(12);
  const Model<double> model = testing::randomTreeBuilder(rng, 9).build(BaseType::Free);
  Data<double> data(model);
  const int n = model.nv();
  const Eigen::VectorXd q = testing::randomVector(rng, n), zero = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd g = nonLinearEffects(model, data, q, zero);
  const double eps = 1e-6;
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd qp = q, qm = q;
    qp[j] += eps;
    qm[j] -= eps;
    forwardKinematics(model, data, qp);
    const double Vp = potentialEnergy(model, data);
    forwardKinematics(model, data, qm);
    const double Vm = potentialEnergy(model, data);
    EXPECT_NEAR(g[j], (Vp - Vm) / (2 * eps), 1e-7 * (1 + std::abs(g[j])));
  }
}

// A vector of the wrong length is an error naming the function and the argument, not a read past
// its end (dynamics::checkArgumentSize).
TEST(Rnea, WrongArgumentSizesAreErrors) {
  testing::ArgumentSizes a;
  const auto& [model, data, ok, bad] = std::tie(a.model, a.data, a.ok, a.bad);
  auto error = [](const std::function<void()>& f) { return testing::invalidArgumentOf(f); };
  EXPECT_EQ(error([&] { rnea(model, data, bad, ok, ok); }), "rnea: q has 4 entries; the model has 3 coordinates");
  EXPECT_NE(error([&] { rnea(model, data, ok, bad, ok); }).find("rnea: v has 4 entries"), std::string::npos);
  EXPECT_NE(error([&] { rnea(model, data, ok, ok, bad); }).find("rnea: a has 4 entries"), std::string::npos);
  EXPECT_NE(error([&] { nonLinearEffects(model, data, ok, bad); }).find("nonLinearEffects: v"), std::string::npos);
  EXPECT_NE(error([&] { nonLinearEffectsAtCurrentPoses(model, data, bad); }).find("v has 4"), std::string::npos);
  EXPECT_EQ(error([&] { rnea(model, data, ok, ok, ok); }), "");
}

}  // namespace
}  // namespace saltus::dynamics
