// The time-stepper with impacts located within the step (StepperOptions::locate_impacts): the
// ball's apexes to round-off, its rest time, elastic bounces conserving energy, steps without a
// new contact unchanged, and an impact on a joint-limit stop.
#include "timestepper/stepper.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "scene/scenario.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/scenes.hpp"

// A named namespace: the folder's test files are compiled as one unit (unity build).
namespace saltus::timestepper::located_impacts_test {

constexpr double g = 9.81;

StepperOptions options(double dt, double theta = 0.5) {
  StepperOptions o;
  o.dt = dt;
  o.theta = theta;
  return o;
}

// Apex after each bounce from the state where the ball turns (v from > 0 to ≤ 0): z + v²/(2g),
// the free-flight apex through that state, so the grid's sampling does not enter; and the rest
// time as in dropBall.
struct LocatedBounces {
  std::vector<double> apex, sampled_apex;
  double rest_time = -1;
  long located = 0;
};

LocatedBounces dropBallLocated(double h0, double e, double dt, double theta, double duration, bool locate = true) {
  StepperOptions o = options(dt, theta);
  o.locate_impacts = locate;
  TimeStepper sim(testing::ballDrop(h0, e), o);
  LocatedBounces out;
  double prev_v = 0, top = 0;
  while (sim.time() < duration) {
    sim.step();
    const double z = sim.q()[0], v = sim.v()[0];
    if (v > 0 && prev_v <= 0) top = z;
    if (prev_v > 0) top = std::max(top, z);
    if (v <= 0 && prev_v > 0) {
      out.apex.push_back(z + v * v / (2 * g));
      out.sampled_apex.push_back(top);
    }
    if (out.rest_time < 0 && std::abs(v) < 1e-9 && z < 1e-6 && sim.contacts()[0].active) out.rest_time = sim.time();
    prev_v = v;
  }
  out.located = sim.stats().located_impacts;
  return out;
}

// θ = ½ is exact in free fall and the gap is quadratic in t, so the impact is found exactly: the
// apexes are e^(2k) h0 to round-off at any dt (measured on the first apex over dt = 2e-3, 1e-3,
// 5e-4: 0.9e-15, −3.1e-15, −1.3e-15 m; without locating −1.57e-3, −1.58e-3, −1.13e-3 m, short by
// the part of a step of free fall that depends on where the grid falls). The highest sample differs
// from the apex by at most ½ g (dt/2)², the grid's sampling (measured −2.5e-6, −4.0e-7, −2.3e-7 m).
// θ = 1 stays first order (its free flight is): measured 3.31e-3, 1.66e-3, 8.3e-4 m.
TEST(Stepper, LocatedImpactsGiveTheBallsApexesToRoundOff) {
  const double h0 = 1.0, e = 0.5;
  for (double dt : {2e-3, 1e-3, 5e-4}) {
    const LocatedBounces b = dropBallLocated(h0, e, dt, 0.5, 1.5);
    ASSERT_GE(b.apex.size(), 3u) << "dt = " << dt;
    for (int k = 1; k <= 3; ++k) {
      const double exact = std::pow(e, 2 * k) * h0;
      EXPECT_NEAR(b.apex[k - 1], exact, 1e-12) << "dt = " << dt << ", bounce " << k;
      EXPECT_LE(exact - b.sampled_apex[k - 1], 0.5 * g * dt * dt / 4 + 1e-12) << "dt = " << dt << ", bounce " << k;
      EXPECT_GE(exact - b.sampled_apex[k - 1], -1e-12) << "dt = " << dt << ", bounce " << k;
    }
    EXPECT_GE(b.located, 3) << "dt = " << dt;
    // Without locating the first apex is short by up to one step of free fall.
    const LocatedBounces old = dropBallLocated(h0, e, dt, 0.5, 0.8, false);
    EXPECT_GT(std::abs(old.apex[0] - e * e * h0), 0.1 * dt) << "dt = " << dt;
    EXPECT_EQ(old.located, 0);
    std::printf("apex dt %g: located %.3g (sampled %.3g), not located %.3g (sampled %.3g)\n", dt,
                b.apex[0] - e * e * h0, b.sampled_apex[0] - e * e * h0, old.apex[0] - e * e * h0,
                old.sampled_apex[0] - e * e * h0);
  }
  // θ = 1: first order, the error halves with dt.
  std::vector<double> errors;
  for (double dt : {2e-3, 1e-3, 5e-4}) {
    errors.push_back(std::abs(dropBallLocated(h0, e, dt, 1.0, 0.8).apex[0] - e * e * h0));
    std::printf("apex θ = 1, dt %g: located %.3g, not located %.3g\n", dt, errors.back(),
                dropBallLocated(h0, e, dt, 1.0, 0.8, false).apex[0] - e * e * h0);
  }
  for (int i = 0; i < 2; ++i)
    EXPECT_NEAR(std::log2(errors[i] / errors[i + 1]), 1.0, 0.1) << errors[i] << " " << errors[i + 1];
}

// The bounces die out at √(2h0/g)(1+e)/(1−e). Approach speeds below 2 g dt are inelastic (not
// located: the step's gap term lands the ball at the step's end), which cuts the remaining flights,
// at most 2 e v/(g(1−e)) with v < 2 g dt; rest is seen at the end of that step or the next. So
// −4 e dt/(1−e) − dt ≤ t − t_rest ≤ 2 dt (measured, (t − t_rest)/dt at dt = 2e-3, 1e-3: e = 0.3
// −0.27, +0.46; e = 0.5 −2.3, −2.6; e = 0.8 −11.9, −12.7, bound −17). At smaller dt the 1e-6 m contact margin ends the bounces first (a
// bounce lower than the margin is not an open contact).
TEST(Stepper, LocatedImpactsRestTime) {
  const double h0 = 1.0;
  for (double e : {0.3, 0.5, 0.8})
    for (double dt : {2e-3, 1e-3}) {
      const double t_rest = std::sqrt(2 * h0 / g) * (1 + e) / (1 - e);
      const LocatedBounces b = dropBallLocated(h0, e, dt, 0.5, t_rest + 0.2);
      ASSERT_GT(b.rest_time, 0) << "e = " << e << ", dt = " << dt;
      EXPECT_LE(b.rest_time - t_rest, 2 * dt + 1e-12) << "e = " << e << ", dt = " << dt;
      EXPECT_GE(b.rest_time - t_rest, -4 * e * dt / (1 - e) - dt - 1e-12) << "e = " << e << ", dt = " << dt;
      std::printf("rest e %g dt %g: (t - t_rest)/dt = %.3f, located %ld\n", e, dt, (b.rest_time - t_rest) / dt,
                  b.located);
    }
}

// e = 1: with θ = ½ the energy is conserved through five bounces to round-off; with θ = 1 it never
// rises (the free flight dissipates ½ g² h² per (sub-)step).
TEST(Stepper, LocatedElasticBouncesConserveEnergy) {
  for (double dt : {1e-3, 1e-2}) {
    StepperOptions o = options(dt, 0.5);
    TimeStepper sim(testing::ballDrop(1.0, 1.0), o);
    const double E0 = sim.energy();
    double error = 0;
    while (sim.stats().located_impacts < 5 || sim.v()[0] > 0 || sim.q()[0] < 0.5) {
      sim.step();
      error = std::max(error, std::abs(sim.energy() - E0));
    }
    EXPECT_LT(error, 1e-12 * E0) << "dt = " << dt;
    EXPECT_EQ(sim.stats().located_impacts, 5);
    o.theta = 1.0;
    TimeStepper implicit(testing::ballDrop(1.0, 1.0), o);
    double E_prev = implicit.energy();
    while (implicit.stats().located_impacts < 5 || implicit.time() < sim.time()) {
      implicit.step();
      EXPECT_LE(implicit.energy(), E_prev + 1e-12 * E0) << "dt = " << dt << ", t = " << implicit.time();
      E_prev = implicit.energy();
    }
  }
}

// Steps in which no open contact closes are computed as without the option, bit for bit: scenes
// whose contacts are closed from the start, and the ball up to its first impact.
TEST(Stepper, LocatingLeavesStepsWithoutANewContactUnchanged) {
  const std::vector<Scene> scenes = {testing::blockSlide(0.2, 1.0, 0.3), testing::blockSlide(0.0, 2.0, 0.3),
                                     testing::pendulumConveyor(2.0, 0.5, 0.01),
                                     testing::painleveRod(2.0, std::atan(2.0), 1.0),
                                     testing::painleveRod(0.5, 0.6, 2.0),
                                     testing::particle3d(Eigen::Vector2d(1.0, 0.5), 0.4, 8)};
  for (const Scene& scene : scenes)
    for (double theta : {0.5, 1.0}) {
      StepperOptions plain_options = options(1e-3, theta);
      plain_options.locate_impacts = false;
      TimeStepper located(scene, options(1e-3, theta)), plain(scene, plain_options);
      for (int i = 0; i < 1000; ++i) {
        located.step();
        plain.step();
        ASSERT_TRUE(located.q() == plain.q() && located.v() == plain.v())
            << scene.name << " θ = " << theta << ", step " << i;
      }
      EXPECT_EQ(located.stats().located_impacts, 0) << scene.name;
    }
  for (double theta : {0.5, 1.0}) {
    StepperOptions plain_options = options(1e-3, theta);
    plain_options.locate_impacts = false;
    const Scene ball = testing::ballDrop(0.3, 0.5);
    TimeStepper located(ball, options(1e-3, theta)), plain(ball, plain_options);
    while (located.stats().located_impacts == 0) {
      ASSERT_TRUE(located.q() == plain.q() && located.v() == plain.v()) << "t = " << located.time();
      located.step();
      plain.step();
      ASSERT_LT(located.time(), 0.3);
    }
    EXPECT_NE(located.q(), plain.q());
    EXPECT_DOUBLE_EQ(located.time(), plain.time());  // the grid stays the same
  }
}

// A joint-limit stop hit at constant speed (no gravity) is located exactly: after the step with
// the impact the coordinate is where the rebound puts it, at any dt.
TEST(Stepper, LocatedImpactOnAJointLimitStop) {
  Scene scene;
  scene.name = "pendulum_stop";
  scene.model = testing::pendulumModel({1.0}, {0.5});
  scene.model.gravity.setZero();
  LimitStop stop;
  stop.name = "joint1_upper";
  stop.coordinate = 0;
  stop.upper = true;
  stop.limit = 0.3;
  stop.restitution = 0.5;
  scene.limits.push_back(stop);
  scene.q0 = Eigen::VectorXd::Zero(1);
  scene.v0 = Eigen::VectorXd::Constant(1, 2.0);
  for (double dt : {1e-3, 7e-3}) {
    TimeStepper sim(scene, options(dt, 1.0));
    while (sim.time() < 0.3) sim.step();
    const double t_hit = 0.3 / 2.0;
    EXPECT_NEAR(sim.v()[0], -1.0, 1e-12) << "dt = " << dt;
    EXPECT_NEAR(sim.q()[0], 0.3 - 1.0 * (sim.time() - t_hit), 1e-12) << "dt = " << dt;
    EXPECT_EQ(sim.stats().located_impacts, 1);
  }
}

}  // namespace saltus::timestepper::located_impacts_test
