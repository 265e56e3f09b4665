// Replaying optimised trajectories (verify/replay.hpp) in the Saltus stepper and in Bullet. Each
// solution is solved once per process (a function-local static; ctest runs one test per process): point_mass_drop with
// e = 0.5 (seed 2, ~0.5 s), pendulum_conveyor (the published problem with P = 3, ~1.5 s) and
// tests/data/problems/push_block.yaml (an actuated point mass, ~0.4 s).
#include "verify/replay.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <unistd.h>

#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/solver.hpp"
#include "saltus/build_paths.hpp"

namespace saltus::verify {
namespace {

using collocation::SavedSolution;

// As `saltus optimize`: the problem's seed (the simulation's, by default), restarts after an
// infeasible end.
SavedSolution solveProblem(const std::string& name, const std::map<std::string, double>& set, unsigned seed, int P = 0) {
  SavedSolution s;
  s.problem = std::make_unique<collocation::Problem>(collocation::loadProblem(name, set));
  s.problem->random_seed = seed;
  if (P > 0) collocation::remesh(*s.problem, s.problem->N, P);
  s.transcription = std::make_unique<collocation::Transcription>(*s.problem, collocation::Method::Impulsive);
  const collocation::Transcription& t = *s.transcription;
  const collocation::Seeding seeding = collocation::makeSeeding(t);
  collocation::SolveOptions so;
  so.restarts = seeding.restarts;
  const collocation::SolveReport r = collocation::solve(t, seeding.seed, so);
  EXPECT_TRUE(r.feasible) << name << ": " << r.stages.back().status;
  s.x = r.x;
  return s;
}

const SavedSolution& dropSolution() {
  static const SavedSolution s = solveProblem("point_mass_drop", {{"restitution", 0.5}}, 2);
  return s;
}
const SavedSolution& conveyorSolution() {
  static const SavedSolution s = solveProblem("pendulum_conveyor", {}, 3, 3);  // P = 3: 180 iterations instead of 280
  return s;
}
const SavedSolution& pushSolution() {
  static const SavedSolution s =
      solveProblem(std::string(SALTUS_SOURCE_DIR) + "/tests/data/problems/push_block.yaml", {}, 1);
  return s;
}

ReplayOptions replayOptions(std::vector<EngineKind> engines, double dt = 1e-4) {
  ReplayOptions o;
  o.engines = std::move(engines);
  o.dt = dt;
  return o;
}

int matchedEvents(const EngineReplay& e) {
  int n = 0;
  for (const EventMatch& m : e.matches) n += m.matched;
  return n;
}

// The bounce of point_mass_drop (h = 0.1 m, e = 0.5): impact at sqrt(2h/g) = 0.1428 s with
// 1.40 m/s, apex e² h = 0.025 m. The stepper resolves the impact up to one step late, so the
// position can differ by up to |Δv| dt = 2.1e-4 m around it and by O(dt) after it: the bound
// 3 |Δv| dt. The deviation is first order in dt (ten times smaller at dt 1e-5), and the replayed
// apex matches the optimised one and the analytic value.
TEST(Replay, PointMassDropBounceInTheSaltusStepper) {
  const SavedSolution& s = dropSolution();
  const double g = 9.81, h = 0.1, e = 0.5;
  const ReplayResult r = replay(s, replayOptions({EngineKind::Saltus}, 1e-4));
  ASSERT_EQ(r.engines.size(), 1u);
  const EngineReplay& E = r.engines[0];
  ASSERT_TRUE(E.completed) << E.message;
  EXPECT_EQ(r.tolerance, 1e-3);  // 10 m/s × dt
  EXPECT_TRUE(E.within_tolerance);
  EXPECT_GT(E.max_position_deviation, 0.0);
  EXPECT_LE(E.rms_position_deviation, E.max_position_deviation);
  EXPECT_LE(E.final_position_deviation, E.max_position_deviation);
  EXPECT_EQ(E.max_penetration, 0.0);  // the stepper projects penetrations out
  ASSERT_GT(r.end_time, 0.214);        // the horizon holds the apex, (1 + e) sqrt(2h/g)
  double apex_opt = 0, apex_replay = 0;
  for (std::size_t k = 0; k < r.t.size(); ++k)
    if (r.t[k] > 0.15) {
      apex_opt = std::max(apex_opt, r.q_opt[k][0]);
      apex_replay = std::max(apex_replay, E.series.q[k][0]);
    }
  EXPECT_NEAR(apex_opt, e * e * h, 2e-4);
  EXPECT_NEAR(apex_replay, apex_opt, 1e-4);

  // Events: impact, touchdown and lift-off of the optimisation, each matched within two steps.
  ASSERT_EQ(r.optimised_events.size(), 3u);
  int impacts = 0;
  for (const ContactEvent& ev : r.optimised_events) {
    impacts += ev.kind == ContactEvent::Impact;
    EXPECT_NEAR(ev.t, std::sqrt(2 * h / g), 1e-3);
  }
  EXPECT_EQ(impacts, 1);
  EXPECT_EQ(matchedEvents(E), 3);
  for (const EventMatch& m : E.matches) EXPECT_LE(std::abs(m.dt), 2e-4);
  EXPECT_TRUE(E.unmatched.empty());
  // The energy after the bounce: e² of the drop's, within the discretisation.
  EXPECT_NEAR(E.energy_start, g * h, 1e-12);
  EXPECT_NEAR(E.energy_end, e * e * g * h, 2e-3);

  // The stepper locates the impact within the step and integrates free flight exactly at θ = ½:
  // what remains is the optimisation's own error (complementarity relaxed to 1e-4), far below
  // the first-order O(|Δv| dt) of an impact resolved at a step's end, and it does not grow with dt.
  EXPECT_LT(E.max_position_deviation, 1e-6);
  const ReplayResult coarse = replay(s, replayOptions({EngineKind::Saltus}, 1e-3));
  EXPECT_LT(coarse.engines[0].max_position_deviation, 1e-6);
}

// pendulum_conveyor: the belt steps on the mesh at [6, 0]; the replay must step it at the solved
// time of that mesh point, and the tip then follows the belt (an impact without collision at the
// step, paper IV.A). The stepper resolves the step within one step: deviation ≤ ~1e-5 rad.
TEST(Replay, PendulumConveyorBeltStepsAtTheSolvedMeshTime) {
  const SavedSolution& s = conveyorSolution();
  const collocation::CollocationTrajectory traj = s.trajectory();
  const scene::Scene scene = replayScene(s);
  ASSERT_EQ(scene.surfaces[0].velocity_schedule.size(), 2u);
  EXPECT_EQ(scene.surfaces[0].velocity_schedule[1].time, traj.meshTimes()[5]);
  EXPECT_EQ(scene.surfaces[0].velocity_schedule[1].velocity, Eigen::Vector3d(0.5, 0, 0));
  EXPECT_GT(traj.meshTimes()[5], 0.01);  // not at rest from the start

  const ReplayResult r = replay(s, replayOptions({EngineKind::Saltus}));
  const EngineReplay& E = r.engines[0];
  ASSERT_TRUE(E.completed) << E.message;
  EXPECT_TRUE(E.within_tolerance);
  EXPECT_LT(E.max_position_deviation, 1e-4);
  // The pendulum moved with the belt (θ2 grows), in the optimisation and in the replay.
  EXPECT_GT(r.q_opt.back()[1] - r.q_opt.front()[1], 0.03);
  EXPECT_NEAR(E.series.q.back()[1], r.q_opt.back()[1], 1e-4);
  ASSERT_EQ(r.optimised_events.size(), 1u);
  EXPECT_EQ(r.optimised_events[0].kind, ContactEvent::ImpactWithoutCollision);
  EXPECT_NEAR(r.optimised_events[0].t, traj.meshTimes()[5], 1e-12);
  ASSERT_EQ(matchedEvents(E), 1);
  EXPECT_GE(E.matches[0].dt, 0.0);  // the step's end sees the new belt velocity
  EXPECT_LE(E.matches[0].dt, 1e-4 + 1e-12);

  // Bullet does not produce the tangential impulse (bullet_world_test.cpp: the tip catches up
  // over ~70 ms): it exceeds the tolerance and the impact without collision stays unmatched.
  // (Here rather than in the Bullet test: ctest runs each test in its own process, and this
  // solve is the slow one.)
  const ReplayResult c = replay(s, replayOptions({EngineKind::Bullet}));
  const EngineReplay& C = c.engines[0];
  ASSERT_TRUE(C.completed) << C.message;
  EXPECT_GT(C.max_position_deviation, 5e-3);
  EXPECT_FALSE(C.within_tolerance);
  ASSERT_EQ(C.matches.size(), 1u);
  EXPECT_FALSE(C.matches[0].matched);
}

// Bullet: the replay runs and reports finite deviations, matched events, its approximations and
// no MLCP fallback. On the bounce it is first order like the stepper (the belt: above).
TEST(Replay, BulletReplayReportsDeviationEventsAndApproximations) {
  const ReplayResult r = replay(dropSolution(), replayOptions({EngineKind::Saltus, EngineKind::Bullet}));
  ASSERT_EQ(r.engines.size(), 2u);
  const EngineReplay& B = r.engines[1];
  EXPECT_EQ(B.engine, EngineKind::Bullet);
  ASSERT_TRUE(B.completed) << B.message;
  EXPECT_TRUE(std::isfinite(B.max_position_deviation));
  EXPECT_GT(B.max_position_deviation, 0.0);
  EXPECT_LT(B.max_position_deviation, 1e-3);
  EXPECT_GT(B.rms_position_deviation, 0.0);
  EXPECT_EQ(matchedEvents(B), 3);
  EXPECT_FALSE(B.approximations.empty());
  EXPECT_EQ(B.mlcp_fallbacks, 0);
  EXPECT_GT(B.max_penetration, 0.0);  // erp2 = 0: a contact sits up to |v| dt below the surface
  EXPECT_LT(B.max_penetration, 1.5 * 1.4 * 1e-4);
  EXPECT_EQ(B.series.t.size(), r.t.size());

}

// push_block: an input replayed. The minimum-effort input of a frictionless 1 kg mass moved by
// d = 0.1 m in T = 0.3 s is u(t) = (12 d / T³)(T/2 − t); the midpoint stepper with the mean input
// over each step integrates it exactly up to the solver's tolerances. A wrong input (twice the
// input, or a constant 0.05 N more: 0.5 · 0.05 · T² = 2.3 mm at the end) is caught by the
// tolerance; PD feedback brings the constant offset back within it.
TEST(Replay, InputReplayAndAWrongInputCaughtByTheTolerance) {
  const SavedSolution& s = pushSolution();
  const double d = 0.1, T = 0.3;
  ReplayOptions o = replayOptions({EngineKind::Saltus});
  const ReplayResult r = replay(s, o);
  const EngineReplay& E = r.engines[0];
  ASSERT_TRUE(E.completed) << E.message;
  EXPECT_NEAR(r.end_time, T, 1e-9);
  // The mean of u over the first step, [0, dt]: the analytic input at dt/2.
  EXPECT_NEAR(r.u_applied[0][0], 12 * d / (T * T * T) * (T / 2 - o.dt / 2), 1e-3);
  EXPECT_LT(E.max_position_deviation, 1e-6);
  EXPECT_NEAR(E.series.q.back()[0], d, 1e-6);
  EXPECT_TRUE(E.within_tolerance);
  EXPECT_TRUE(r.optimised_events.empty());  // resting contact throughout
  EXPECT_TRUE(E.events.empty());

  o.input_scale = 2.0;
  const ReplayResult doubled = replay(s, o);
  EXPECT_FALSE(doubled.engines[0].within_tolerance);
  EXPECT_FALSE(doubled.withinTolerance());
  EXPECT_GT(doubled.engines[0].max_position_deviation, 0.05);

  o.input_scale = 1.0;
  o.input_offset = Eigen::VectorXd::Constant(1, 0.05);
  const ReplayResult offset = replay(s, o);
  EXPECT_NEAR(offset.engines[0].final_position_deviation, 0.5 * 0.05 * T * T, 1e-5);
  EXPECT_FALSE(offset.engines[0].within_tolerance);

  o.feedback = Feedback::Pd;  // Kp 100: the offset leaves a deviation ≤ 0.05 / 100
  const ReplayResult tracked = replay(s, o);
  EXPECT_TRUE(tracked.engines[0].within_tolerance);
  EXPECT_LT(tracked.engines[0].max_position_deviation, 0.05 / 100);
}

// Restart::Mesh: each element replayed from its own optimised start. A constant 0.05 N too much
// on the 1 kg block of push_block strays 0.5 · 0.05 · t² from where the replay last started: open
// loop 0.5 · 0.05 · T² (T = 0.3 s) at the end, with restarts 0.5 · 0.05 · h² (h = 0.03 s, its
// ten equal elements), (T / h)² = 100 times less. The drop's bounce at a mesh point is still the
// engine's own: the restart before it takes the state before the jump, and the impact matches.
TEST(Replay, MeshRestartsBoundTheDeviationByOneElement) {
  const SavedSolution& s = pushSolution();
  const double T = 0.3, h = 0.03, a = 0.05;
  ReplayOptions o = replayOptions({EngineKind::Saltus});
  o.input_offset = Eigen::VectorXd::Constant(1, a);
  const ReplayResult open = replay(s, o);
  o.restart = Restart::Mesh;
  const ReplayResult restarted = replay(s, o);
  ASSERT_EQ(restarted.mesh_times.size(), 11u);
  for (std::size_t n = 1; n < restarted.mesh_times.size(); ++n)
    ASSERT_NEAR(restarted.mesh_times[n] - restarted.mesh_times[n - 1], h, 1e-9);
  const EngineReplay& E = restarted.engines[0];
  ASSERT_TRUE(E.completed) << E.message;
  EXPECT_NEAR(open.engines[0].max_position_deviation, 0.5 * a * T * T, 1e-5);
  // Each restart at the last step at or before its mesh time: a segment is h plus at most dt.
  EXPECT_NEAR(E.max_position_deviation, 0.5 * a * h * h, 0.5 * a * (2 * h * o.dt + o.dt * o.dt) + 1e-7);
  EXPECT_NEAR(E.max_velocity_deviation, a * h, a * o.dt + 1e-6);
  EXPECT_NEAR(E.final_position_deviation, 0.5 * a * h * h, 0.5 * a * (2 * h * o.dt + o.dt * o.dt) + 1e-7);

  ReplayOptions d = replayOptions({EngineKind::Saltus});
  d.restart = Restart::Mesh;
  const ReplayResult bounce = replay(dropSolution(), d);
  const EngineReplay& B = bounce.engines[0];
  ASSERT_TRUE(B.completed) << B.message;
  EXPECT_TRUE(B.within_tolerance) << B.max_position_deviation;
  EXPECT_EQ(matchedEvents(B), static_cast<int>(bounce.optimised_events.size()));
  EXPECT_NEAR(B.energy_end, 0.5 * 0.5 * 9.81 * 0.1, 2e-3);  // e² of the drop's energy: the engine bounced
  EXPECT_EQ(parseRestart("mesh"), Restart::Mesh);
  EXPECT_STREQ(restartName(Restart::None), "none");
  EXPECT_THROW(parseRestart("element"), std::invalid_argument);
}

// From the state after each mesh point's jump: where there is no jump (the push) the same
// restarts as Restart::Mesh; at the drop's bounce the engine starts with the optimiser's
// rebound, so it records no impact of its own there, and the motion after it is still matched.
TEST(Replay, RestartsAfterJumpsTakeTheOptimisersImpulse) {
  ReplayOptions o = replayOptions({EngineKind::Saltus});
  o.input_offset = Eigen::VectorXd::Constant(1, 0.05);
  o.restart = Restart::Mesh;
  const ReplayResult before = replay(pushSolution(), o);
  o.restart = Restart::MeshAfterJumps;
  const ReplayResult after = replay(pushSolution(), o);
  ASSERT_TRUE(after.engines[0].completed) << after.engines[0].message;
  // (the jump between the two sides of a mesh point without an impulse is round-off)
  EXPECT_NEAR(after.engines[0].max_position_deviation, before.engines[0].max_position_deviation, 1e-12);
  EXPECT_NEAR(after.engines[0].max_velocity_deviation, before.engines[0].max_velocity_deviation, 1e-12);

  ReplayOptions d = replayOptions({EngineKind::Saltus});
  const auto impacts = [](const EngineReplay& E) {
    int n = 0;
    for (const ContactEvent& e : E.events) n += e.kind == ContactEvent::Impact;
    return n;
  };
  d.restart = Restart::Mesh;
  const ReplayResult engine = replay(dropSolution(), d);
  d.restart = Restart::MeshAfterJumps;
  const ReplayResult given = replay(dropSolution(), d);
  const EngineReplay& B = engine.engines[0];
  const EngineReplay& A = given.engines[0];
  ASSERT_TRUE(A.completed) << A.message;
  EXPECT_TRUE(A.within_tolerance) << A.max_position_deviation;
  EXPECT_GE(impacts(B), 1);
  EXPECT_EQ(impacts(A), impacts(B) - 1);  // the bounce's impulse was the optimiser's
  EXPECT_NEAR(A.energy_end, 0.5 * 0.5 * 9.81 * 0.1, 2e-3);
  EXPECT_EQ(parseRestart("mesh-after-jumps"), Restart::MeshAfterJumps);
}

TEST(Replay, RefusesBadOptions) {
  const SavedSolution& s = pushSolution();
  ReplayOptions o = replayOptions({EngineKind::Saltus});
  o.dt = 0;
  EXPECT_THROW(replay(s, o), std::invalid_argument);
  o.dt = -1e-3;
  EXPECT_THROW(replay(s, o), std::invalid_argument);
  // A step longer than a tenth of the solution replays nothing of it (its default tolerance,
  // 10 m/s × dt, would accept anything): refused, naming the duration.
  const double T = s.trajectory().endTime();
  o.dt = 10;
  try {
    replay(s, o);
    ADD_FAILURE() << "dt = 10 s accepted on a " << T << " s solution";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("dt: expected at most a tenth of the solution's duration"), std::string::npos)
        << e.what();
  }
  o.dt = T / 10;  // the longest step accepted
  EXPECT_NO_THROW(checkReplayOptions(o, s));
  o = replayOptions({EngineKind::Saltus});
  o.input_offset = Eigen::VectorXd::Zero(2);  // one input
  EXPECT_THROW(replay(s, o), std::invalid_argument);
  o = replayOptions({EngineKind::Saltus});
  o.tolerance = -1;
  EXPECT_THROW(replay(s, o), std::invalid_argument);
  o = replayOptions({});
  EXPECT_THROW(replay(s, o), std::invalid_argument);
  EXPECT_THROW(parseEngines("ode"), std::invalid_argument);
  EXPECT_EQ(parseEngines("both").size(), 2u);
  EXPECT_THROW(parseFeedback("pid"), std::invalid_argument);
}

// The belt's step is given on the problem's elements ([6, 0]); the first-order method has
// first_order_steps_per_element steps per element, so the step happens at step 6·steps_per_element's time.
TEST(Replay, FirstOrderBeltStepsAtItsElementsMeshTime) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("saltus_replay_fo_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const collocation::Problem p = collocation::loadProblem("pendulum_conveyor");
  const collocation::Transcription t(p, collocation::Method::FirstOrder);
  collocation::writeSolution(dir.string(), t, t.perturb(t.nullSeed(), 0.1, 3));  // unequal step lengths
  const collocation::SavedSolution s = collocation::loadSolution(dir.string());
  const scene::Scene scene = replayScene(s);
  const int steps_per_element = p.first_order_steps_per_element;
  const auto& steps = p.surface_steps.at(0);
  const auto& schedule = scene.surfaces[0].velocity_schedule;
  ASSERT_EQ(schedule.size(), steps.size());
  ASSERT_GT(steps.back().element, 0);
  for (std::size_t i = 0; i < steps.size(); ++i)
    EXPECT_DOUBLE_EQ(schedule[i].time, s.trajectory().meshTimes()[steps[i].element * steps_per_element]) << "step " << i;
  std::filesystem::remove_all(dir);
}

// A first-order solution is replayed against its own O(h) error: the default tolerance adds one
// step's travel at the top speed. The inelastic drop from 0.2 m (v = sqrt(2 g h) = 1.98 m/s at
// the landing): the deviation is first order in the step (halved with twice the elements) and
// within the allowance, and the allowance is max |ż| × longest step.
TEST(Replay, FirstOrderSolutionWithinItsOwnStepError) {
  std::vector<double> deviation;
  for (int N : {10, 20}) {
    SavedSolution s;
    s.problem = std::make_unique<collocation::Problem>(collocation::loadProblem("point_mass_drop", {{"height", 0.2}}));
    collocation::remesh(*s.problem, N, s.problem->P);
    s.problem->h_max *= 20.0 / N;
    s.transcription = std::make_unique<collocation::Transcription>(*s.problem, collocation::Method::FirstOrder);
    const collocation::Seeding seeding = collocation::makeSeeding(*s.transcription);
    collocation::SolveOptions so;
    so.restarts = seeding.restarts;
    const collocation::SolveReport r = collocation::solve(*s.transcription, seeding.seed, so);
    ASSERT_TRUE(r.feasible) << "N = " << N << ": " << r.stages.back().status;
    s.x = r.x;
    const ReplayResult R = replay(s, replayOptions({EngineKind::Saltus}));
    const EngineReplay& e = R.engines.at(0);
    ASSERT_TRUE(e.completed) << e.message;
    const std::vector<double> mesh = s.trajectory().meshTimes();
    double step = 0;
    for (std::size_t n = 1; n < mesh.size(); ++n) step = std::max(step, mesh[n] - mesh[n - 1]);
    // max |ż| is the scheme's landing speed, below the exact one by its own O(h) error.
    EXPECT_NEAR(R.method_allowance, std::sqrt(2 * 9.81 * 0.2) * step, 0.1 * R.method_allowance) << "N = " << N;
    EXPECT_DOUBLE_EQ(R.tolerance, 1e-3 + R.method_allowance);
    EXPECT_TRUE(e.within_tolerance) << "N = " << N << ": " << e.max_position_deviation << " > " << R.tolerance;
    EXPECT_GT(e.max_position_deviation, 1e-3) << "N = " << N << ": a first-order solution beyond 10 m/s × dt";
    deviation.push_back(e.max_position_deviation);
    // A given tolerance is applied as it is.
    ReplayOptions given = replayOptions({EngineKind::Saltus});
    given.tolerance = 1e-3;
    const ReplayResult G = replay(s, given);
    EXPECT_EQ(G.method_allowance, 0);
    EXPECT_FALSE(G.engines.at(0).within_tolerance);
  }
  const double order = std::log2(deviation[0] / deviation[1]);
  EXPECT_NEAR(order, 1.0, 0.3) << deviation[0] << " → " << deviation[1];
}

}  // namespace
}  // namespace saltus::verify
