// Body and point Jacobians against finite differences of the kinematics; J̇v against the
// difference of J v along the motion.
#include "dynamics/jacobian.hpp"

#include <gtest/gtest.h>

#include "tests/support/random_model.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

TEST(Jacobian, PointJacobianIsDerivativeOfPosition) {
  std::mt19937 rng(51);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    const Model<double> model = testing::randomTreeBuilder(rng, 8).build(base);
    Data<double> data(model);
    const int n = model.nv();
    const Eigen::VectorXd q = testing::randomVector(rng, n);
    const double eps = 1e-6;
    Mat3X<double> J(3, n);
    for (int b = 0; b < model.nbodies(); ++b) {
      const Eigen::Vector3d p = testing::randomVector(rng, 3);
      forwardKinematics(model, data, q);
      pointJacobian(model, data, b, p, J);
      for (int j = 0; j < n; ++j) {
        Eigen::VectorXd qp = q, qm = q;
        qp[j] += eps;
        qm[j] -= eps;
        forwardKinematics(model, data, qp);
        const Eigen::Vector3d pp = pointPosition(data, b, p);
        forwardKinematics(model, data, qm);
        const Eigen::Vector3d pm = pointPosition(data, b, p);
        EXPECT_LT((J.col(j) - (pp - pm) / (2 * eps)).norm(), 1e-8) << toString(base) << " body " << b << " coordinate " << j;
        if (!model.isAncestor(model.coordinate_body[j], b)) {
          EXPECT_EQ(J.col(j).norm(), 0.0);
        }
      }
    }
  }
}

TEST(Jacobian, BodyJacobianGivesWorldSpatialVelocity) {
  std::mt19937 rng(52);
  const Model<double> model = testing::randomTreeBuilder(rng, 9).build(BaseType::Free);
  Data<double> data(model);
  const int n = model.nv();
  const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n);
  forwardKinematics(model, data, q, v);
  Mat6X<double> J(6, n);
  Mat3X<double> Jp(3, n);
  for (int b = 0; b < model.nbodies(); ++b) {
    bodyJacobianWorld(model, data, b, J);
    const Motion<double> vW = data.X_world[b].applyInverse(data.v[b]);
    EXPECT_LT((J * v - vW.vector()).norm(), 1e-12);
    // The linear velocity of a body point is v_O + ω × p in world coordinates.
    const Eigen::Vector3d p = testing::randomVector(rng, 3);
    pointJacobian(model, data, b, p, Jp);
    EXPECT_LT((Jp * v - pointVelocity(data, b, p)).norm(), 1e-12);
  }
}

TEST(Jacobian, VelocityProductTermIsDerivativeOfJv) {
  std::mt19937 rng(53);
  const Model<double> model = testing::randomTreeBuilder(rng, 8).build(BaseType::Planar);
  Data<double> data(model);
  const int n = model.nv();
  const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                        a = testing::randomVector(rng, n);
  const double eps = 1e-6;
  Mat3X<double> Jp(3, n), Jm(3, n), J(3, n);
  for (int b = 0; b < model.nbodies(); ++b) {
    const Eigen::Vector3d p = testing::randomVector(rng, 3);
    forwardKinematics(model, data, Eigen::VectorXd(q + eps * v));
    pointJacobian(model, data, b, p, Jp);
    forwardKinematics(model, data, Eigen::VectorXd(q - eps * v));
    pointJacobian(model, data, b, p, Jm);
    forwardKinematics(model, data, q, v, a);
    pointJacobian(model, data, b, p, J);
    const Eigen::Vector3d Jdot_v = (Jp - Jm) * v / (2 * eps);
    EXPECT_LT((pointAccelerationBias(data, b, p) - Jdot_v).norm(), 1e-7);
    // a_P = J q̈ + J̇ q̇.
    EXPECT_LT((pointAcceleration(data, b, p) - (J * a + pointAccelerationBias(data, b, p))).norm(), 1e-12);
  }
}

TEST(Jacobian, WrongColumnCountIsAnError) {
  testing::ArgumentSizes a;
  const auto& [model, data, ok, bad] = std::tie(a.model, a.data, a.ok, a.bad);
  auto error = [](const std::function<void()>& f) { return testing::invalidArgumentOf(f); };
  forwardKinematics(model, data, ok);
  Eigen::Matrix3Xd J3(3, model.nv() + 1);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J6(6, model.nv() - 1);
  EXPECT_NE(error([&] { pointJacobian(model, data, 0, Eigen::Vector3d(Eigen::Vector3d::Zero()), J3); }).find("pointJacobian: J's columns"),
            std::string::npos);
  EXPECT_NE(error([&] { bodyJacobianWorld(model, data, 0, J6); }).find("bodyJacobianWorld: J's columns has 2"),
            std::string::npos);
}

}  // namespace
}  // namespace saltus::dynamics
