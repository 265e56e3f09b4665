// The time-stepper on contact between two moving bodies (a point on one body against a plane
// fixed in the other): the built-in scenes block_on_cart and block_on_slab against elementary
// mechanics (Coulomb friction on a pulled cart, Newton's restitution, conservation of momentum),
// and the plane's extent (a block sliding off the deck's end falls freely).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "scene/scenario.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::timestepper {
namespace {

constexpr double kGravity = 9.81;

StepperOptions twoBodyOptions(double dt) {
  StepperOptions o;
  o.dt = dt;
  o.theta = 0.5;
  o.solver = LcpMethod::Lemke;
  return o;
}

// Cart (M) pulled by F on frictionless rails, block (m) on its top with friction μ: sticking iff
// F ≤ μ g (M + m), both at F/(M + m); above, the block at μ g and the cart at (F − μ m g)/M.
TEST(StepperTwoBodies, BlockOnACartSticksBelowMuAndSlidesAbove) {
  const double M = 4, m = 1, mu = 0.4, dt = 1e-3, T = 0.5;
  for (const double F : {0.5 * mu * kGravity * (M + m), 30.0}) {
    SCOPED_TRACE("F = " + std::to_string(F));
    TimeStepper sim(scene::loadScene("block_on_cart", {{"force", F}}), twoBodyOptions(dt));
    double largest_pn_error = 0;
    while (sim.time() < T - 1e-12) {
      sim.step();
      largest_pn_error = std::max(largest_pn_error, std::abs(sim.contacts()[0].pn - m * kGravity * dt));
    }
    const bool sticks = F <= mu * kGravity * (M + m);
    const double a_cart = sticks ? F / (M + m) : (F - mu * m * kGravity) / M, a_block = sticks ? a_cart : mu * kGravity;
    // constant accelerations: the trapezoidal position update is exact up to round-off
    EXPECT_NEAR(sim.q()[0], 0.5 * a_cart * T * T, 1e-9);  // cart_x
    EXPECT_NEAR(sim.q()[1], 0.5 * a_block * T * T, 1e-9);  // block_x
    EXPECT_NEAR(sim.v()[0], a_cart * T, 1e-9);
    EXPECT_NEAR(sim.v()[1], a_block * T, 1e-9);
    EXPECT_NEAR(sim.q()[2], 0.0, 1e-9);  // block_z: on the deck, neither sinking nor lifting
    EXPECT_LT(largest_pn_error, 1e-9);   // the deck carries the block's weight, m g per step
    EXPECT_NEAR(sim.contacts()[0].vt1, (a_block - a_cart) * T, 1e-9);  // the block's slip on the deck
  }
}

// Sliding, the block falls behind and passes the rear end of the deck (half-length 0.5 m) when
// ½ (a_cart − a_block) t² = 0.5; beyond it the plane's extent ends: the block falls freely.
TEST(StepperTwoBodies, BlockLeavesTheDeckAtItsEndAndFalls) {
  const double M = 4, m = 1, mu = 0.4, F = 30, deck = 0.5, dt = 1e-4;
  const double a_rel = (F - mu * m * kGravity) / M - mu * kGravity, t_off = std::sqrt(2 * deck / a_rel);
  TimeStepper sim(scene::loadScene("block_on_cart"), twoBodyOptions(dt));
  double t_left = -1, s_left = 0, largest_s_error = 0;
  while (sim.time() < 1.0 - 1e-12) {
    sim.step();
    // The report's plane coordinates: the block's place on the deck (the cart's origin, t1 = x).
    largest_s_error = std::max({largest_s_error, std::abs(sim.contacts()[0].s1 - (sim.q()[1] - sim.q()[0])),
                                std::abs(sim.contacts()[0].s2)});
    if (t_left < 0 && !sim.contacts()[0].over_plane) t_left = sim.time(), s_left = sim.contacts()[0].s1;
  }
  ASSERT_GT(t_left, 0) << "the block never left the deck";
  EXPECT_NEAR(t_left, t_off, 2 * dt);
  EXPECT_LT(largest_s_error, 1e-12);
  EXPECT_LT(s_left, -deck);  // beyond the rear end: touches nothing
  EXPECT_GT(s_left, -deck - 2 * a_rel * t_off * dt);
  const double fall = 1.0 - t_off;
  EXPECT_NEAR(sim.q()[2], -0.5 * kGravity * fall * fall, 2 * kGravity * dt);  // free fall from the deck's height
  EXPECT_NEAR(sim.v()[1], mu * kGravity * t_off, 2 * mu * kGravity * dt);     // no more friction: x velocity kept
  EXPECT_NEAR(sim.v()[0], F / M * fall + (F - mu * m * kGravity) / M * t_off, 2 * F / M * dt);  // cart alone
  EXPECT_LT(sim.stats().max_penetration, 1e-9);  // below the deck's plane, but beyond its end
}

// The deck is a plate, not a half-space: the block that fell past the deck's rear end is under it
// when the cart is pushed back beneath it, and keeps falling freely (before, it was met with the
// whole depth below the deck's level as a penetration and thrown up onto the deck).
TEST(StepperTwoBodies, ABlockThatFellBelowTheDeckStaysUnderItWhenTheDeckComesBack) {
  const double F = 30, deck = 0.5, dt = 1e-4;
  TimeStepper sim(scene::loadScene("block_on_cart", {{"force", F}}), twoBodyOptions(dt));
  double t_left = -1, z_left = 0, vz_left = 0, vx_left = 0, x_left = 0;
  bool back_under = false;
  double largest_fall_error = 0, largest_impulse = 0;
  int steps_over_the_deck = 0;
  while (sim.time() < 1.2 - 1e-12) {
    sim.step();
    const auto& block = sim.contacts()[0];
    if (t_left < 0) {
      if (!block.over_plane) t_left = sim.time(), x_left = sim.q()[1], z_left = sim.q()[2], vx_left = sim.v()[1], vz_left = sim.v()[2];
      continue;
    }
    const double t = sim.time() - t_left;
    // 0.1 s after it left, the cart is pushed back hard: its deck runs back beneath the block.
    if (t > 0.1) sim.setInput(Eigen::Vector3d(-20 * F, 0, 0));
    largest_impulse = std::max(largest_impulse, std::abs(block.pn));
    largest_fall_error = std::max({largest_fall_error, std::abs(sim.q()[2] - (z_left + vz_left * t - 0.5 * kGravity * t * t)),
                                   std::abs(sim.q()[1] - (x_left + vx_left * t))});
    const double s = sim.q()[1] - sim.q()[0];
    if (std::abs(s) < deck - 0.1 && sim.q()[2] < -0.05) back_under = true;
    steps_over_the_deck += block.over_plane;
  }
  ASSERT_GT(t_left, 0) << "the block never left the deck";
  EXPECT_TRUE(back_under) << "the deck never came back above the block";
  EXPECT_EQ(steps_over_the_deck, 0);
  EXPECT_EQ(largest_impulse, 0);
  EXPECT_LT(largest_fall_error, 1e-9);
  EXPECT_LT(sim.stats().max_penetration, 1e-9);
}

// A block dropped onto a slab resting on the ground: the slab stays, the block leaves at e v, and
// the ground takes (1 + e) m v through the slab.
TEST(StepperTwoBodies, BlockReboundsFromASlabThatPassesTheImpulseToTheGround) {
  const double M = 2, m = 1, h = 0.5, e = 0.5, dt = 1e-4;
  const double v = std::sqrt(2 * kGravity * h), t_hit = std::sqrt(2 * h / kGravity);
  TimeStepper sim(scene::loadScene("block_on_slab"), twoBodyOptions(dt));
  double p_ground = 0, p_block = 0, apex = 0, largest_slab_z = 0;
  bool rebounded = false;
  while (sim.time() < t_hit + 0.9 * e * v / kGravity * 2) {
    const double v_before = sim.v()[1];
    sim.step();
    largest_slab_z = std::max(largest_slab_z, std::abs(sim.q()[0]));
    if (!rebounded && v_before < 0 && sim.v()[1] > 0) {  // the impact step
      rebounded = true;
      p_ground = sim.contacts()[0].pn;
      p_block = sim.contacts()[1].pn;
      EXPECT_NEAR(sim.v()[1], e * v, 2 * kGravity * dt);
      EXPECT_NEAR(sim.time(), t_hit, 2 * dt);
    }
    if (rebounded) apex = std::max(apex, sim.q()[1] - 0.1);  // above the slab's top
  }
  ASSERT_TRUE(rebounded);
  EXPECT_LT(largest_slab_z, 1e-9);                          // the slab never moves
  EXPECT_NEAR(p_block, (1 + e) * m * v, 3 * m * kGravity * dt);     // Newton: the block's change of momentum
  EXPECT_NEAR(p_ground, p_block + M * kGravity * dt, 1e-9);         // passed on, with the slab's weight
  EXPECT_NEAR(apex, e * e * h, 2e-3 * h);
}

// A block hitting a free slab with gravity off: momentum is conserved at every step and the
// relative normal velocity reverses times e.
TEST(StepperTwoBodies, FreeSlabCollisionConservesMomentum) {
  const double M = 2, m = 1, e = 0.5, v_b = -2.0, dt = 1e-4;
  TimeStepper sim(scene::loadScene("block_on_slab", {{"g", 0.0}, {"slab_height", 0.2}, {"block_speed", 2.0},
                                                    {"height", 0.1}}),
                  twoBodyOptions(dt));
  const double p0 = m * v_b;
  double largest_drift = 0;
  while (sim.time() < 0.2) {
    sim.step();
    largest_drift = std::max(largest_drift, std::abs(M * sim.v()[0] + m * sim.v()[1] - p0));
  }
  EXPECT_LT(largest_drift, 1e-12);
  EXPECT_NEAR(sim.v()[1], (m * v_b - M * e * v_b) / (m + M), 1e-9);  // block
  EXPECT_NEAR(sim.v()[0], (m * v_b + m * e * v_b) / (m + M), 1e-9);  // slab
  EXPECT_GT(sim.q()[1] - sim.q()[0] - 0.1, 0.0);                      // apart again
}

}  // namespace
}  // namespace saltus::timestepper
