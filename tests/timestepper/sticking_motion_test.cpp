// The exact sticking motions of timestepper/sticking_motion.hpp: Painlevé's rod (hand values of
// the impulse, the cone condition against Painlevé's B, conservation and finite differences of the
// pivot motion, where sticking ends) and the pendulum stuck to the belt (the point follows the
// belt, velocities and forces against finite differences, impulse and forces against the
// time-stepper's), and the time-stepper converging to both.
#include "timestepper/sticking_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "dynamics/dynamics.hpp"
#include "scene/scenario.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::timestepper::exact {
namespace {

constexpr double kG = 9.81;

StepperOptions thetaOptions(double dt, double theta) {
  StepperOptions o;
  o.dt = dt;
  o.theta = theta;
  return o;
}

// |[q; v] − exact| at T after stepping the scene at dt.
template <class Exact>
double stepperError(const scene::Scene& scene, double dt, double theta, double T, const Exact& exact) {
  TimeStepper sim(scene, thetaOptions(dt, theta));
  const long steps = std::lround(T / dt);
  for (long i = 0; i < steps; ++i) sim.step();
  Eigen::VectorXd x(sim.q().size() + sim.v().size());
  x << sim.q(), sim.v();
  return (x - exact(sim.time())).norm();
}

TEST(PainleveRodMotion, ImpulseAndVelocitiesAtTanTwoMatchHandValues) {
  // tan θ0 = 2: cos² = 0.2, sin cos = 0.4; l = 0.5, u = 1: P/m = (−1.6/4, 1.2/4) = (−0.4, 0.3),
  // (ẋ, ż, θ̇)⁺ = (0.75 · 0.8, 0.75 · 0.4, 0.75 · 0.8944/0.5).
  const double angle = std::atan(2.0), l = 0.5;
  const PainleveRodMotion rod(l, angle, 1.0, 2.0, kG);
  EXPECT_NEAR(rod.paradoxCoefficient(), 1 + 0.6 - 2.4, 1e-15);
  EXPECT_TRUE(rod.stopsByImpulse());
  EXPECT_NEAR(rod.impulsePerMass()[0], -0.4, 1e-15);
  EXPECT_NEAR(rod.impulsePerMass()[1], 0.3, 1e-15);
  const Eigen::Matrix<double, 6, 1> x = rod.planarState(0, 0, 0);
  EXPECT_NEAR(x[0], 0, 1e-15);
  EXPECT_NEAR(x[1], l * std::sin(angle), 1e-15);
  EXPECT_NEAR(x[2], angle, 1e-15);
  EXPECT_NEAR(x[3], 0.6, 1e-15);
  EXPECT_NEAR(x[4], 0.3, 1e-15);
  EXPECT_NEAR(x[5], 0.75 * 2 / std::sqrt(5.0) / l, 1e-14);
}

TEST(PainleveRodMotion, ImpulseConservesMomentaAndStopsTheEnd) {
  for (const double angle : {0.3, 0.8, 1.2})
    for (const double l : {0.25, 1.0}) {
      const double u = 1.7, m = 1.0, I = m * l * l / 3;
      const PainleveRodMotion rod(l, angle, u, 10.0, kG);
      const Eigen::Vector2d P = rod.impulsePerMass() * m;
      const Eigen::Matrix<double, 6, 1> x = rod.planarState(0, 0, 0);
      EXPECT_NEAR(m * (x[3] - u), P[0], 1e-14);  // linear momentum
      EXPECT_NEAR(m * x[4], P[1], 1e-14);
      // Angular momentum about the centre (rotation about +y): end at r = (l cos θ, −l sin θ),
      // (r × P)_y = r_z P_x − r_x P_z.
      EXPECT_NEAR(I * x[5], -l * std::sin(angle) * P[0] - l * std::cos(angle) * P[1], 1e-14);
      // The end is at rest: v_end = v_c + ω × r.
      EXPECT_NEAR(x[3] - l * std::sin(angle) * x[5], 0, 1e-14);
      EXPECT_NEAR(x[4] - l * std::cos(angle) * x[5], 0, 1e-14);
    }
}

TEST(PainleveRodMotion, ImpulseInsideTheConeExactlyInPainlevesRegion) {
  int inside = 0, outside = 0;
  for (double mu = 0.5; mu <= 3.0; mu += 0.25)
    for (double angle = 0.1; angle < 1.5; angle += 0.1) {
      const PainleveRodMotion rod(0.5, angle, 1.0, mu, kG);
      const Eigen::Vector2d P = rod.impulsePerMass();
      const double c = std::cos(angle), s = std::sin(angle);
      const bool in_cone = std::abs(P[0]) <= mu * P[1];
      EXPECT_EQ(rod.stopsByImpulse(), in_cone) << "mu " << mu << " angle " << angle;
      EXPECT_EQ(in_cone, mu > (1 + 3 * c * c) / (3 * s * c)) << "mu " << mu << " angle " << angle;
      (in_cone ? inside : outside)++;
      if (!in_cone) {
        EXPECT_EQ(rod.stickEnd(1.0), 0.0);
      }
    }
  EXPECT_GT(inside, 10);  // the grid spans both sides
  EXPECT_GT(outside, 10);
  // The least μ of the paradox, 4/3 at tan θ = 2 (Champneys & Várkonyi 2016), is the boundary.
  EXPECT_NEAR(PainleveRodMotion(0.5, std::atan(2.0), 1.0, 4.0 / 3, kG).paradoxCoefficient(), 0, 1e-15);
}

TEST(PainleveRodMotion, PivotMotionConservesEnergyAndMatchesFiniteDifferences) {
  const double l = 0.5;
  const PainleveRodMotion rod(l, std::atan(2.0), 1.0, 2.0, kG);
  // Energy per unit mass about the stuck end: ½ (4/3) l² θ̇² + g l sin θ.
  const auto energy = [&](double t) {
    const auto s = rod.at(t);
    return 0.5 * 4.0 / 3 * l * l * s.theta_dot * s.theta_dot + kG * l * std::sin(s.theta);
  };
  for (const double t : {0.1, 0.37, 0.7}) {
    EXPECT_NEAR(energy(t), energy(0), 1e-12) << "t = " << t;
    const double h = 1e-4;
    const Eigen::Matrix<double, 6, 1> xm = rod.planarState(t - h, 0, 0), x0 = rod.planarState(t, 0, 0),
                                      xp = rod.planarState(t + h, 0, 0);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR((xp[k] - xm[k]) / (2 * h), x0[3 + k], 1e-7) << "t = " << t << " k " << k;
    // The end force: F = m (a_c + g ẑ), a_c by second differences of the centre.
    const auto st = rod.at(t);
    EXPECT_NEAR((xp[0] - 2 * x0[0] + xm[0]) / (h * h), st.force_t, 1e-5) << "t = " << t;
    EXPECT_NEAR((xp[1] - 2 * x0[1] + xm[1]) / (h * h) + kG, st.force_n, 1e-5) << "t = " << t;
  }
}

TEST(PainleveRodMotion, StickingEndsWhereTheForceLeavesTheCone) {
  const double mu = 2.0;
  const PainleveRodMotion rod(0.5, std::atan(2.0), 1.0, mu, kG);
  const double t_end = rod.stickEnd(2.0);
  ASSERT_TRUE(std::isfinite(t_end));
  const auto at_end = rod.at(t_end);
  EXPECT_NEAR(std::abs(at_end.force_t), mu * at_end.force_n, 1e-9);
  for (double t = 0; t < t_end - 1e-6; t += 0.01) {
    const auto s = rod.at(t);
    EXPECT_GT(s.force_n, 0);
    EXPECT_LT(std::abs(s.force_t), mu * s.force_n) << "t = " << t;
  }
  const auto after = rod.at(t_end + 1e-3);
  EXPECT_GT(std::abs(after.force_t), mu * after.force_n);
  // The built-in scene ends while the end still sticks.
  EXPECT_LT(scene::loadScene("painleve_rod").duration, t_end);
  EXPECT_TRUE(std::isinf(rod.stickEnd(0.5)));
  EXPECT_THROW(PainleveRodMotion(0.5, 1.6, 1.0, mu, kG), std::invalid_argument);
  EXPECT_THROW(PainleveRodMotion(0.5, 1.0, 0.0, mu, kG), std::invalid_argument);
}

TEST(PainleveRodMotion, TimeStepperConvergesToIt) {
  // The impulse falls within the first step, applied where the θ-step is linearised (its middle
  // for θ = ½), so both schemes are first order here: the rod's rise starts half a step late.
  const scene::Scene scene = scene::loadScene("painleve_rod");
  const PainleveRodMotion rod(0.5, std::atan(2.0), 1.0, 2.0, kG);
  const auto exact = [&](double t) { return Eigen::VectorXd(rod.planarState(t, 0, 0)); };
  for (const double theta : {1.0, 0.5}) {
    const double e1 = stepperError(scene, 2e-3, theta, 0.5, exact);
    const double e2 = stepperError(scene, 1e-3, theta, 0.5, exact);
    const double e3 = stepperError(scene, 5e-4, theta, 0.5, exact);
    EXPECT_GT(e1 / e2, 1.8) << "theta " << theta;
    EXPECT_GT(e2 / e3, 1.8) << "theta " << theta;
    EXPECT_LT(e3, 5e-3) << "theta " << theta;  // measured 4.5e-3 (θ = 1), 4.4e-3 (θ = ½)
  }
}

// ---------------------------------------------------------------------------------------------

TEST(BeltStickingMotion, PointFollowsTheBeltWithMatchingVelocities) {
  const scene::Scene scene = scene::loadScene("pendulum_conveyor");  // belt 0.5 m/s from 0.1 s
  const BeltStickingMotion belt(scene);
  dynamics::Data<double> data(scene.model);
  const scene::Contact& c = scene.contacts[0];
  dynamics::forwardKinematics(scene.model, data, scene.q0);
  const Eigen::Vector3d p0 = dynamics::pointPosition(data, c.body, c.p_B);
  for (const double t : {0.0, 0.05, 0.1, 0.25, 0.5}) {
    const Eigen::VectorXd x = belt.state(t);
    dynamics::forwardKinematics(scene.model, data, x.head(2), x.tail(2));
    const Eigen::Vector3d p = dynamics::pointPosition(data, c.body, c.p_B);
    const double moved = 0.5 * std::max(0.0, t - 0.1);
    EXPECT_NEAR(p.x(), p0.x() + moved, 1e-12) << "t = " << t;
    EXPECT_NEAR(p.z(), p0.z(), 1e-12) << "t = " << t;
    const Eigen::Vector3d v = dynamics::pointVelocity(data, c.body, c.p_B);
    EXPECT_NEAR(v.x(), t >= 0.1 ? 0.5 : 0.0, 1e-12) << "t = " << t;
    EXPECT_NEAR(v.z(), 0, 1e-12) << "t = " << t;
    if (t > 0.1) {  // q̇ against central differences of q
      const double h = 1e-5;
      const Eigen::VectorXd qd = (belt.state(t + h).head(2) - belt.state(t - h).head(2)) / (2 * h);
      EXPECT_NEAR((qd - x.tail(2)).norm(), 0, 1e-8) << "t = " << t;
    }
  }
  EXPECT_NEAR((belt.state(0.05) - belt.state(0)).norm(), 0, 1e-15);  // at rest before the step
}

TEST(BeltStickingMotion, ImpulseAndForcesMatchTheTimeSteppers) {
  // The stepper's impulses per step are an independent measurement of the same forces: pn/dt and
  // pt/dt over a sticking step, and the step's impulse at the belt step (plus dt times the force).
  const scene::Scene scene = scene::loadScene("pendulum_conveyor");
  const BeltStickingMotion belt(scene);
  const double dt = 1e-4;
  TimeStepper sim(scene, thetaOptions(dt, 0.5));
  while (sim.time() < 0.05 - 1e-12) sim.step();
  const Eigen::Vector2d F0 = belt.contactForce(0.05);
  EXPECT_NEAR(sim.contacts()[0].pn / dt, F0[1], 1e-6 * F0[1]);
  EXPECT_NEAR(sim.contacts()[0].pt1 / dt, F0[0], 1e-6 * F0[1]);
  while (sim.time() < 0.1 - 1e-12) sim.step();  // the step ending at 0.1 s carries the impulse
  const Eigen::Vector2d P = belt.stepImpulse(0.1);
  EXPECT_GT(P[1], 0);
  EXPECT_LE(std::abs(P[0]), scene.contacts[0].friction * P[1]);  // the impulse is inside the cone
  EXPECT_NEAR(sim.contacts()[0].pn, P[1], 0.02 * P[1]);
  EXPECT_NEAR(sim.contacts()[0].pt1, P[0], 0.02 * P[1]);
  while (sim.time() < 0.3 - 1e-12) sim.step();
  // With θ = ½ the impulses of a sticking contact alternate from step to step (6.04 / 6.73 N s per
  // dt here); their mean over 10 ms is the force (measured within 3e-5 of it).
  double pn = 0, pt = 0;
  for (int i = 0; i < 100; ++i) {
    sim.step();
    pn += sim.contacts()[0].pn;
    pt += sim.contacts()[0].pt1;
  }
  const Eigen::Vector2d F = belt.contactForce(0.305);
  EXPECT_NEAR(pn / 0.01, F[1], 0.01 * F[1]);
  EXPECT_NEAR(pt / 0.01, F[0], 0.01 * F[1]);
  EXPECT_TRUE(std::isinf(belt.stickEnd(scene.duration)));
}

TEST(BeltStickingMotion, TimeStepperConvergesToIt) {
  // The step that ends at the belt step sees the belt at its new speed throughout: first order.
  const scene::Scene scene = scene::loadScene("pendulum_conveyor");
  const BeltStickingMotion belt(scene);
  const auto exact = [&](double t) { return belt.state(t); };
  for (const double theta : {1.0, 0.5}) {
    const double e1 = stepperError(scene, 2e-3, theta, scene.duration, exact);
    const double e2 = stepperError(scene, 1e-3, theta, scene.duration, exact);
    const double e3 = stepperError(scene, 5e-4, theta, scene.duration, exact);
    EXPECT_GT(e1 / e2, 1.8) << "theta " << theta;
    EXPECT_GT(e2 / e3, 1.8) << "theta " << theta;
    EXPECT_LT(e3, 6e-4) << "theta " << theta;  // measured 5.3e-4 (θ = 1), 2.0e-4 (θ = ½)
  }
}

TEST(BeltStickingMotion, StickingEndsWhenTheBeltOutrunsTheCone) {
  // Left running, the belt drags the tip until friction can no longer hold it (after 1.8 s at
  // 0.5 m/s); at the returned time the force is on the cone's boundary.
  const scene::Scene scene = scene::loadScene("pendulum_conveyor");
  const BeltStickingMotion belt(scene);
  const double t_end = belt.stickEnd(5.0);
  ASSERT_TRUE(std::isfinite(t_end));
  EXPECT_GT(t_end, 0.1);
  const Eigen::Vector2d F = belt.contactForce(t_end);
  EXPECT_NEAR(std::max(-F[1], std::abs(F[0]) - scene.contacts[0].friction * F[1]), 0, 1e-6);
}

TEST(BeltStickingMotion, RefusesScenesOfAnotherKind) {
  try {
    BeltStickingMotion motion(scene::loadScene("ball_drop"));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("two coordinates"), std::string::npos) << e.what();
  }
  try {
    BeltStickingMotion motion(scene::loadScene("block_slide"));  // two coordinates, moving at t = 0
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at rest"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saltus::timestepper::exact
