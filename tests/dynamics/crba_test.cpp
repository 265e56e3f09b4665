// CRBA against RNEA columns, kinetic energy and the closed-form pendulum and free body.
#include "dynamics/crba.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "tests/support/free_body.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/random_model.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

TEST(Crba, DoublePendulumClosedForm) {
  const Model<double> model = testing::pendulumModel({1.0, 1.0}, {0.5, 0.5});
  Data<double> data(model);
  for (double th2 : {0.0, M_PI / 4, 2.0}) {
    const Eigen::Vector2d q(0.3, th2);
    EXPECT_LT((crba(model, data, q) - testing::doublePendulumMassMatrix(1, 1, 0.5, 0.5, th2)).norm(), 1e-12);
  }
}

TEST(Crba, FreeBodyKineticEnergy) {
  std::mt19937 rng(5);
  double m;
  Eigen::Vector3d c;
  Eigen::Matrix3d Ic;
  testing::randomInertia(rng, m, c, Ic);
  const Model<double> model = testing::freeBodyModel(m, c, Ic);
  Data<double> data(model);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd q = testing::randomVector(rng, 6, 1.2), v = testing::randomVector(rng, 6, 2);
    const Eigen::MatrixXd& M = crba(model, data, q);
    // T = ½ m |ṗ_c|² + ½ ωᵀ I_c,W ω with ω from the Euler rates.
    const Eigen::Matrix3d R = testing::eulerRotation(q);
    const Eigen::Vector3d w = testing::eulerAngularVelocity(q, v);
    const Eigen::Vector3d v_com = v.head<3>() + w.cross(R * c);
    const double T = 0.5 * m * v_com.squaredNorm() + 0.5 * w.dot(R * Ic * R.transpose() * w);
    EXPECT_NEAR(0.5 * v.dot(M * v), T, 1e-12 * (1 + T));
  }
}

TEST(Crba, ColumnsEqualRneaAndMatrixIsSymmetricPositiveDefinite) {
  std::mt19937 rng(21);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int k = 0; k < 8; ++k) {
      const Model<double> model = testing::randomTreeBuilder(rng, 3 + 2 * k).build(base);
      Data<double> data(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n, 1.2), v = testing::randomVector(rng, n);
      const Eigen::MatrixXd M = crba(model, data, q);
      EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
      EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(M).info(), Eigen::Success);
      // M e_j = RNEA(q, v, e_j) − RNEA(q, v, 0).
      const Eigen::VectorXd h = nonLinearEffects(model, data, q, v);
      for (int j = 0; j < n; ++j) {
        const Eigen::VectorXd col = rnea(model, data, q, v, Eigen::VectorXd::Unit(n, j)) - h;
        EXPECT_LT((col - M.col(j)).norm(), 1e-10 * (1 + M.norm())) << toString(base) << " column " << j;
      }
      // ½ vᵀ M v = Σ ½ v_iᵀ I_i v_i.
      forwardKinematics(model, data, q, v);
      EXPECT_NEAR(0.5 * v.dot(M * v), kineticEnergy(model, data), 1e-10 * (1 + M.norm()));
    }
  }
}

TEST(Crba, WrongArgumentSizeIsAnError) {
  testing::ArgumentSizes a;
  const auto& [model, data, ok, bad] = std::tie(a.model, a.data, a.ok, a.bad);
  auto error = [](const std::function<void()>& f) { return testing::invalidArgumentOf(f); };
  EXPECT_EQ(error([&] { crba(model, data, bad); }), "crba: q has 4 entries; the model has 3 coordinates");
  EXPECT_EQ(error([&] { crba(model, data, ok); }), "");
}

}  // namespace
}  // namespace saltus::dynamics
