// Seeds from the time-stepper (collocation/simulation_seed.hpp): the drop's landing placed on an
// element boundary at the analytic time with the analytic velocity jump and impulse, free flight
// exact before it and the static reaction after it; the belt's step of the pendulum found as an
// impact without collision at its mesh point; the first-order layout filled; and the seeds solve.
#include "collocation/simulation_seed.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "collocation/input_schedule.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/solver.hpp"
#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace {

constexpr double kGravity = 9.81;

TEST(SimulationSeed, DropLandsOnAnElementBoundaryWithTheAnalyticJump) {
  for (const double e : {0.0, 0.5}) {
    const double height = 0.1;
    const Problem p = testing::pointMassDrop(e, height);
    const Transcription t(p, Method::Impulsive);
    SimulationSeedReport report;
    const Eigen::VectorXd x = seedFromSimulation(t, &report);
    const double t_land = std::sqrt(2 * height / kGravity), v_land = kGravity * t_land;
    ASSERT_GE(report.events.size(), 1u) << "e = " << e;
    EXPECT_NEAR(report.events[0], t_land, 1.5 * report.dt);
    // The boundary at the landing: Δv = (1 + e) v, impulse m (1 + e) v (m = 1 kg), element
    // lengths within their bounds, the boundary at the impact time.
    int landing = -1;
    double time = 0;
    for (int n = 0; n < t.elements(); ++n) {
      const double h = x[t.layout()[n].h];
      EXPECT_GE(h, t.variableLower()[t.layout()[n].h] - 1e-12);
      EXPECT_LE(h, t.variableUpper()[t.layout()[n].h] + 1e-12);
      if (landing < 0 && std::abs(time - report.events[0]) < 1e-9) landing = n;
      time += h;
    }
    ASSERT_GT(landing, 0) << "no boundary at the impact";
    const auto& L = t.layout()[landing];
    EXPECT_NEAR(x[L.points[0].accel_or_jump], (1 + e) * v_land, 0.02 * v_land) << "e = " << e;
    EXPECT_NEAR(x[L.contacts[0].rn[0]], (1 + e) * v_land, 0.02 * v_land);
    const auto& before = t.layout()[landing - 1];
    EXPECT_NEAR(x[before.points[before.end].v], -v_land, 0.01 * v_land);
    // Free flight before the landing: θ = ½ integrates it exactly.
    double t0 = 0;
    for (int n = 0; n < landing; ++n) {
      const auto& E = t.layout()[n];
      for (std::size_t q = 0; q < E.points.size(); ++q) {
        const double tq = t0 + x[E.h] * E.tau[q];
        // (the landing's time is estimated from the gap and speed at its step's start: 1e-7 m)
        const double z = height - 0.5 * kGravity * tq * tq;
        EXPECT_NEAR(x[E.points[q].q], z, 1e-7) << "[" << n << "," << q << "]";
        EXPECT_NEAR(x[E.points[q].v], -kGravity * tq, 1e-6);
        EXPECT_NEAR(x[E.contacts[0].y[q]], std::max(0.0, z), 1e-7);
      }
      t0 += x[E.h];
    }
    if (e == 0) {  // resting after the landing: the reaction holds the weight
      const auto& R = t.layout()[landing + 1];
      for (int c : R.collocation) {
        EXPECT_NEAR(x[R.contacts[0].rn[c]], kGravity, 1e-6);
        EXPECT_NEAR(x[R.points[c].q], 0, 1e-9);
      }
    }
  }
}

TEST(SimulationSeed, BeltStepIsAnImpactWithoutCollisionAtItsMeshPoint) {
  const Problem p = testing::pendulumConveyor(2.0, 0.5);
  const Transcription t(p, Method::Impulsive);
  SimulationSeedReport report;
  const Eigen::VectorXd x = seedFromSimulation(t, &report);
  ASSERT_EQ(report.events.size(), 1u);
  EXPECT_NEAR(report.events[0], report.mesh_times[5], 1e-12);  // the belt steps at [6, 0]
  const auto& L = t.layout()[5];
  EXPECT_GT(x[L.contacts[0].rn[0]], 0.1);  // the tangential impulse comes with a normal one
  EXPECT_GT(x.segment(L.points[0].accel_or_jump, 2).norm(), 0.5);  // Δq̇ of the joints
  // Before the step the tip rests on the belt: no jump, reactions at the collocation points.
  const auto& R = t.layout()[2];
  for (int c : R.collocation) EXPECT_GT(x[R.contacts[0].rn[c]], 1.0);
  EXPECT_NEAR(x[t.layout()[3].points[0].accel_or_jump], 0, 1e-12);
}

TEST(SimulationSeed, FillsTheFirstOrderSteps) {
  const Problem p = testing::pointMassDrop(0.0);
  const Transcription t(p, Method::FirstOrder);
  SimulationSeedReport report;
  const Eigen::VectorXd x = seedFromSimulation(t, &report);
  EXPECT_EQ(static_cast<int>(report.mesh_times.size()), p.N + 1);
  double time = 0, total = 0;
  for (const auto& L : t.layout()) total += x[L.h];
  EXPECT_NEAR(total, report.mesh_times.back(), 1e-12);
  for (const auto& L : t.layout()) {
    time += x[L.h];
    if (time < report.events.at(0) - 1e-9) {
      EXPECT_NEAR(x[L.points[1].q], 0.1 - 0.5 * kGravity * time * time, 1e-9);
    }
  }
}

TEST(SimulationSeed, SeedsOfTheDropSolveWithoutRestarts) {
  for (const double e : {0.0, 0.5}) {
    const Problem p = testing::pointMassDrop(e);
    const Transcription t(p, Method::Impulsive);
    SolveOptions o;
    o.warm_seed = true;  // as saltus optimize --seed-kind simulation: the seed is near a solution
    const SolveReport r = solve(t, seedFromSimulation(t), o);
    EXPECT_TRUE(r.feasible) << "e = " << e << ": " << r.stages.back().status << ", largest product " << r.largest_product;
  }
}

}  // namespace
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace {

// A hint that puts the mass on the ground at [9, 0]: reachable from 0.1 m (the landing at
// 0.143 s lies in the 0.016–0.16 s that [9, 0] can take), not from 0.15 m (0.175 s).
TEST(SimulationSeed, HintsAreCheckedAgainstTheUnactuatedMotion) {
  for (const double height : {0.1, 0.15}) {
    Problem p = testing::pointMassDrop(0.0, height);
    p.hints.push_back({{Quantity::Kind::Gap, 0}, 8, 0, 0.0, 0.0, "test.yaml:3:5"});
    const Transcription t(p, Method::Impulsive);
    const std::vector<HintReach> r = checkHints(t);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].origin, "test.yaml:3:5");
    EXPECT_EQ(r[0].contact, "ball");
    EXPECT_NEAR(r[0].earliest, 8 * 0.1 * 0.02, 1e-12);
    EXPECT_NEAR(r[0].latest, 8 * 0.02, 1e-12);
    EXPECT_NEAR(r[0].closes, std::sqrt(2 * height / kGravity), 1e-3);
    EXPECT_EQ(r[0].reachable, height == 0.1) << "height " << height;
    EXPECT_FALSE(r[0].actuated);
  }
  // With inputs the unactuated motion is one of many: the Ollie's tail hint at [10, 0], which the
  // board standing on its wheels never meets, is reported as one for the inputs to bring about.
  {
    const Problem ollie = loadProblem("ollie_simple");
    const std::vector<HintReach> r = checkHints(Transcription(ollie, Method::Impulsive));
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].contact, "tail");
    EXPECT_LT(r[0].closes, 0.0);
    EXPECT_FALSE(r[0].reachable);
    EXPECT_TRUE(r[0].actuated);
  }
  // A gap bound on every element is a condition, not a contact event: not checked.
  Problem p = testing::pointMassDrop(0.0, 0.1);
  p.hints.push_back({{Quantity::Kind::Gap, 0}, -1, 0, 0.0, 0.0, "test.yaml:4:5"});
  EXPECT_TRUE(checkHints(Transcription(p, Method::Impulsive)).empty());
}

}  // namespace
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace scheduled_seed_test {

// The drop of Fig. 3 with its vertical force as an input (within ±30 N), pushed up by a schedule:
// 2 m g (a net g upwards) until t_push, then nothing, to the horizon.
struct PushedDrop {
  Problem problem;
  InputSchedule schedule;
};
PushedDrop pushedDrop(double height, double t_push, double horizon) {
  PushedDrop d{testing::pointMassDrop(0.0, height), {}};
  d.problem.h_max = 0.05;
  d.problem.inputs = {0};
  d.problem.input_lower = Eigen::VectorXd::Constant(1, -30);
  d.problem.input_upper = Eigen::VectorXd::Constant(1, 30);
  d.schedule.times = {0, t_push, horizon};
  d.schedule.values = {Eigen::VectorXd::Constant(1, 2 * kGravity), Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1)};
  return d;
}

// The drop of Fig. 3 pushed up by an input schedule: 2 m g for 0.09 s (a net g upwards), then
// nothing, over a horizon of 0.6 s. The seed follows the exact motion (θ = ½ integrates constant
// forces exactly, the change lies on a step's end), lands at the analytic time, carries the
// schedule's inputs at its points, and its elements start at the horizon over N.
TEST(SimulationSeed, AnInputScheduleDrivesTheSimulation) {
  const double g = 9.81, height = 0.1, t_push = 0.09, horizon = 0.6;
  const PushedDrop drop = pushedDrop(height, t_push, horizon);
  const Problem& p = drop.problem;
  const InputSchedule& schedule = drop.schedule;
  const Transcription t(p, Method::Impulsive);
  SimulationSeedReport report;
  const Eigen::VectorXd x = seedFromSimulation(t, &report, &schedule);
  const double z1 = height + 0.5 * g * t_push * t_push, v1 = g * t_push;
  auto z = [&](double time) {
    if (time <= t_push) return height + 0.5 * g * time * time;
    const double s = time - t_push;
    return z1 + v1 * s - 0.5 * g * s * s;
  };
  const double t_land = t_push + (v1 + std::sqrt(v1 * v1 + 2 * g * z1)) / g;
  EXPECT_NEAR(report.dt, horizon / p.N / 40, 1e-15);
  ASSERT_GE(report.events.size(), 1u);
  EXPECT_NEAR(report.events[0], t_land, 1.5 * report.dt);
  EXPECT_NEAR(report.mesh_times.back(), horizon, 0.5 * horizon / p.N + 1e-12);
  double t0 = 0;
  int checked = 0;
  for (int n = 0; n < t.elements() && t0 + 1e-9 < report.events[0]; ++n) {
    const auto& E = t.layout()[n];
    for (std::size_t q = 0; q < E.points.size(); ++q) {
      const double tq = t0 + x[E.h] * E.tau[q];
      EXPECT_NEAR(x[E.points[q].q], z(tq), 1e-7) << "[" << n << "," << q << "]";
      if (E.points[q].u >= 0) {
        EXPECT_DOUBLE_EQ(x[E.points[q].u], tq < t_push ? 2 * g : 0.0) << "[" << n << "," << q << "]";
        ++checked;
      }
    }
    t0 += x[E.h];
  }
  EXPECT_GT(checked, 20);
  // Without the schedule the same problem drops from rest, as before.
  SimulationSeedReport unactuated;
  seedFromSimulation(t, &unactuated);
  ASSERT_GE(unactuated.events.size(), 1u);
  EXPECT_NEAR(unactuated.events[0], std::sqrt(2 * height / g), 1.5 * unactuated.dt);
}

}  // namespace scheduled_seed_test
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace longest_elements_test {

// Elements starting at their longest (h0 = h_max: a total time of at least N h_max): the landing
// at 0.1428 s lies just after its nearest boundary, 7 × 0.02 s, which no element can stretch to;
// it takes the next boundary, [8, 0], the eight elements before it shorter.
TEST(SimulationSeed, AnEventBeyondItsNearestBoundaryTakesTheNext) {
  Problem p = testing::pointMassDrop(0.0, 0.1);
  p.total_time = p.N * p.h_max;
  const Transcription t(p, Method::Impulsive);
  SimulationSeedReport report;
  const Eigen::VectorXd x = seedFromSimulation(t, &report);
  const double t_land = std::sqrt(2 * 0.1 / 9.81);
  ASSERT_EQ(report.events.size(), 1u);
  EXPECT_NEAR(report.events[0], t_land, 1.5 * report.dt);
  EXPECT_NEAR(report.mesh_times[8], report.events[0], 1e-12);
  for (int n = 0; n < 8; ++n) EXPECT_NEAR(x[t.layout()[n].h], report.events[0] / 8, 1e-12);
  for (int n = 8; n < p.N; ++n) EXPECT_NEAR(x[t.layout()[n].h], p.h_max, 1e-12);
}

}  // namespace longest_elements_test
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace ollie_schedule_test {

// The Ollie's searched schedule (models/problems/ollie_simple_schedule.csv, from a search as
// examples/python/ollie_seed_search.py's) within the riders' bounds, and its seed an Ollie before
// any solve: both wheels above the air goal at [20, 0], no foot through the deck, and the board
// back on its wheels at the end.
TEST(SimulationSeed, TheOllieScheduleSeedsAnOllie) {
  const Problem p = loadProblem("ollie_simple");
  const InputSchedule schedule = readInputSchedule(problemsDirectory() + "/ollie_simple_schedule.csv", p);
  EXPECT_NEAR(schedule.horizon(), p.N * p.h_max, 1e-12);
  const Transcription t(p, Method::Impulsive);
  SimulationSeedReport report;
  const Eigen::VectorXd x = seedFromSimulation(t, &report, &schedule);
  std::map<std::string, int> contact;
  for (std::size_t c = 0; c < t.contacts().size(); ++c) contact[t.contacts()[c].name] = static_cast<int>(c);
  const double goal = p.parameters.at("clearance_goal");
  const ElementLayout& air = t.layout()[20];
  EXPECT_GE(x[air.contacts[contact.at("rear_wheel")].y[0]], goal);
  EXPECT_GE(x[air.contacts[contact.at("front_wheel")].y[0]], goal);
  for (const ElementLayout& L : t.layout())
    for (std::size_t q = 0; q < L.points.size(); ++q)
      for (const char* foot : {"back_foot", "front_foot"}) EXPECT_GE(x[L.contacts[contact.at(foot)].y[q]], -2e-3);
  const ElementLayout& end = t.layout().back();
  for (const char* wheel : {"rear_wheel", "front_wheel"}) EXPECT_LT(x[end.contacts[contact.at(wheel)].y[end.end]], 0.01);
}

}  // namespace ollie_schedule_test
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace scheduled_seed_test {

// Re-simulation (seedFromResimulation): the drop pushed up by a schedule, its seed's inputs made
// a schedule again (scheduleFromInputs) and simulated anew. The schedule holds each collocation
// point's input over its own stretch, within the bounds, to the seed's total time; the push now
// ends where the hold switches, within an element of where it ended, and the new seed lands at
// the analytic time of that push.
TEST(SimulationSeed, AResimulationReplaysThePointsInputs) {
  const double g = 9.81, height = 0.1, t_push = 0.09, horizon = 0.6;
  const PushedDrop drop = pushedDrop(height, t_push, horizon);
  const Problem& p = drop.problem;
  const InputSchedule& schedule = drop.schedule;
  const Transcription t(p, Method::Impulsive);
  Eigen::VectorXd x = seedFromSimulation(t, nullptr, &schedule);
  // An input beyond its bound (as Ipopt's relaxed bounds allow) is held at the bound.
  const ElementLayout& last = t.layout().back();
  x[last.points[last.collocation.back()].u] = 30 + 1e-8;

  const InputSchedule held = scheduleFromInputs(t, x);
  double total = 0;
  for (const ElementLayout& L : t.layout()) total += x[L.h];
  EXPECT_NEAR(held.horizon(), total, 1e-12);
  EXPECT_EQ(held.times.front(), 0.0);
  double t0 = 0;
  for (const ElementLayout& L : t.layout()) {
    for (int c : L.collocation)
      EXPECT_DOUBLE_EQ(held.at(t0 + L.tau[c] * x[L.h])[0], std::min(30.0, x[L.points[c].u]));
    t0 += x[L.h];
  }
  EXPECT_EQ(held.values.back()[0], 30.0);
  // Where the push ends in the held schedule: within an element of t_push.
  double t_switch = -1;
  for (std::size_t i = 1; i < held.times.size() && t_switch < 0; ++i)
    if (held.values[i][0] == 0 && held.values[i - 1][0] == 2 * g) t_switch = held.times[i];
  ASSERT_GT(t_switch, 0);
  EXPECT_LT(std::abs(t_switch - t_push), p.h_max);

  SimulationSeedReport report;
  const Eigen::VectorXd again = seedFromResimulation(t, x, &report);
  const double z1 = height + 0.5 * g * t_switch * t_switch, v1 = g * t_switch;
  const double t_land = t_switch + (v1 + std::sqrt(v1 * v1 + 2 * g * z1)) / g;
  ASSERT_GE(report.events.size(), 1u);
  EXPECT_NEAR(report.events[0], t_land, 1.5 * report.dt);
  EXPECT_NEAR(report.mesh_times.back(), total, p.h_max);  // the mesh placed on the landing moves the end
  // Its points carry the held inputs.
  t0 = 0;
  for (const ElementLayout& L : t.layout()) {
    for (int c : L.collocation) EXPECT_DOUBLE_EQ(again[L.points[c].u], held.at(t0 + L.tau[c] * again[L.h])[0]);
    t0 += again[L.h];
  }
}

// A problem without inputs has no schedule to replay.
TEST(SimulationSeed, AResimulationNeedsInputs) {
  const Problem p = testing::pointMassDrop(0.0, 0.1);
  const Transcription t(p, Method::Impulsive);
  EXPECT_THROW(scheduleFromInputs(t, seedFromSimulation(t)), std::invalid_argument);
}

// A tracked re-simulation (trackingFromPoint): a point that holds the mass still at 0.1 m with
// no input, which open loop is a fall to the ground. Its input tracks the point's height, a
// critically damped oscillator of natural frequency ω on the mass: from rest under gravity the
// error is e(t) = −(g/ω²)(1 − (1 + ωt) e^{−ωt}) (settling at −g/ω², no landing), and the seed
// carries the input applied, u = −k_p e − k_d ė = m g (1 − (1 − ωt) e^{−ωt}).
TEST(SimulationSeed, ATrackedResimulationHoldsThePointsMotionAgainstGravity) {
  const double g = 9.81, height = 0.1, omega = 20;
  const PushedDrop drop = pushedDrop(height, 0.09, 0.6);
  const Problem& p = drop.problem;
  const Transcription t(p, Method::Impulsive);
  Eigen::VectorXd x = seedFromSimulation(t);
  for (const ElementLayout& L : t.layout())
    for (const auto& pt : L.points) {
      x[pt.q] = height;
      x[pt.v] = 0;
      if (pt.accel_or_jump >= 0) x[pt.accel_or_jump] = 0;
      if (pt.u >= 0) x[pt.u] = 0;
    }

  const Tracking tracking = trackingFromPoint(t, x, omega);
  EXPECT_DOUBLE_EQ(tracking.kp[0], omega * omega);  // the mass is 1 kg
  EXPECT_DOUBLE_EQ(tracking.kd[0], 2 * omega);
  Eigen::VectorXd q_ref, v_ref;
  tracking.reference(0.3, q_ref, v_ref);
  EXPECT_DOUBLE_EQ(q_ref[0], height);
  EXPECT_DOUBLE_EQ(v_ref[0], 0.0);

  SimulationSeedReport open_loop, tracked;
  seedFromResimulation(t, x, &open_loop);
  EXPECT_FALSE(open_loop.events.empty());  // it lands
  const Eigen::VectorXd seed = seedFromResimulation(t, x, &tracked, omega);
  EXPECT_TRUE(tracked.events.empty());
  double t0 = 0, largest = 0;
  int checked = 0;
  for (const ElementLayout& L : t.layout()) {
    for (int c : L.collocation) {
      const double time = t0 + L.tau[c] * seed[L.h];
      const double decay = std::exp(-omega * time);
      const double e = -g / (omega * omega) * (1 - (1 + omega * time) * decay);
      // the feedback acts on the state at each step's start: a lag of the order of ω dt
      EXPECT_NEAR(seed[L.points[c].q], height + e, omega * tracked.dt * g / (omega * omega)) << "t = " << time;
      // the input applied over the step that contains the point: within a step's change of it
      EXPECT_NEAR(seed[L.points[c].u], g * (1 - (1 - omega * time) * decay), 2 * g * omega * tracked.dt) << "t = " << time;
      largest = std::max(largest, seed[L.points[c].u]);
      ++checked;
    }
    t0 += seed[L.h];
  }
  EXPECT_EQ(checked, p.N * p.P);
  EXPECT_GT(largest, g);  // the overshoot of the critically damped input, 1 + e^{−2} at ωt = 2
}

// Tracking needs a problem with inputs and a positive frequency.
TEST(SimulationSeed, TrackingNeedsInputsAndAPositiveFrequency) {
  const PushedDrop drop = pushedDrop(0.1, 0.09, 0.6);
  const Transcription t(drop.problem, Method::Impulsive);
  const Eigen::VectorXd x = seedFromSimulation(t);
  EXPECT_THROW(trackingFromPoint(t, x, 0), std::invalid_argument);
  EXPECT_THROW(trackingFromPoint(t, x, -1), std::invalid_argument);
  const Problem bare = testing::pointMassDrop(0.0, 0.1);
  const Transcription u(bare, Method::Impulsive);
  EXPECT_THROW(trackingFromPoint(u, seedFromSimulation(u), 30), std::invalid_argument);
}

}  // namespace scheduled_seed_test
}  // namespace saltus::collocation
