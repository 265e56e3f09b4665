// Forward kinematics: velocities and accelerations of points are the time derivatives of the
// positions (central differences along the motion); forwardVelocities agrees with it.
#include "dynamics/kinematics.hpp"

#include <gtest/gtest.h>

#include "tests/support/free_body.hpp"
#include "tests/support/random_model.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

TEST(Kinematics, FreeBaseMatchesEulerAngles) {
  std::mt19937 rng(41);
  double m;
  Eigen::Vector3d c;
  Eigen::Matrix3d Ic;
  testing::randomInertia(rng, m, c, Ic);
  const Model<double> model = testing::freeBodyModel(m, c, Ic);
  Data<double> data(model);
  const Eigen::VectorXd q = testing::randomVector(rng, 6, 1.2);
  forwardKinematics(model, data, q);
  const int root = model.nbodies() - 1;
  EXPECT_LT((bodyRotation(data, root) - testing::eulerRotation(q)).norm(), 1e-14);
  EXPECT_LT((bodyPosition(data, root) - q.head<3>()).norm(), 1e-14);
}

TEST(Kinematics, PointVelocityAndAccelerationAreDerivatives) {
  std::mt19937 rng(42);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    const Model<double> model = testing::randomTreeBuilder(rng, 7).build(base);
    Data<double> data(model);
    const int n = model.nv();
    const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                          a = testing::randomVector(rng, n);
    const double eps = 1e-6;
    for (int b = 0; b < model.nbodies(); ++b) {
      const Eigen::Vector3d p = testing::randomVector(rng, 3);
      // v_P = d/dt p_P along q(t) = q + t v.
      forwardKinematics(model, data, Eigen::VectorXd(q + eps * v));
      const Eigen::Vector3d pp = pointPosition(data, b, p);
      forwardKinematics(model, data, Eigen::VectorXd(q - eps * v));
      const Eigen::Vector3d pm = pointPosition(data, b, p);
      // a_P = d/dt v_P along q(t) = q + t v + t²/2 a, v(t) = v + t a.
      forwardKinematics(model, data, Eigen::VectorXd(q + eps * v), Eigen::VectorXd(v + eps * a));
      const Eigen::Vector3d vp = pointVelocity(data, b, p);
      forwardKinematics(model, data, Eigen::VectorXd(q - eps * v), Eigen::VectorXd(v - eps * a));
      const Eigen::Vector3d vm = pointVelocity(data, b, p);
      forwardKinematics(model, data, q, v, a);
      EXPECT_LT((pointVelocity(data, b, p) - (pp - pm) / (2 * eps)).norm(), 1e-7) << toString(base) << " body " << b;
      EXPECT_LT((pointAcceleration(data, b, p) - (vp - vm) / (2 * eps)).norm(), 1e-6) << toString(base) << " body " << b;
    }
  }
}

// forwardVelocities: the poses and body velocities of forwardKinematics(q, v) to round-off (the
// same operations without the bias accelerations; the compiler may contract them differently),
// for every kind of base.
TEST(Kinematics, ForwardVelocitiesAreThoseOfForwardKinematics) {
  std::mt19937 rng(43);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    const Model<double> model = testing::randomTreeBuilder(rng, 6).build(base);
    Data<double> full(model), light(model);
    const Eigen::VectorXd q = testing::randomVector(rng, model.nv()), v = testing::randomVector(rng, model.nv());
    forwardKinematics(model, full, q, v);
    forwardVelocities(model, light, q, v);
    double largest = 0;
    for (int b = 0; b < model.nbodies(); ++b) {
      largest = std::max(largest, light.v[b].v.norm());
      EXPECT_LT((light.X_world[b].E - full.X_world[b].E).norm(), 1e-14) << toString(base) << " body " << b;
      EXPECT_LT((light.X_world[b].r - full.X_world[b].r).norm(), 1e-14) << toString(base) << " body " << b;
      EXPECT_LT((light.v[b].w - full.v[b].w).norm(), 1e-14) << toString(base) << " body " << b;
      EXPECT_LT((light.v[b].v - full.v[b].v).norm(), 1e-14) << toString(base) << " body " << b;
    }
    EXPECT_GT(largest, 0.1) << toString(base);  // the bodies move
  }
}

TEST(Kinematics, WrongArgumentSizesAreErrors) {
  testing::ArgumentSizes a;
  const auto& [model, data, ok, bad] = std::tie(a.model, a.data, a.ok, a.bad);
  auto error = [](const std::function<void()>& f) { return testing::invalidArgumentOf(f); };
  EXPECT_NE(error([&] { forwardKinematics(model, data, bad); }).find("forwardKinematics: q has 4"), std::string::npos);
  EXPECT_NE(error([&] { forwardKinematics(model, data, ok, bad); }).find("forwardKinematics: v has 4"), std::string::npos);
  EXPECT_NE(error([&] { forwardKinematics(model, data, ok, ok, bad); }).find("forwardKinematics: a has 4"),
            std::string::npos);
  EXPECT_NE(error([&] { forwardVelocities(model, data, bad, ok); }).find("forwardVelocities: q has 4"), std::string::npos);
  EXPECT_EQ(error([&] { forwardKinematics(model, data, ok, ok, ok); }), "");
}

}  // namespace
}  // namespace saltus::dynamics
