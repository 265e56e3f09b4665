// Energy balance dE/dt = q̇ᵀτ along ABA, centre of mass of a pendulum.
#include "dynamics/energy.hpp"

#include <gtest/gtest.h>

#include "dynamics/aba.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/random_model.hpp"

namespace saltus::dynamics {
namespace {

double totalEnergy(const Model<double>& model, Data<double>& data, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  forwardKinematics(model, data, q, v);
  return kineticEnergy(model, data) + potentialEnergy(model, data);
}

TEST(Energy, PowerBalanceAlongForwardDynamics) {
  std::mt19937 rng(61);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int k = 0; k < 5; ++k) {
      const Model<double> model = testing::randomTreeBuilder(rng, 3 + 2 * k).build(base);
      Data<double> data(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                            tau = testing::randomVector(rng, n, 3);
      const Eigen::VectorXd qdd = aba(model, data, q, v, tau);
      const double eps = 1e-6;
      // q(t) = q + t v + t²/2 q̈ and v(t) = v + t q̈: the central difference is exact to O(eps²).
      const double dEdt = (totalEnergy(model, data, q + eps * v + 0.5 * eps * eps * qdd, v + eps * qdd) -
                           totalEnergy(model, data, q - eps * v + 0.5 * eps * eps * qdd, v - eps * qdd)) / (2 * eps);
      EXPECT_NEAR(dEdt, v.dot(tau), 1e-6 * (1 + std::abs(v.dot(tau)))) << toString(base);
    }
  }
}

TEST(Energy, PendulumCentreOfMassAndPotential) {
  const Model<double> model = testing::pendulumModel({1.0, 2.0}, {0.5, 0.8});
  Data<double> data(model);
  const Eigen::Vector2d q(0.3, -0.5);
  forwardKinematics(model, data, q);
  // Rotation about +y by θ maps (0, 0, −c) to (−c sin θ, 0, −c cos θ).
  const Eigen::Vector3d c1(-0.25 * std::sin(0.3), 0, -0.25 * std::cos(0.3));
  const Eigen::Vector3d c2 = Eigen::Vector3d(-0.5 * std::sin(0.3), 0, -0.5 * std::cos(0.3)) +
                             Eigen::Vector3d(-0.4 * std::sin(-0.2), 0, -0.4 * std::cos(-0.2));
  const Eigen::Vector3d com = (1.0 * c1 + 2.0 * c2) / 3.0;
  EXPECT_LT((centerOfMass(model, data) - com).norm(), 1e-14);
  EXPECT_DOUBLE_EQ(data.mass, 3.0);
  EXPECT_NEAR(potentialEnergy(model, data), 3.0 * 9.81 * com.z(), 1e-12);
}

}  // namespace
}  // namespace saltus::dynamics
