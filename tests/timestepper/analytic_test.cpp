// The closed-form answers of timestepper/analytic.hpp against hand values and each other
// (elementary mechanics), the first-apex measurement on synthetic trajectories, and one
// run of the time-stepper on the built-in ball_drop scene measured with it.
#include "timestepper/analytic.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "dynamics/configuration.hpp"
#include "dynamics/kinematics.hpp"
#include "scene/scenario.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::timestepper::analytic {
namespace {

constexpr double g = 9.81;

TEST(Analytic, BallApexes) {
  EXPECT_DOUBLE_EQ(ballApex(1.0, 0.5, 0), 1.0);
  EXPECT_DOUBLE_EQ(ballApex(1.0, 0.5, 1), 0.25);
  EXPECT_DOUBLE_EQ(ballApex(1.0, 0.5, 2), 0.0625);  // e^(2k) h0: 0.25000 / 0.06250 m
  EXPECT_DOUBLE_EQ(ballApex(2.0, 0.8, 1), 2.0 * 0.64);
  EXPECT_DOUBLE_EQ(ballApex(1.0, 0.0, 1), 0.0);
}

TEST(Analytic, BallImpactSpeedMatchesApex) {
  // v_k² = 2 g h_k: the ball leaves impact k at e v_k and rises to h_(k+1).
  for (double e : {0.3, 0.5, 1.0})
    for (int k = 0; k < 3; ++k) {
      const double v = ballImpactSpeed(1.5, e, k, g);
      EXPECT_NEAR(v * v, 2 * g * ballApex(1.5, e, k), 1e-12) << "e " << e << " k " << k;
    }
  EXPECT_NEAR(ballImpactSpeed(1.0, 0.5, 0, g), std::sqrt(2 * g), 1e-15);
}

TEST(Analytic, BallRestTimeIsTheSumOfTheFlights) {
  // √(2h0/g) to the first impact, then 2 e^k √(2h0/g) per bounce: a geometric series.
  const double h0 = 1.0, e = 0.5;
  EXPECT_NEAR(ballRestTime(h0, e, g), 1.355, 5e-4);  // models/scenes/README.md
  double t = std::sqrt(2 * h0 / g);
  for (int k = 1; k < 200; ++k) t += 2 * std::pow(e, k) * std::sqrt(2 * h0 / g);
  EXPECT_NEAR(ballRestTime(h0, e, g), t, 1e-12);
  EXPECT_TRUE(std::isinf(ballRestTime(h0, 1.0, g)));
  EXPECT_NEAR(ballRestTime(h0, 0.0, g), std::sqrt(2 * h0 / g), 1e-15);
}

TEST(Analytic, LevelSlideStops) {
  // README: v0 = 2 m/s, μ = 0.3 stops after v0/(μg) = 0.680 s at v0²/(2μg) = 0.680 m.
  const double v0 = 2.0, mu = 0.3;
  EXPECT_TRUE(slideSticks(mu, 0));
  EXPECT_DOUBLE_EQ(slideAcceleration(mu, 0, g), -mu * g);
  EXPECT_NEAR(slideStopTime(v0, mu, 0, g), v0 / (mu * g), 1e-15);
  EXPECT_NEAR(slideStopDistance(v0, mu, 0, g), v0 * v0 / (2 * mu * g), 1e-15);
  EXPECT_NEAR(slideStopDistance(v0, mu, 0, g), 0.6796, 1e-4);
  // v0²/(2μg): μ = 0.37, v0 = 2.3 m/s stops at 0.72871 m.
  EXPECT_NEAR(slideStopDistance(2.3, 0.37, 0, g), 0.72871, 1e-5);
}

TEST(Analytic, SlidePositionFollowsTheParabolaThenStays) {
  const double v0 = 2.0, mu = 0.5, alpha = 0.2;  // tan α = 0.203 < μ: decelerates and sticks
  const double a = slideAcceleration(mu, alpha, g), t_stop = slideStopTime(v0, mu, alpha, g);
  ASSERT_LT(a, 0);
  EXPECT_NEAR(slideStopDistance(v0, mu, alpha, g), v0 * v0 / (2 * g * (mu * std::cos(alpha) - std::sin(alpha))), 1e-15);
  EXPECT_NEAR(slidePosition(v0, mu, alpha, g, 0.5 * t_stop), v0 * 0.5 * t_stop + 0.5 * a * 0.25 * t_stop * t_stop, 1e-14);
  EXPECT_NEAR(slidePosition(v0, mu, alpha, g, t_stop), slideStopDistance(v0, mu, alpha, g), 1e-14);
  EXPECT_DOUBLE_EQ(slidePosition(v0, mu, alpha, g, 10 * t_stop), slideStopDistance(v0, mu, alpha, g));
  EXPECT_DOUBLE_EQ(slidePosition(v0, mu, alpha, g, 0), 0);
}

TEST(Analytic, SteepSlideAccelerates) {
  const double v0 = 1.0, mu = 0.3, alpha = 0.5;  // tan α = 0.546 > μ
  EXPECT_FALSE(slideSticks(mu, alpha));
  const double a = slideAcceleration(mu, alpha, g);
  EXPECT_NEAR(a, g * (std::sin(alpha) - mu * std::cos(alpha)), 1e-15);
  EXPECT_GT(a, 0);
  EXPECT_TRUE(std::isinf(slideStopTime(v0, mu, alpha, g)));
  EXPECT_TRUE(std::isinf(slideStopDistance(v0, mu, alpha, g)));
  for (double t : {0.1, 1.0, 3.0}) EXPECT_NEAR(slidePosition(v0, mu, alpha, g, t), v0 * t + 0.5 * a * t * t, 1e-12);
  // tan α = μ exactly: a = 0 (up to round-off), constant speed.
  EXPECT_TRUE(slideSticks(std::tan(0.3), 0.3));
  EXPECT_NEAR(slidePosition(v0, std::tan(0.3), 0.3, g, 2.0), 2.0 * v0, 1e-12);
}

// Samples of an exact bouncing ball: heights at t = i dt, impulse > 0 at the sample just after
// each impact.
void exactBounces(double h0, double e, double dt, double duration, std::vector<double>& z, std::vector<double>& pn) {
  z.clear();
  pn.clear();
  const double t1 = std::sqrt(2 * h0 / g);
  for (int i = 0; i * dt <= duration; ++i) {
    const double t = i * dt;
    double zi, impulse = 0;
    if (t < t1) {
      zi = h0 - 0.5 * g * t * t;
    } else {
      // after the k-th impact: flights of length 2 e^k t1
      double start = t1, flight = 2 * e * t1, v = e * g * t1;
      int k = 1;
      while (t >= start + flight && k < 50) start += flight, flight *= e, v *= e, ++k;
      const double s = t - start;
      zi = v * s - 0.5 * g * s * s;
      if (s < dt) impulse = 1;  // the step that ended here contained impact k
    }
    z.push_back(zi);
    pn.push_back(impulse);
  }
}

TEST(Analytic, FirstApexOfAnExactTrajectory) {
  std::vector<double> z, pn;
  exactBounces(1.0, 0.5, 1e-4, 2.0, z, pn);
  EXPECT_NEAR(firstApex(z, pn), 0.25, 1e-6);
  exactBounces(1.0, 0.8, 1e-3, 3.0, z, pn);
  EXPECT_NEAR(firstApex(z, pn), 0.64, 1e-5);
}

TEST(Analytic, FirstApexEdgeCases) {
  // No impact: NaN.
  EXPECT_TRUE(std::isnan(firstApex({1.0, 0.9, 0.5}, {0, 0, 0})));
  EXPECT_TRUE(std::isnan(firstApex({}, {})));
  // An impact spread over two samples, then flight, then the second impact: the apex is the
  // highest sample in between, not the start height and not after the second impact.
  EXPECT_DOUBLE_EQ(firstApex({1.0, 0.0, 0.0, 0.1, 0.3, 0.2, 0.0, 0.05, 0.9}, {0, 1, 2, 0, 0, 0, 3, 0, 0}), 0.3);
  // No second impact: up to the end.
  EXPECT_DOUBLE_EQ(firstApex({1.0, 0.0, 0.2, 0.4}, {0, 1, 0, 0}), 0.4);
  EXPECT_THROW(firstApex({1.0}, {}), std::invalid_argument);
}

TEST(Analytic, StepperOnTheBuiltInBallDropScene) {
  const Scene scene = scene::loadScene("ball_drop", {{"restitution", 0.5}});
  StepperOptions o;
  o.dt = 1e-4;
  TimeStepper sim(scene, o);
  std::vector<double> z{sim.q()[0]}, pn{0};
  while (sim.time() < 1.2) {
    sim.step();
    z.push_back(sim.q()[0]);
    pn.push_back(sim.contacts()[0].pn);
  }
  EXPECT_NEAR(firstApex(z, pn), ballApex(scene.parameters.at("height"), 0.5, 1), 2e-3);
}

// newtons_cradle: with the resting balls touching, the stepper's impact (all contacts at once)
// gives the LCP's velocities for every e, keeping momentum (and energy for e = 1); with them
// 1 mm apart the impacts are pairwise and e = 1 passes the velocity down the row.
TEST(Analytic, StepperOnNewtonsCradle) {
  for (double e : {0.0, 0.5, 1.0}) {
    SCOPED_TRACE("e = " + std::to_string(e));
    const Scene scene = scene::loadScene("newtons_cradle", {{"restitution", e}});
    StepperOptions o;
    o.dt = 1e-3;
    TimeStepper sim(scene, o);
    const double E0 = sim.energy();
    while (sim.time() < scene.duration - 1e-12) sim.step();
    const std::vector<double> v = cradleVelocities(e, 1.0);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(sim.v()[i], v[i], 1e-12) << i;
    EXPECT_NEAR(sim.v().sum(), 1.0, 1e-12);  // momentum / (m v)
    if (e == 1.0) { EXPECT_NEAR(sim.energy(), E0, 1e-14); }
  }
  const Scene apart = scene::loadScene("newtons_cradle", {{"spacing", 1e-3}});
  StepperOptions o;
  o.dt = 1e-3;
  TimeStepper sim(apart, o);
  while (sim.time() < apart.duration - 1e-12) sim.step();
  EXPECT_NEAR(sim.v()[0], 0, 1e-12);
  EXPECT_NEAR(sim.v()[1], 0, 1e-12);
  EXPECT_NEAR(sim.v()[2], 1, 1e-12);
}

// box_on_corners: four contacts for six coordinates, a rank-deficient LCP. Resting, and dropped
// flat from 0.2 m: after landing the reactions, whatever split Lemke picks, are non-negative,
// sum to m g dt and have no moment about the centre of mass; the box stays flat where it is,
// with no jitter, creep or turn.
TEST(Analytic, StepperOnTheBoxOnFourCorners) {
  for (double drop : {0.0, 0.2}) {
    SCOPED_TRACE("drop " + std::to_string(drop));
    const Scene scene = scene::loadScene("box_on_corners", {{"drop", drop}});
    const double m = scene.model.totalMass(), g = 9.81, dt = 1e-3;
    StepperOptions o;
    o.dt = dt;
    TimeStepper sim(scene, o);
    const double t_land = std::sqrt(2 * drop / g);
    while (sim.time() < scene.duration - 1e-12) {
      sim.step();
      if (sim.time() < t_land + 2 * dt) continue;
      double sum = 0;
      Eigen::Vector2d moment = Eigen::Vector2d::Zero();  // about the centre, of the vertical reactions
      for (std::size_t c = 0; c < 4; ++c) {
        const double pn = sim.contacts()[c].pn;
        EXPECT_GE(pn, -1e-15);
        sum += pn;
        moment += pn * Eigen::Vector2d(scene.contacts[c].p_B.y(), -scene.contacts[c].p_B.x());
      }
      ASSERT_NEAR(sum, m * g * dt, 1e-12 * m * g) << "t = " << sim.time();
      ASSERT_LT(moment.norm(), 1e-12) << "t = " << sim.time();
    }
    Eigen::VectorXd rest = dynamics::neutralConfiguration(scene.model);
    rest[scene.model.positionIndex("base_z")] = scene.parameters.at("half_z");
    EXPECT_LT((sim.q() - rest).lpNorm<Eigen::Infinity>(), 1e-12) << sim.q().transpose();
    EXPECT_LT(sim.v().lpNorm<Eigen::Infinity>(), 1e-12) << sim.v().transpose();
    EXPECT_EQ(sim.stats().lcp_failures, 0);
  }
}

// chain_on_stops: ten links falling onto nine pairs of stops, many struck in one step. The step
// never fails, no stop is passed (an impulse on one stop drives others closed within the step:
// they get rows and the LCP is solved again; before, stops were passed by 4.4 mrad), the energy
// never rises above its start (the semi-implicit step wobbles by O(dt) in free motion; only the
// inelastic stops act), and the stats report the stops' penetration as the reports show it.
TEST(Analytic, StepperOnTheChainOnItsStops) {
  const Scene scene = scene::loadScene("chain_on_stops", {});
  StepperOptions o;
  o.dt = 1e-3;
  TimeStepper sim(scene, o);
  const double energy_start = sim.energy();
  double largest_gap_below = 0;
  int most_at_once = 0;
  while (sim.time() < scene.duration - 1e-12) {
    sim.step();
    int struck = 0;
    for (const ContactReport& r : sim.contacts()) {
      struck += r.pn > 0;
      largest_gap_below = std::max(largest_gap_below, -r.gap);
    }
    most_at_once = std::max(most_at_once, struck);
    ASSERT_LE(sim.energy(), energy_start + 1e-3) << "t = " << sim.time();
  }
  EXPECT_LT(sim.energy(), energy_start - 0.1);
  EXPECT_GE(most_at_once, 5);
  EXPECT_EQ(sim.stats().lcp_failures, 0);
  EXPECT_GE(sim.stats().max_stop_penetration, largest_gap_below);
  EXPECT_LT(sim.stats().max_stop_penetration, 1e-9);
  EXPECT_EQ(sim.stats().max_penetration, 0);  // no point contacts
}

// Housner's rocking block: a square block loses 3/4 of its angular velocity (α = π/4,
// r = 1 − 3/4); the tilt after an impact inverts the return speed; the measurement finds the
// largest |θ| between the first two flat instants.
TEST(Analytic, RockingBlockClosedForms) {
  EXPECT_NEAR(rockingImpactRatio(0.3, 0.3), 0.25, 1e-15);
  EXPECT_NEAR(rockingImpactRatio(0.1, 0.4), 1 - 1.5 / 17, 1e-15);  // sin² α = b² / R²
  for (double theta0 : {0.01, 0.1, 0.2})
    EXPECT_NEAR(rockingTilt(0.1, 0.4, rockingReturnSpeed(0.1, 0.4, theta0, 9.81), 9.81), theta0, 1e-12) << theta0;
  EXPECT_DOUBLE_EQ(rockingFirstTilt({0.1, 0.05, -0.02, -0.07, -0.04, 0.01, 0.3}), 0.07);
  EXPECT_DOUBLE_EQ(rockingFirstTilt({0.1, -0.02, -0.05}), 0.05);  // no second flat: to the end
  EXPECT_TRUE(std::isnan(rockingFirstTilt({0.1, 0.05, 0.01})));
}

// The stepper on rocking_block (θ = ½, dt 1e-4): the block comes back flat at the pendulum's
// speed, loses Housner's fraction at each of six impacts, rocks to the tilt the energy gives, and
// never slides (it is flat at the same place every time).
TEST(Analytic, StepperOnTheRockingBlock) {
  const Scene scene = scene::loadScene("rocking_block", {});
  const double b = scene.parameters.at("half_width"), h = scene.parameters.at("half_height"),
               theta0 = scene.parameters.at("tilt"), g = 9.81;
  StepperOptions o;
  o.dt = 1e-4;
  o.theta = 0.5;
  TimeStepper sim(scene, o);
  const int x = scene.model.coordinateIndex("base_x"), th = scene.model.coordinateIndex("base_theta");
  const double x_flat = b * std::cos(theta0) - h * std::sin(theta0) - b;  // the pivot stays at x = b cos θ0 − h sin θ0
  std::vector<double> theta{sim.q()[th]};
  double omega_expected = rockingReturnSpeed(b, h, theta0, g);
  int impacts = 0;
  while (sim.time() < scene.duration && impacts < 6) {
    const double theta_before = sim.q()[th], omega_before = sim.v()[th];
    sim.step();
    theta.push_back(sim.q()[th]);
    EXPECT_GT(sim.contacts()[0].gap, -1e-9);
    EXPECT_GT(sim.contacts()[1].gap, -1e-9);
    if (theta_before * sim.q()[th] < 0) {  // flat within this step: the impact
      ++impacts;
      SCOPED_TRACE("impact " + std::to_string(impacts));
      EXPECT_NEAR(std::abs(omega_before), omega_expected, 2e-3 * omega_expected);
      EXPECT_NEAR(sim.v()[th] / omega_before, rockingImpactRatio(b, h), 2e-3);
      EXPECT_NEAR(sim.q()[x], x_flat, 1e-4);
      omega_expected *= rockingImpactRatio(b, h);
    }
  }
  EXPECT_EQ(impacts, 6);
  const double first_tilt = rockingTilt(b, h, rockingImpactRatio(b, h) * rockingReturnSpeed(b, h, theta0, g), g);
  EXPECT_NEAR(rockingFirstTilt(theta), first_tilt, 1e-3 * first_tilt);
}

// hyq_drop (a quaternion base, 12 joints, 4 feet with friction, 24 stops; θ = 1, dt 1e-3): the
// feet land together and the legs fold onto their knee stops; no foot and no stop is passed
// (measured before the projection: feet 1.6e-6 m, stops 0; with θ = ½, 2.7e-4 m and 8.5e-4 rad),
// the mechanical energy never rises above its start, no LCP fails, and by 1 s the robot is still
// on its feet where they landed.
TEST(Analytic, StepperOnTheHyqDrop) {
  const Scene scene = scene::loadScene("hyq_drop", {});
  ASSERT_EQ(scene.model.nq(), 19);
  ASSERT_EQ(scene.limits.size(), 24u);
  StepperOptions o;
  o.dt = 1e-3;
  o.theta = 1.0;
  TimeStepper sim(scene, o);
  const double E0 = sim.energy();
  std::vector<Eigen::Vector2d> landed(4, Eigen::Vector2d::Constant(std::nan("")));
  dynamics::Data<double> data(scene.model);
  double largest_E = E0;
  while (sim.time() < scene.duration - 1e-12) {
    sim.step();
    largest_E = std::max(largest_E, sim.energy());
    dynamics::forwardKinematics(scene.model, data, sim.q());
    for (int c = 0; c < 4; ++c) {
      ASSERT_GT(sim.contacts()[c].gap, -o.penetration_tolerance) << "t = " << sim.time();
      const Eigen::Vector3d foot = dynamics::pointPosition(data, scene.contacts[c].body, scene.contacts[c].p_B);
      if (std::isnan(landed[c][0]) && sim.contacts()[c].active) landed[c] = foot.head<2>();
    }
  }
  EXPECT_EQ(sim.stats().lcp_failures, 0);
  EXPECT_LT(sim.stats().max_penetration, 1e-5);
  EXPECT_LT(sim.stats().max_stop_penetration, 1e-6);
  EXPECT_LT(largest_E - E0, 1e-9 * E0);
  EXPECT_LT(sim.energy(), E0 - 100);  // the fall's energy lost in the impacts and the folding
  for (const char* knee : {"lf_kfe_joint", "rf_kfe_joint", "lh_kfe_joint", "rh_kfe_joint"})
    EXPECT_NEAR(std::abs(sim.q()[scene.model.positionIndex(knee)]), 2.44346095279, 1e-3) << knee;
  EXPECT_LT(sim.v().lpNorm<Eigen::Infinity>(), 0.2);
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d foot = dynamics::pointPosition(data, scene.contacts[c].body, scene.contacts[c].p_B);
    EXPECT_LT((foot.head<2>() - landed[c]).norm(), 1e-2) << scene.contacts[c].name;
  }
}

// box_stack (three boxes at rest, the top one 1, 100 or 10,000 times heavier): Lemke gives each
// contact the weight above it, to round-off, at every step, and nothing moves; projected
// Gauss–Seidel does not converge from a ratio of 100 and the step fails with its residual.
TEST(Analytic, StepperOnTheBoxStack) {
  for (double ratio : {1.0, 100.0, 1e4}) {
    SCOPED_TRACE("mass_ratio " + std::to_string(ratio));
    const Scene scene = scene::loadScene("box_stack", {{"mass_ratio", ratio}});
    const double m = scene.parameters.at("mass"), g = 9.81, dt = 1e-3;
    const double weight_above[3] = {(2 + ratio) * m * g, (1 + ratio) * m * g, ratio * m * g};  // ground, middle, top
    StepperOptions o;
    o.dt = dt;
    TimeStepper sim(scene, o);
    const Eigen::VectorXd q0 = sim.q();
    for (int k = 0; k < 200; ++k) {
      sim.step();
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(sim.contacts()[c].pn, weight_above[c] * dt, 1e-11 * weight_above[0] * dt) << c;
    }
    EXPECT_LT((sim.q() - q0).lpNorm<Eigen::Infinity>(), 1e-12);
    EXPECT_LT(sim.v().lpNorm<Eigen::Infinity>(), 1e-12);
    EXPECT_EQ(sim.stats().lcp_failures, 0);
  }
  StepperOptions pgs;
  pgs.dt = 1e-3;
  pgs.solver = LcpMethod::Pgs;
  TimeStepper equal(scene::loadScene("box_stack", {}), pgs);
  for (int k = 0; k < 200; ++k) equal.step();  // ratio 1: converges
  TimeStepper heavy(scene::loadScene("box_stack", {{"mass_ratio", 100.0}}), pgs);
  EXPECT_THROW(heavy.step(), SimulationError);
}

// Landau and Lifshitz's flip times against a hand evaluation: λ = √12.0001, k' = √(8.33e-6),
// K ≈ ln(4/k') for k → 1 (Abramowitz and Stegun 17.3.26).
TEST(Analytic, SpinFlipTimes) {
  const std::vector<double> t = spinFlipTimes(0.1, 0.2, 0.3, 6.0, 0.01, 10.0);
  ASSERT_EQ(t.size(), 2u);
  const double lambda = std::sqrt(0.1 * 0.720006 / 0.006), kp = std::sqrt(1 - 0.72 / 0.720006);
  EXPECT_NEAR(t[0], std::log(4 / kp) / lambda, 1e-5);
  EXPECT_NEAR(t[1], 3 * t[0], 1e-12);
}

// The stepper on fast_spin (a quaternion base, no contact) over 42 s, five periods of the flip:
// the body flips at Landau and Lifshitz's times (ten flips), energy and the world angular momentum
// hold to the integrator's order (θ = ½: second, bounded at 3e-6 of E_0 over the five periods;
// θ = 1: first, growing to 7 %), and the quaternion stays unit, tumbling through every attitude
// (the Euler-angle base stops at pitch ±π/2).
TEST(Analytic, StepperOnTheFastSpin) {
  const Scene scene = scene::loadScene("fast_spin", {});
  ASSERT_EQ(scene.model.base, dynamics::BaseType::FreeQuaternion);
  const Eigen::Vector3d I(0.1, 0.2, 0.3);
  const double w2 = scene.parameters.at("spin"), w3 = scene.parameters.at("wobble"), t_end = 42.0;
  const std::vector<double> flips = spinFlipTimes(I[0], I[1], I[2], w2, w3, t_end);
  ASSERT_EQ(flips.size(), 10u);
  auto momentum = [&](const TimeStepper& sim) -> Eigen::Vector3d {
    const Eigen::Vector4d Q = sim.q().segment<4>(3);
    return Eigen::Quaterniond(Q[0], Q[1], Q[2], Q[3]).toRotationMatrix() * I.cwiseProduct(sim.v().segment<3>(3));
  };
  for (double theta : {0.5, 1.0}) {
    double drift[2] = {0, 0};
    for (int refine = 0; refine < 2; ++refine) {
      SCOPED_TRACE("theta " + std::to_string(theta) + " refine " + std::to_string(refine));
      StepperOptions o;
      o.dt = 1e-3 / (1 << refine);
      o.theta = theta;
      TimeStepper sim(scene, o);
      const double E0 = sim.energy();
      const Eigen::Vector3d L0 = momentum(sim);
      std::vector<double> seen;
      double largest_L = 0, largest_norm = 0;
      while (sim.time() < t_end - 1e-12) {
        const double before = sim.v()[4];
        sim.step();
        if (before * sim.v()[4] < 0) seen.push_back(sim.time());
        drift[refine] = std::max(drift[refine], std::abs(sim.energy() - E0));
        largest_L = std::max(largest_L, (momentum(sim) - L0).norm());
        largest_norm = std::max(largest_norm, std::abs(sim.q().segment<4>(3).norm() - 1));
      }
      ASSERT_EQ(seen.size(), flips.size());
      for (std::size_t i = 0; i < flips.size(); ++i) EXPECT_NEAR(seen[i], flips[i], theta == 0.5 ? 2e-3 : 5e-3) << i;
      EXPECT_LT(drift[refine] / E0, theta == 0.5 ? 1e-5 : 0.1);
      EXPECT_LT(largest_L / L0.norm(), theta == 0.5 ? 1e-5 : 5e-2);
      EXPECT_LT(largest_norm, 1e-14);
    }
    const double order = std::log2(drift[0] / drift[1]);
    EXPECT_NEAR(order, theta == 0.5 ? 2.0 : 1.0, 0.25) << "theta " << theta;
  }
}

}  // namespace
}  // namespace saltus::timestepper::analytic
