// The saved solutions of the benchmarks (tests/data/solutions/; each folder's README says how it
// was made), checked as a user would check them: every condition recomputed from the state, not
// read from the solver's constraint values — no penetration (the gap from the kinematics), each
// reaction inside its friction cone, the joint stops and the torque limits respected, every task
// condition of the problem file met, every velocity jump removing kinetic energy and leaving its
// contacts closed. The legged solutions' further checks are in legged_solution_test.cpp, the
// Ollie's in ollie_solution_test.cpp.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "collocation/solution.hpp"
#include "contact/kinematics.hpp"
#include "dynamics/energy.hpp"
#include "tests/saltus/saved_solution_fixture.hpp"

namespace {

using namespace saltus;
using namespace saltus::saved_solutions;
using collocation::Quantity;


TEST_P(SavedSolutionTest, NoPenetrationReactionsInTheirConesStopsAndTorqueLimitsHold) {
  const collocation::Transcription& t = transcription();
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  const std::vector<collocation::Sample> samples = collocation::trajectory(t, solution_->x);
  ASSERT_GT(samples.size(), 100u);
  const int nu = static_cast<int>(problem().inputs.size());
  double worst_gap = 0, worst_cone = 0;
  for (const collocation::Sample& s : samples) {
    dynamics::forwardKinematics(model, data, s.q);
    for (std::size_t c = 0; c < t.contacts().size(); ++c) {
      const auto& cp = t.contacts()[c];
      const double phi = contact::gap(cp, data, s.q.data());  // a stop: sign · (q_i − limit)
      worst_gap = std::min(worst_gap, phi);
      EXPECT_GE(phi, -kTol) << (cp.isStop() ? "joint stop " : "contact ") << c << " at t = " << s.t;
      const collocation::ContactSample& r = s.contacts[c];
      EXPECT_GE(r.rn, -kTol);
      EXPECT_GE(r.pn, -kTol);
      if (cp.isStop()) continue;
      // A polyhedral cone's force is inside the circular one: ‖f_t‖ ≤ μ f_n.
      const double cone = std::max(r.rt.norm() - cp.friction * r.rn, r.pt.norm() - cp.friction * r.pn);
      worst_cone = std::max(worst_cone, cone);
      EXPECT_LE(r.rt.norm(), cp.friction * r.rn * (1 + 1e-6) + kTol) << "contact " << c << " at t = " << s.t;
      EXPECT_LE(r.pt.norm(), cp.friction * r.pn * (1 + 1e-6) + kTol) << "contact " << c << " at t = " << s.t;
    }
    // Torque limits at the collocation points, where the inputs are the solver's variables.
    if (s.point >= 1 && s.point <= problem().P)
      for (int i = 0; i < nu; ++i) {
        EXPECT_GE(s.u[i], problem().input_lower[i] - kTol) << "input " << i << " at t = " << s.t;
        EXPECT_LE(s.u[i], problem().input_upper[i] + kTol) << "input " << i << " at t = " << s.t;
      }
  }
  std::cout << GetParam() << ": " << samples.size() << " samples, deepest gap " << worst_gap
            << ", largest excess over the cone " << worst_cone << "\n";
}

TEST_P(SavedSolutionTest, EveryConditionOfTheProblemFileHolds) {
  const collocation::Transcription& t = transcription();
  const std::vector<collocation::Sample> samples = collocation::trajectory(t, solution_->x);
  const int P = problem().P;
  int checked = 0;
  for (const collocation::PointBound& b : problem().bounds) {
    for (const collocation::Sample& s : samples) {
      // The sample's place in the problem's mesh: [n, 0] after an impulse, [n, P + 1] before
      // the next one (the previous element's end).
      if (b.element >= 0 && s.element != b.element) continue;
      if (b.point >= 0 && s.point != b.point) continue;
      double value = 0;
      switch (b.quantity.kind) {
        case Quantity::Kind::Position: value = s.q[b.quantity.index]; break;
        case Quantity::Kind::Velocity: value = s.v[b.quantity.index]; break;
        case Quantity::Kind::Input:
          if (s.point < 1 || s.point > P) continue;  // inputs are variables at collocation points
          value = s.u[b.quantity.index];
          break;
        case Quantity::Kind::Gap: value = s.contacts[b.quantity.index].gap; break;
      }
      const double scale = std::max(1.0, std::abs(value));
      EXPECT_GE(value, b.lower - kTol * scale) << b.origin << " at [" << s.element + 1 << ", " << s.point << "]";
      EXPECT_LE(value, b.upper + kTol * scale) << b.origin << " at [" << s.element + 1 << ", " << s.point << "]";
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
  // The initial state: imposed at [1, 0].
  const collocation::Sample& first = samples.front();
  EXPECT_LT((first.q - problem().scene.q0).cwiseAbs().maxCoeff(), kTol);
  EXPECT_LT((first.v - problem().scene.v0).cwiseAbs().maxCoeff(), kTol);
}

// Every velocity jump is an inelastic or partly elastic impact, which cannot add kinetic energy
// (with one contact of e ≤ 1 or only frictionless plastic ones it removes it; the impulses
// without collision at closed contacts do no work). And each impulse leaves its contact closed and
// not approaching: the gap and the normal velocity after the jump, from the kinematics, 0 (at
// least 0 where the contact restitutes, e > 0), to the relaxed complementarity's scale. The energy
// is ½ Σ vᵢᵀ Iᵢ vᵢ over the bodies (RBDA 2.67), from the state on each side of the jump.
TEST_P(SavedSolutionTest, EveryVelocityJumpDissipatesAndLeavesItsContactsClosed) {
  const collocation::Transcription& t = transcription();
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  const std::vector<collocation::Sample> samples = collocation::trajectory(t, solution_->x);
  const auto energy = [&](const collocation::Sample& s) {
    dynamics::forwardKinematics(model, data, s.q, s.v);
    return dynamics::kineticEnergy(model, data);
  };
  const double tolerance = problem().complementarity_tolerance;
  int jumps = 0, impulses = 0;
  double largest_product = 0, largest_gain = -std::numeric_limits<double>::infinity(), largest_loss = 0, loss_at = 0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const collocation::Sample &before = samples[k - 1], &after = samples[k];
    if (after.point != 0 || after.element == 0) continue;
    ASSERT_EQ(before.t, after.t);  // [n, 0] follows [n − 1, P + 1]: the two sides of the jump
    ++jumps;
    const double e0 = energy(before), e1 = energy(after);
    largest_gain = std::max(largest_gain, e1 - e0);
    if (e0 - e1 > largest_loss) largest_loss = e0 - e1, loss_at = after.t;
    // The relaxed complementarity (products up to 1e-4) leaves impulses of millinewton-seconds at
    // open contacts: 1e-6 of the energy or 1e-4 J.
    EXPECT_LE(e1 - e0, 1e-4 + 1e-6 * e0) << "at t = " << after.t;
    for (std::size_t c = 0; c < t.contacts().size(); ++c) {
      const double pn = after.contacts[c].pn, vn = after.contacts[c].vn;
      if (pn < 1e-2) continue;
      ++impulses;
      // Closed and not approaching, each to the relaxed complementarity's scale: its products
      // with the impulse within the tolerance, as the solver bounds them.
      const double closed = pn * std::abs(after.contacts[c].gap), approaching = pn * std::max(0.0, -vn);
      const double leaving = t.contacts()[c].restitution == 0 ? pn * std::max(0.0, vn) : 0.0;
      largest_product = std::max({largest_product, closed, approaching, leaving});
      EXPECT_LE(closed, tolerance) << "contact " << c << " at t = " << after.t << ", impulse " << pn;
      EXPECT_LE(approaching, tolerance) << "contact " << c << " at t = " << after.t << ", impulse " << pn;
      EXPECT_LE(leaving, tolerance) << "contact " << c << " at t = " << after.t << ", impulse " << pn;
    }
  }
  EXPECT_GT(jumps, 0);
  std::cout << GetParam() << ": " << jumps << " jumps, " << impulses << " impulses of at least 0.01 N s; largest gain "
            << largest_gain << " J, largest loss " << largest_loss << " J at t = " << loss_at
            << "; largest product of an impulse with its gap or normal velocity " << largest_product << "\n";
}

INSTANTIATE_TEST_SUITE_P(Benchmarks, SavedSolutionTest,
                         ::testing::Values("biped_stop_impulsive", "monopod_turn_impulsive", "ollie_assist_0.5",
                                           "ollie_assist_0.03125", "ollie_impulsive"));

}  // namespace
