// The quaternion base (BaseType::FreeQuaternion) against the Euler-angle base at the same states,
// away from the Euler singularity, and the manifold operations of configuration.hpp: integrate
// and difference are inverse, stay on the unit sphere, and their finite differences give the
// Jacobians.
#include "dynamics/configuration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "dynamics/aba.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/rnea.hpp"
#include "tests/support/free_body.hpp"
#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

// The quaternion-base state of an Euler-base state (x, y, z, ψ, θ, φ, joints; rates): the same
// origin and rotation, ṗ the same, ω_B = Rᵀ ω_world.
struct QuaternionState {
  Eigen::VectorXd q, v;
};
QuaternionState fromEuler(const Eigen::VectorXd& q_euler, const Eigen::VectorXd& v_euler) {
  const int n = static_cast<int>(q_euler.size());
  QuaternionState s{Eigen::VectorXd(n + 1), Eigen::VectorXd(n)};
  const Eigen::Matrix3d R = testing::eulerRotation(q_euler);
  s.q.head<3>() = q_euler.head<3>();
  s.q.segment<4>(3) = rotationToQuaternion(R);
  s.q.tail(n - 6) = q_euler.tail(n - 6);
  s.v.head<3>() = v_euler.head<3>();
  s.v.segment<3>(3) = R.transpose() * testing::eulerAngularVelocity(q_euler, v_euler);
  s.v.tail(n - 6) = v_euler.tail(n - 6);
  return s;
}

Eigen::VectorXd randomEulerConfiguration(std::mt19937& rng, int n) {
  Eigen::VectorXd q = testing::randomVector(rng, n, 1.2);
  q[4] = std::clamp(q[4], -1.2, 1.2);  // pitch away from ±π/2
  return q;
}

TEST(Configuration, BuilderNamesPositionsAndVelocities) {
  std::mt19937 rng(3);
  const Model<double> model = testing::randomTreeBuilder(rng, 4).build(BaseType::FreeQuaternion);
  EXPECT_EQ(model.nv(), 10);
  EXPECT_EQ(model.nq(), 11);
  EXPECT_EQ(model.position_name[3], "base_qw");
  EXPECT_EQ(model.position_name[6], "base_qz");
  EXPECT_EQ(model.coordinate_name[3], "base_wx");
  EXPECT_EQ(model.position_name[7], model.coordinate_name[6]);
  EXPECT_EQ(model.first_position[1], 7);
  EXPECT_EQ(model.positionOf(6), 7);
  EXPECT_EQ(model.positionOf(2), 2);
  EXPECT_TRUE(model.isTranslation(2));
  EXPECT_FALSE(model.isTranslation(3));
  const Eigen::VectorXd q0 = neutralConfiguration(model);
  EXPECT_EQ(q0[3], 1.0);
  EXPECT_EQ(q0.norm(), 1.0);
  Data<double> data(model);
  EXPECT_THROW(forwardKinematics(model, data, Eigen::VectorXd::Zero(10)), std::invalid_argument);
}

// Poses, body velocities, kinetic energy, M⁻¹(τ − h) and point Jacobians agree with the Euler
// base: the same physics in other coordinates.
TEST(Configuration, KernelsEqualEulerBase) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 10; ++trial) {
    const int joints = 1 + 2 * trial;
    const ModelBuilder builder = testing::randomTreeBuilder(rng, joints);
    const Model<double> euler = builder.build(BaseType::Free), quat = builder.build(BaseType::FreeQuaternion);
    Data<double> de(euler), dq(quat);
    const int n = euler.nv();
    const Eigen::VectorXd qe = randomEulerConfiguration(rng, n), ve = testing::randomVector(rng, n);
    const QuaternionState s = fromEuler(qe, ve);
    forwardKinematics(euler, de, qe, ve);
    forwardKinematics(quat, dq, s.q, s.v);
    for (int i = 0; i < euler.nbodies(); ++i) {
      EXPECT_LT((de.X_world[i].E - dq.X_world[i].E).norm(), 1e-12) << trial << " body " << i;
      EXPECT_LT((de.X_world[i].r - dq.X_world[i].r).norm(), 1e-12);
      EXPECT_LT((de.v[i].vector() - dq.v[i].vector()).norm(), 1e-11 * (1 + de.v[i].vector().norm()));
    }
    EXPECT_NEAR(kineticEnergy(euler, de), kineticEnergy(quat, dq), 1e-10 * (1 + kineticEnergy(euler, de)));

    // Joint torques with no base wrench: the joint accelerations agree, and the bodies'
    // spatial accelerations (independent of the coordinates) too.
    Eigen::VectorXd tau = testing::randomVector(rng, n, 3);
    tau.head<6>().setZero();
    const Eigen::VectorXd ae = aba(euler, de, qe, ve, tau), aq = aba(quat, dq, s.q, s.v, tau);
    EXPECT_LT((ae.tail(n - 6) - aq.tail(n - 6)).norm(), 1e-9 * (1 + ae.norm())) << trial;
    EXPECT_LT((ae.head<3>() - aq.head<3>()).norm(), 1e-9 * (1 + ae.norm())) << trial;  // p̈, world axes
    forwardKinematics(euler, de, qe, ve, ae);
    forwardKinematics(quat, dq, s.q, s.v, aq);
    for (int i = 0; i < euler.nbodies(); ++i)
      EXPECT_LT((de.a[i].vector() - dq.a[i].vector()).norm(), 1e-9 * (1 + de.a[i].vector().norm())) << trial;

    // ABA against the mass matrix and RNEA of the quaternion base itself.
    const Eigen::VectorXd tau_q = testing::randomVector(rng, n, 3);
    const Eigen::VectorXd h = nonLinearEffects(quat, dq, s.q, s.v);
    const Eigen::VectorXd expected = crba(quat, dq, s.q).llt().solve(tau_q - h);
    const Eigen::VectorXd qdd = aba(quat, dq, s.q, s.v, tau_q);
    EXPECT_LT((qdd - expected).norm(), 1e-9 * (1 + expected.norm())) << trial;
    EXPECT_LT((rnea(quat, dq, s.q, s.v, qdd) - tau_q).norm(), 1e-9 * (1 + tau_q.norm())) << trial;

    // A point's world velocity through the Jacobians of each base.
    const int body = euler.nbodies() - 1;
    const Eigen::Vector3d p(0.1, -0.2, 0.3);
    Eigen::MatrixXd Je = Eigen::MatrixXd::Zero(3, n), Jq = Eigen::MatrixXd::Zero(3, n);
    forwardKinematics(euler, de, qe);
    forwardKinematics(quat, dq, s.q);
    pointJacobian(euler, de, body, p, Je);
    pointJacobian(quat, dq, body, p, Jq);
    EXPECT_LT((Je * ve - Jq * s.v).norm(), 1e-11 * (1 + (Je * ve).norm())) << trial;
  }
}

// integrate and difference are inverse; the quaternion stays unit; over many small steps with a
// constant ω_B the orientation is exactly the rotation exp(ω_B t) (no truncation for a constant
// body rate).
TEST(Configuration, IntegrateAndDifferenceAreInverse) {
  std::mt19937 rng(5);
  const Model<double> model = testing::randomTreeBuilder(rng, 3).build(BaseType::FreeQuaternion);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q = testing::randomVector(rng, model.nq(), 1.0);
    normalizeConfiguration(model, q);
    const Eigen::VectorXd v = testing::randomVector(rng, model.nv(), 2.0);
    Eigen::VectorXd q1(model.nq());
    integrate(model, q, v, 0.3, q1);
    EXPECT_NEAR(q1.segment<4>(3).norm(), 1.0, 1e-15);
    EXPECT_LT((difference(model, q, q1) - 0.3 * v).norm(), 1e-12) << trial;
  }
  Eigen::VectorXd q = neutralConfiguration(model);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(model.nv());
  v.segment<3>(3) = Eigen::Vector3d(0.3, -1.1, 2.0);
  for (int step = 0; step < 10000; ++step) integrate(model, q, v, 1e-3, q);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(10.0 * v.segment<3>(3).norm(), v.segment<3>(3).normalized()).toRotationMatrix();
  EXPECT_LT((quaternionToRotation(q.segment<4>(3)) - expected).norm(), 1e-11);
  EXPECT_NEAR(q.segment<4>(3).norm(), 1.0, 1e-14);
}

// Finite differences on the manifold: d/dε of a point's world position along q ⊕ ε e_k is the
// point Jacobian's column k, for every velocity coordinate.
TEST(Configuration, FiniteDifferencesOnTheManifoldGiveTheJacobian) {
  std::mt19937 rng(11);
  const Model<double> model = testing::randomTreeBuilder(rng, 5).build(BaseType::FreeQuaternion);
  Data<double> data(model);
  const int n = model.nv(), body = model.nbodies() - 1;
  const Eigen::Vector3d p(0.2, 0.1, -0.1);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q = testing::randomVector(rng, model.nq(), 1.5);
    normalizeConfiguration(model, q);
    forwardKinematics(model, data, q);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, n);
    pointJacobian(model, data, body, p, J);
    const double eps = 1e-6;
    Eigen::VectorXd qp(model.nq()), qm(model.nq());
    for (int k = 0; k < n; ++k) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, k);
      integrate(model, q, e, eps, qp);
      integrate(model, q, e, -eps, qm);
      forwardKinematics(model, data, qp);
      const Eigen::Vector3d xp = pointPosition(data, body, p);
      forwardKinematics(model, data, qm);
      const Eigen::Vector3d xm = pointPosition(data, body, p);
      EXPECT_LT(((xp - xm) / (2 * eps) - J.col(k)).norm(), 1e-8) << "trial " << trial << " coordinate " << k;
    }
  }
}

// A quaternion off the unit sphere still gives a rotation; a zero one is refused.
TEST(Configuration, NonUnitQuaternionsAreNormalised) {
  std::mt19937 rng(2);
  const Model<double> model = testing::randomTreeBuilder(rng, 2).build(BaseType::FreeQuaternion);
  Data<double> a(model), b(model);
  Eigen::VectorXd q = testing::randomVector(rng, model.nq(), 1.0);
  Eigen::VectorXd q_scaled = q;
  q_scaled.segment<4>(3) *= 3.7;
  forwardKinematics(model, a, q);
  forwardKinematics(model, b, q_scaled);
  EXPECT_LT((a.X_world.back().E - b.X_world.back().E).norm(), 1e-14);
  EXPECT_LT((a.X_world.back().E * a.X_world.back().E.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  q.segment<4>(3).setZero();
  EXPECT_THROW(normalizeConfiguration(model, q), std::invalid_argument);
  EXPECT_THROW(checkedForDerivatives(model), std::invalid_argument);
}

}  // namespace
}  // namespace saltus::dynamics
