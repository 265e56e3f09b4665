// verify/mujoco_world.hpp: MuJoCo built from a saltus scene. The restitution mapping inverts the
// spring's rebound formula; the rebound is Newton's within 0.02 at dt 1e-4; a resting ball is held
// by its weight's impulse; a block slides the Coulomb distance v0²/(2 μ g); a planar body flies
// the analytic parabola with the saltus coordinates (x, z, θ); MuJoCo's contact starts where
// saltus' gap closes on a tilted rod; scenes it cannot build are refused by name.
#include "verify/mujoco_world.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "scene/scenario.hpp"
#include "timestepper/analytic.hpp"

namespace saltus::verify {
namespace {

MujocoWorldOptions withDt(double dt) {
  MujocoWorldOptions o;
  o.dt = dt;
  return o;
}

// A linear spring of damping ratio ζ rebounds with e = exp(−π ζ / √(1 − ζ²)).
TEST(MujocoWorld, TheDampingRatioGivesTheRestitutionBack) {
  EXPECT_EQ(dampingRatioForRestitution(0), 1.0);
  EXPECT_EQ(dampingRatioForRestitution(1), 0.0);
  for (double e : {0.1, 0.5, 0.9, 0.99}) {
    const double zeta = dampingRatioForRestitution(e);
    EXPECT_NEAR(std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta)), e, 1e-14) << e;
  }
  EXPECT_THROW(dampingRatioForRestitution(1.5), std::invalid_argument);
}

// The first rebound's height is e_eff² h; MuJoCo's contact spring gives e_eff near the scene's e
// at small steps (its impedance below 1 and the discrete spring shift it at large ones).
double reboundRatio(double e, double dt) {
  const scene::Scene scene = scene::loadScene("ball_drop", {{"restitution", e}, {"height", 1.0}});
  MujocoWorld world(scene, withDt(dt));
  double apex = 0;
  while (world.time() < 0.8) {  // lands at 0.45 s; the apex at about 0.68 s
    world.step();
    if (world.time() > 0.5) apex = std::max(apex, world.q()[0]);
  }
  EXPECT_EQ(world.stats().warnings, 0);
  return std::sqrt(apex);
}

TEST(MujocoWorld, TheReboundIsNewtonsWithinTwoHundredthsAtSmallSteps) {
  // measured e_eff: e = 0.5: 0.609 (dt 1e-3), 0.501 (1e-4); e = 0.9: 0.906, 0.885
  for (double e : {0.5, 0.9}) {
    EXPECT_NEAR(reboundRatio(e, 1e-4), e, 0.02) << "e = " << e;
    EXPECT_NEAR(reboundRatio(e, 1e-3), e, 0.12) << "e = " << e;
  }
}

// At rest on the ground the contact carries the weight: m g dt a step, pointing up (the sign of
// MuJoCo's contact force on the body), sinking less than a millimetre.
TEST(MujocoWorld, ARestingBallIsHeldByItsWeight) {
  const scene::Scene scene = scene::loadScene("ball_drop", {{"restitution", 0.0}});
  const double dt = 1e-3, m = scene.model.totalMass();
  MujocoWorld world(scene, withDt(dt));
  world.reset(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), 0);
  for (int k = 0; k < 500; ++k) world.step();
  EXPECT_TRUE(world.contacts()[0].active);
  EXPECT_NEAR(world.contacts()[0].pn, m * 9.81 * dt, 1e-3 * m * 9.81 * dt);
  EXPECT_NEAR(world.contacts()[0].pt1, 0, 1e-12);
  EXPECT_LT(world.stats().max_penetration, 1e-3);
  EXPECT_NEAR(world.v()[0], 0, 1e-6);
}

// Coulomb friction on level ground stops a block after v0²/(2 μ g) (block_slide's own answer).
TEST(MujocoWorld, ABlockSlidesTheCoulombDistance) {
  const double v0 = 2, mu = 0.3, g = 9.81;
  const scene::Scene scene = scene::loadScene("block_slide", {{"speed", v0}, {"friction", mu}});
  MujocoWorld world(scene, withDt(1e-4));
  for (int k = 0; k < 10000; ++k) world.step();  // stops at v0/(μ g) = 0.68 s
  const int s = scene.model.coordinateIndex("s");
  EXPECT_NEAR(world.q()[s], v0 * v0 / (2 * mu * g), 0.005 * v0 * v0 / (2 * mu * g));
  EXPECT_NEAR(world.v()[s], 0, 1e-3);
  EXPECT_NEAR(world.contacts()[0].pt1, 0, 1e-9);  // at rest on level ground: no friction
}

// No contact: the planar base flies the parabola, coordinate by coordinate, with semi-implicit
// Euler's O(dt) error: x, z and θ map onto MuJoCo's slides and hinge by name and axis.
TEST(MujocoWorld, APlanarBodyFliesTheParabolaInSaltusCoordinates) {
  const scene::Scene scene = scene::loadScene("painleve_rod", {});
  const double dt = 1e-4, T = 0.3, g = 9.81;
  MujocoWorld world(scene, withDt(dt));
  Eigen::Vector3d q0(0.2, 5.0, 0.4), v0(1.5, 2.0, -3.0);  // (x, z, θ): far above the ground
  world.reset(q0, v0, 0);
  while (world.time() < T - 1e-12) world.step();
  EXPECT_NEAR(world.q()[0], q0[0] + v0[0] * T, 1e-9);
  EXPECT_NEAR(world.q()[1], q0[1] + v0[1] * T - g * T * T / 2, g * T * dt);
  EXPECT_NEAR(world.q()[2], q0[2] + v0[2] * T, 1e-9);
  EXPECT_NEAR(world.v()[1], v0[1] - g * T, 1e-9);
  EXPECT_NEAR(world.energy(), 0.5 * scene.model.totalMass() * (v0[0] * v0[0] + v0[1] * v0[1]) +
                                  scene.model.totalMass() * g * q0[1] + 0.5 * scene.model.inertia[0].I(1, 1) * v0[2] * v0[2],
              scene.model.totalMass() * g * g * T * dt);
}

// A tilted rod dropped on its tip: MuJoCo's contact (its sphere at the saltus contact point,
// turned by θ) starts where saltus' gap reaches zero, and is not active before.
TEST(MujocoWorld, TheContactStartsWhereSaltusGapCloses) {
  const scene::Scene scene = scene::loadScene("painleve_rod", {{"friction", 0.3}});
  const double dt = 1e-4;
  MujocoWorld world(scene, withDt(dt));
  Eigen::VectorXd q = scene.q0, v = Eigen::VectorXd::Zero(3);
  q[1] += 0.05;  // 5 cm above the ground
  world.reset(q, v, 0);
  bool touched = false;
  for (int k = 0; k < 3000 && !touched; ++k) {
    const double gap_before = world.contacts()[0].gap;
    world.step();
    if (world.contacts()[0].active) {
      touched = true;
      EXPECT_LT(gap_before, 2e-4);  // a step's travel at 1 m/s
      EXPECT_GT(world.contacts()[0].pn, 0);
    }
  }
  EXPECT_TRUE(touched);
}

TEST(MujocoWorld, ScenesItCannotBuildAreRefusedByName) {
  try {
    MujocoWorld world(scene::loadScene("pendulum_conveyor", {}));
    FAIL() << "built";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("moves (a belt)"), std::string::npos) << e.what();
  }
  try {
    MujocoWorld world(scene::loadScene(SALTUS_SOURCE_DIR "/tests/data/scenes/free_rigid_body.yaml", {}));
    FAIL() << "built";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("use base: free_quaternion"), std::string::npos) << e.what();
  }
}

// A quaternion base is MuJoCo's free joint, state as it is: fast_spin flips at Landau and
// Lifshitz's times (MuJoCo's semi-implicit Euler, dt 1e-3: within 10 ms), its quaternion stays
// unit; the box on four corners rests flat, sunk by MuJoCo's soft contact by less than a
// millimetre, and does not turn.
TEST(MujocoWorld, AQuaternionBaseIsMujocosFreeJoint) {
  const scene::Scene spin = scene::loadScene("fast_spin", {});
  MujocoWorld world(spin, withDt(1e-3));
  const std::vector<double> flips = timestepper::analytic::spinFlipTimes(0.1, 0.2, 0.3, 6.0, 0.01, spin.duration);
  std::vector<double> seen;
  const double E0 = 0.5 * (0.2 * 36 + 0.3 * 1e-4);
  double largest_dE = 0;
  while (world.time() < spin.duration - 1e-9) {
    const double before = world.v()[4];
    world.step();
    ASSERT_EQ(world.q().size(), 7);
    EXPECT_NEAR(world.q().segment<4>(3).norm(), 1.0, 1e-12);
    if (before * world.v()[4] < 0) seen.push_back(world.time());
    const Eigen::Vector3d w = world.v().segment<3>(3);
    largest_dE = std::max(largest_dE, std::abs(0.5 * (0.1 * w[0] * w[0] + 0.2 * w[1] * w[1] + 0.3 * w[2] * w[2]) - E0));
  }
  ASSERT_EQ(seen.size(), flips.size());
  for (std::size_t i = 0; i < flips.size(); ++i) EXPECT_NEAR(seen[i], flips[i], 1e-2);
  EXPECT_LT(largest_dE / E0, 0.05);
  std::printf("[ mujoco   ] fast_spin dt 1e-3: flips at %.4f, %.4f s (analytic %.4f, %.4f); largest |dE|/E0 %.2g\n", seen[0],
              seen[1], flips[0], flips[1], largest_dE / E0);

  const scene::Scene box = scene::loadScene("box_on_corners", {});
  MujocoWorld resting(box, withDt(1e-3));
  for (int k = 0; k < 1000; ++k) resting.step();
  const double half_z = box.parameters.at("half_z");
  EXPECT_NEAR(resting.q()[2], half_z, 1e-3);
  EXPECT_LT((resting.q().segment<4>(3) - Eigen::Vector4d(1, 0, 0, 0)).norm(), 1e-6);
  EXPECT_LT(resting.q().head<2>().norm(), 1e-6);
}

// A contact on a plane fixed in another body (a box on the plane's body): the touching cradle's
// balls come out of the impact with momentum kept, and a block on a pulled cart keeps the cart's
// contact force on both bodies (equal and opposite: the pair's total horizontal momentum grows
// by the pulling force alone).
TEST(MujocoWorld, AContactOnABodysPlane) {
  const scene::Scene cradle = scene::loadScene("newtons_cradle", {});
  MujocoWorld world(cradle, withDt(1e-4));
  while (world.time() < cradle.duration - 1e-12) world.step();
  EXPECT_NEAR(world.v().sum(), 1.0, 1e-6);  // momentum / (m v)
  EXPECT_GT(world.v()[2], 0.5);             // the last ball leaves
  EXPECT_LT(world.stats().max_penetration, 1e-3);
  const scene::Scene cart = scene::loadScene("block_on_cart", {{"force", 10.0}});  // sticks: F < μ g (M + m)
  MujocoWorld pulled(cart, withDt(1e-3));
  for (int k = 0; k < 300; ++k) pulled.step();
  const double M = cart.parameters.at("cart_mass"), m = cart.parameters.at("block_mass");
  const int cx = cart.model.coordinateIndex("cart_x"), bx = cart.model.coordinateIndex("block_x");
  EXPECT_NEAR(M * pulled.v()[cx] + m * pulled.v()[bx], 10.0 * pulled.time(), 1e-6);
  EXPECT_NEAR(pulled.v()[bx], pulled.v()[cx], 0.02);  // the block rides on the cart
  EXPECT_TRUE(pulled.contacts()[0].active);
}

// The model MuJoCo compiled is kept, and says what it approximates.
TEST(MujocoWorld, TheModelAndItsApproximationsAreReported) {
  const MujocoWorld world(scene::loadScene("ball_drop", {}));
  EXPECT_NE(world.mjcf().find("<pair geom1=\"contact0\" geom2=\"surface0\""), std::string::npos) << world.mjcf();
  bool restitution = false;
  for (const std::string& a : world.approximations()) restitution = restitution || a.find("restitution") != std::string::npos;
  EXPECT_TRUE(restitution);
}

}  // namespace
}  // namespace saltus::verify
