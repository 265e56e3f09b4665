// Spatial algebra against the 6×6 matrix forms of RBDA chapter 2.
#include "dynamics/spatial.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

struct SpatialTest : ::testing::Test {
  std::mt19937 rng{7};
  Transform<double> randomTransform() {
    const Eigen::VectorXd x = testing::randomVector(rng, 7);
    return {Eigen::Quaterniond(x[0], x[1], x[2], x[3]).normalized().toRotationMatrix(), x.tail<3>()};
  }
  Motion<double> randomMotion() { return Motion<double>::FromVector(testing::randomVector(rng, 6)); }
  Force<double> randomForce() { return Force<double>::FromVector(testing::randomVector(rng, 6)); }
};

TEST_F(SpatialTest, TransformActsAsItsMatrix) {
  for (int k = 0; k < 20; ++k) {
    const Transform<double> X = randomTransform();
    const Motion<double> m = randomMotion();
    const Force<double> f = randomForce();
    const Mat6<double> Xm = X.matrix();
    // X* = X⁻ᵀ (RBDA 2.25).
    const Mat6<double> Xf = Xm.inverse().transpose();
    EXPECT_LT((X.apply(m).vector() - Xm * m.vector()).norm(), 1e-12);
    EXPECT_LT((X.apply(f).vector() - Xf * f.vector()).norm(), 1e-12);
    EXPECT_LT((X.applyInverse(m).vector() - Xm.inverse() * m.vector()).norm(), 1e-12);
    EXPECT_LT((X.applyTranspose(f).vector() - Xm.transpose() * f.vector()).norm(), 1e-12);
    EXPECT_LT((X.inverse().matrix() - Xm.inverse()).norm(), 1e-12);
    // Power is frame invariant: (X m)·(X* f) = m·f.
    EXPECT_NEAR(dot(X.apply(m), X.apply(f)), dot(m, f), 1e-12);
  }
}

TEST_F(SpatialTest, CompositionMultipliesMatrices) {
  const Transform<double> A = randomTransform(), B = randomTransform();
  EXPECT_LT(((A * B).matrix() - A.matrix() * B.matrix()).norm(), 1e-12);
}

TEST_F(SpatialTest, CrossProductsAreDual) {
  // crf(v) = −crm(v)ᵀ (RBDA 2.32): (v × m)·f = −m·(v ×* f).
  const Motion<double> v = randomMotion(), m = randomMotion();
  const Force<double> f = randomForce();
  EXPECT_NEAR(dot(v.cross(m), f), -dot(m, v.crossForce(f)), 1e-12);
}

TEST_F(SpatialTest, InertiaTransformMatchesMatrixSandwich) {
  double mass;
  Eigen::Vector3d c;
  Eigen::Matrix3d Ic;
  for (int k = 0; k < 20; ++k) {
    testing::randomInertia(rng, mass, c, Ic);
    const RigidInertia<double> I = RigidInertia<double>::FromCom(mass, c, Ic);
    const Transform<double> X = randomTransform();
    const Mat6<double> expected = X.matrix().transpose() * I.matrix() * X.matrix();
    EXPECT_LT((I.transformedBy(X).matrix() - expected).norm(), 1e-12);
    const Motion<double> v = randomMotion();
    EXPECT_LT(((I * v).vector() - I.matrix() * v.vector()).norm(), 1e-12);
    // Kinetic energy ½ vᵀ I v is the rigid-body formula ½ m |v_c|² + ½ ωᵀ I_c ω.
    const Eigen::Vector3d v_com = v.v + v.w.cross(c);
    EXPECT_NEAR(dot(v, I * v), mass * v_com.squaredNorm() + v.w.dot(Ic * v.w), 1e-12);
  }
}

TEST_F(SpatialTest, AxisAngleIsARotationAboutTheAxis) {
  const Eigen::Vector3d axis = testing::randomVector(rng, 3).normalized();
  const Mat3<double> R = axisAngle<double>(axis, 0.7);
  EXPECT_LT((R * R.transpose() - Mat3<double>::Identity()).norm(), 1e-14);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  EXPECT_LT((R * axis - axis).norm(), 1e-14);
  EXPECT_LT((R - Eigen::AngleAxisd(0.7, axis).toRotationMatrix()).norm(), 1e-14);
}

}  // namespace
}  // namespace saltus::dynamics
