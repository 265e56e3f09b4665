// The solver's tightening (collocation/solver.hpp): a feasibility stage that ends near the
// tolerance or at its limit is tightened in steps, each from the stage before's end under the
// monotone barrier, and which ends are tightened (tightensAfter).
#include <IpReturnCodes.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "collocation/nlp.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/solution.hpp"
#include "collocation/solver.hpp"
#include "tests/support/drop_checks.hpp"
#include "tests/support/near_miss_drop.hpp"

namespace saltus::collocation {
namespace {

using testing::checkDrop;
using testing::expectTightenedDrop;
using testing::nearMissDrop;
using testing::Solved;
using testing::withHeightCost;
using testing::withMaxVariable;

// A feasibility stage that ends just above the tolerance is tightened. The inelastic drop from
// the perturbed simulation seed 5 ends at a local minimum of the penalty with a few small
// impulses while the mass rests (largest product 1.5e-4); the tightening stage, every ε bounded
// by 0.9 × 1e-4 from that point, reaches a solution that lands at the analytic time; without it
// the solve ends infeasible.
TEST(Solver, TighteningPullsANearMissUnderTheTolerance) {
  Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions without;
  without.tighten_within = 0;
  const SolveReport near = solve(t, seeding.seed, without);
  ASSERT_FALSE(near.feasible);
  ASSERT_EQ(near.stages.size(), 1u);
  EXPECT_GT(near.largest_product, p.complementarity_tolerance);
  EXPECT_LE(near.largest_product, 10 * p.complementarity_tolerance);

  const SolveReport tightened = solve(t, seeding.seed, SolveOptions{});
  expectTightenedDrop(t, tightened);
  // Without a task stage to polish its point, the tightening stage converges (Ipopt's tolerance
  // makes the free fall exact to 1e-6).
  EXPECT_EQ(tightened.stages[1].status, "Solve_Succeeded");

  // With a task cost the tightened point is where the task stage starts; without tightening
  // it would start off the constraints (its ε bounded below the near miss's products). The task
  // problem starts from the near miss itself (a local minimum of the penalty, where its
  // feasibility stage ends again), carried over by variable name, with x_m the largest height in
  // it: its own seeding would draw other random numbers, and whether their feasibility stage
  // ends just above the tolerance or just under it depends on rounding.
  withHeightCost(p);
  const Transcription task(p, Method::Impulsive);
  const Eigen::VectorXd task_seed = withMaxVariable(t, near.x, task);
  const SolveReport c = solve(task, [&](int) { return Seed{task_seed, true}; }, SolveOptions{});
  ASSERT_EQ(c.stages.size(), 3u);
  EXPECT_EQ(c.stages[0].name, "feasibility");
  EXPECT_GT(c.stages[0].largest_product, p.complementarity_tolerance);
  EXPECT_EQ(c.stages[1].name, "tighten");
  EXPECT_EQ(c.stages[2].name, "task");
  EXPECT_LE(c.stages[1].largest_product, p.complementarity_tolerance);
  // With the task stage to follow, the tightening stage stops at its first feasible point (an
  // iterate or a trial of its last iteration), and that is not an interruption.
  EXPECT_EQ(c.stages[1].status, "Stopped_At_Feasible_Point");
  if (c.stages[1].kept_iteration >= 0) {
    EXPECT_LE(c.stages[1].iterations, c.stages[1].kept_iteration + 1);
  }
  EXPECT_FALSE(c.interrupted);
  EXPECT_TRUE(c.converged) << c.stages[2].status << ": " << c.note;
  EXPECT_NEAR(c.objective, 0.1, 1e-3);  // x_m: the drop's start
}

// SolveOptions::feasibility_only (a continuation's step): the feasibility stage alone, the same
// stage as a full solve's first, with neither the tightening its near miss would get nor the
// task stage its cost would.
TEST(Solver, FeasibilityOnlyIsTheFirstStageAlone) {
  Problem p = nearMissDrop();
  withHeightCost(p);
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  const Eigen::VectorXd x0 = seeding.seed(0).x;
  const SolveReport full = solve(t, x0, SolveOptions{});
  ASSERT_GT(full.stages.size(), 1u);
  SolveOptions only;
  only.feasibility_only = true;
  const SolveReport first = solve(t, x0, only);
  ASSERT_EQ(first.stages.size(), 1u);
  EXPECT_EQ(first.stages[0].name, "feasibility");
  EXPECT_EQ(first.stages[0].iterations, full.stages[0].iterations);
  EXPECT_EQ(first.stages[0].largest_product, full.stages[0].largest_product);
  EXPECT_EQ(first.kept_stage, 0);
  EXPECT_EQ(first.iterations, first.stages[0].iterations);
}

// A stage that only restores feasibility from near a solution (a tightening step, or a first
// stage from a warm seed) runs under Ipopt's monotone barrier from μ₀ = 1e-4 (the adaptive
// strategy's oracle ignores μ₀); a first stage from a cold seed, and the task stage, which
// optimises, under the adaptive one; the caller's mu_strategy overrides them all. The near miss:
// a cold feasibility stage, then tightening, to the drop either way.
TEST(Solver, StagesThatRestoreFeasibilityNearASolutionUseTheMonotoneBarrier) {
  Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  const SolveReport r = solve(t, seeding.seed, SolveOptions{});
  expectTightenedDrop(t, r);
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[0].barrier, "adaptive");
  EXPECT_EQ(r.stages[1].barrier, "monotone");

  SolveOptions adaptive;
  adaptive.ipopt["mu_strategy"] = "adaptive";
  const SolveReport a = solve(t, seeding.seed, adaptive);
  expectTightenedDrop(t, a);
  for (const StageReport& s : a.stages) EXPECT_EQ(s.barrier, "adaptive") << s.name;

  // With a task cost (the lowest largest height, x_m), from the drop as a warm seed: the first
  // stage monotone, the task stage adaptive, the result feasible.
  withHeightCost(p);
  const Transcription task(p, Method::Impulsive);
  const Eigen::VectorXd task_seed = withMaxVariable(t, r.x, task);
  const SolveReport c = solve(task, [&](int) { return Seed{task_seed, true}; }, SolveOptions{});
  ASSERT_GE(c.stages.size(), 2u);
  EXPECT_EQ(c.stages.front().name, "feasibility");
  EXPECT_EQ(c.stages.front().barrier, "monotone");
  EXPECT_EQ(c.stages.back().name, "task");
  EXPECT_EQ(c.stages.back().barrier, "adaptive");
  EXPECT_TRUE(c.feasible) << c.stages.back().status;
}

// A tightening stage starts at the stage before's end and keeps it: the caller's bound_push and
// bound_frac (0.1 here, Ipopt's 0.01 by default: a cold first stage's start) do not move it into
// its bounds. The near miss as a warm seed that keeps its warm start: its first stage ends where
// it did, and the tightening stage from there is the same stage, iteration for iteration, with and
// without the caller's push.
TEST(Solver, TheTighteningStageStartsAtTheStageBeforesEndWhateverTheCallersBoundPush) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions without;
  without.tighten_within = 0;
  const SolveReport near = solve(t, seeding.seed, without);
  ASSERT_GT(near.largest_product, p.complementarity_tolerance);
  const SeedFunction warm = [&](int) { return Seed{near.x, true, false, true}; };
  const SolveReport plain = solve(t, warm, SolveOptions{});
  SolveOptions pushed;
  pushed.ipopt["bound_push"] = "0.1";
  pushed.ipopt["bound_frac"] = "0.1";
  const SolveReport r = solve(t, warm, pushed);
  expectTightenedDrop(t, plain);
  expectTightenedDrop(t, r);
  EXPECT_EQ(r.stages[0].iterations, plain.stages[0].iterations);
  EXPECT_EQ(r.stages[1].iterations, plain.stages[1].iterations);
  EXPECT_LE((r.x - plain.x).lpNorm<Eigen::Infinity>(), 1e-12);
}

// When no stage ends feasible, the result is the point nearest a trajectory, not the last
// stage's. The near miss above (products 1.5e-4, constraints met), untightened, with a task stage
// stopped at its start pushed 0.1 inside its bounds (every reaction and ε at least 0.1: products
// of at least 1e-2): the feasibility stage's point is kept, and said so.
TEST(Solver, WithoutAFeasiblePointTheNearerStageEndIsKept) {
  Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  SolveOptions without;
  without.tighten_within = 0;
  const SolveReport near = solve(t, makeSeeding(t).seed, without);
  ASSERT_FALSE(near.feasible);
  ASSERT_EQ(near.stages.size(), 1u);
  ASSERT_TRUE(near.stages[0].succeeded) << near.stages[0].status;

  withHeightCost(p);
  const Transcription task(p, Method::Impulsive);
  const Eigen::VectorXd task_seed = withMaxVariable(t, near.x, task);
  SolveOptions o = without;
  o.task_ipopt = {{"max_iter", "0"}, {"bound_push", "0.1"}, {"bound_frac", "0.1"}};
  const SolveReport r = solve(task, [&](int) { return Seed{task_seed, true}; }, o);
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[1].name, "task");
  EXPECT_EQ(r.stages[1].iterations, 0);
  EXPECT_GE(r.stages[1].largest_product, 1e-2);
  EXPECT_LE(r.stages[0].largest_product, 10 * p.complementarity_tolerance);
  EXPECT_FALSE(r.feasible);
  // The result's products are measured at its point x: the feasibility stage's end.
  EXPECT_EQ(r.largest_product, r.stages[0].largest_product);
  EXPECT_EQ(r.largest_violation, r.stages[0].largest_violation);
  EXPECT_NE(r.note.find("kept the feasibility stage's point"), std::string::npos) << r.note;
  // The solve's status is the kept stage's, not the last stage's of no iterations.
  EXPECT_EQ(r.kept_stage, 0);
  EXPECT_EQ(r.stages[1].status, "Maximum_Iterations_Exceeded");
  EXPECT_EQ(&r.keptStage(), &r.stages[0]);
  EXPECT_TRUE(r.keptStage().succeeded) << r.keptStage().status;
}

// A feasibility stage stopped by its iteration limit short of the tolerance is tightened too. The
// drop of the test above, allowed 80 iterations (it needs 106), stops at products of 1.6e-4;
// without tightening that is the result, infeasible; with it the tightening stage (its own 80
// iterations) reaches a solution that lands at the analytic time. --tighten-within limits it.
TEST(Solver, AFeasibilityStageStoppedByItsLimitIsTightened) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions o;
  o.ipopt["max_iter"] = "80";
  SolveOptions without = o;
  without.tighten_within = 0;
  const SolveReport stopped = solve(t, seeding.seed, without);
  ASSERT_EQ(stopped.stages.size(), 1u);
  EXPECT_EQ(stopped.stages[0].status, "Maximum_Iterations_Exceeded");
  EXPECT_FALSE(stopped.feasible);
  EXPECT_GT(stopped.largest_product, p.complementarity_tolerance);

  const SolveReport r = solve(t, seeding.seed, o);
  EXPECT_EQ(r.stages[0].status, "Maximum_Iterations_Exceeded");
  expectTightenedDrop(t, r);

  // tighten_within limits it as it does a solved stage: stopped after 10 iterations the products
  // are more than 10 times the tolerance, and with tighten_within = 10 there is no tightening.
  o.ipopt["max_iter"] = "10";
  o.tighten_within = 10;
  const SolveReport early = solve(t, seeding.seed, o);
  ASSERT_EQ(early.stages[0].status, "Maximum_Iterations_Exceeded");
  ASSERT_GT(early.stages[0].largest_product, 10 * p.complementarity_tolerance);
  EXPECT_EQ(early.stages.size(), 1u);
  EXPECT_FALSE(early.feasible);
}

// From products far above the tolerance the tightening bound is lowered in steps
// (SolveOptions::tighten_factor). The near miss of the tests above (products of 1.5e-4) with a
// factor of 1.2, so that it is far enough above the tolerance for a step: each step bounds
// every ε by 0.9 × the products over 1.2 and stops at its first point within them, and the last
// step, bounded by 0.9 × the tolerance, converges to the drop that lands at the analytic time.
// With a factor of 1 the tightening is the one stage.
TEST(Solver, TighteningFromFarAboveTheToleranceLowersTheBoundInSteps) {
  const Problem p = nearMissDrop();
  const double tolerance = p.complementarity_tolerance;
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions o;
  o.tighten_factor = 1.2;
  const SolveReport r = solve(t, seeding.seed, o);
  ASSERT_GE(r.stages.size(), 3u);
  const double start = r.stages[0].largest_product;
  ASSERT_GT(start, 1.2 * tolerance);
  EXPECT_EQ(r.stages[0].product_bound, 0.0);
  double bound = start;  // the products' tolerance of the step before
  for (std::size_t i = 1; i + 1 < r.stages.size(); ++i) {
    const StageReport& step = r.stages[i];
    EXPECT_EQ(step.name, "tighten");
    // The lower of the last tolerance and the products reached, over the factor.
    const double expected = std::min(bound, r.stages[i - 1].largest_product) / 1.2;
    EXPECT_NEAR(step.product_bound, kPenaltyBoundFraction * expected, 1e-12 * expected) << "step " << i;
    EXPECT_EQ(step.status, "Stopped_At_Feasible_Point") << "step " << i;
    EXPECT_LE(step.largest_product, expected) << "step " << i;
    EXPECT_LE(step.largest_violation, o.violation_tolerance) << "step " << i;
    EXPECT_GT(expected, tolerance);
    bound = expected;
  }
  const StageReport& last = r.stages.back();
  EXPECT_EQ(last.name, "tighten");
  EXPECT_EQ(last.product_bound, kPenaltyBoundFraction * tolerance);
  EXPECT_EQ(last.status, "Solve_Succeeded");
  EXPECT_TRUE(r.feasible);
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);

  // The steps' bounds are the NLP's: every ε of a step's problem is bounded by its bound.
  Nlp step(t, Stage::Tighten, r.x);
  step.boundProducts(0.25);
  const int n = t.variables(), m = t.constraints();
  std::vector<double> xl(n), xu(n), gl(m), gu(m);
  ASSERT_TRUE(step.get_bounds_info(n, xl.data(), xu.data(), m, gl.data(), gu.data()));
  ASSERT_FALSE(t.penaltyVariables().empty());
  for (int e : t.penaltyVariables()) EXPECT_EQ(xu[e], 0.25);

  o.tighten_factor = 1;
  const SolveReport one = solve(t, seeding.seed, o);
  ASSERT_EQ(one.stages.size(), 2u);
  EXPECT_EQ(one.stages[1].product_bound, kPenaltyBoundFraction * tolerance);
}

// Which ends of the feasibility stage are tightened (tightensAfter): an infeasible point within
// tighten_within × the tolerance, whether Ipopt solved the stage, stopped it at a limit or failed
// its restoration phase there; not a feasible point, not one beyond the ratio, not one left by an
// error in a step.
TEST(Solver, TighteningFollowsASolvedStoppedOrFailedRestorationEnd) {
  const double tolerance = 1e-4, violation = 1e-5, within = std::numeric_limits<double>::infinity();
  StageReport end;
  end.largest_product = 0.015;
  end.largest_violation = 1.3e-9;
  const auto with = [&](int code, bool succeeded) {
    StageReport s = end;
    s.status_code = code;
    s.succeeded = succeeded;
    return s;
  };
  EXPECT_TRUE(tightensAfter(with(Ipopt::Solved_To_Acceptable_Level, true), tolerance, violation, within));
  EXPECT_TRUE(tightensAfter(with(Ipopt::Maximum_Iterations_Exceeded, false), tolerance, violation, within));
  EXPECT_TRUE(tightensAfter(with(Ipopt::Maximum_CpuTime_Exceeded, false), tolerance, violation, within));
  EXPECT_TRUE(tightensAfter(with(Ipopt::Restoration_Failed, false), tolerance, violation, within));
  EXPECT_FALSE(tightensAfter(with(Ipopt::Error_In_Step_Computation, false), tolerance, violation, within));
  EXPECT_FALSE(tightensAfter(with(Ipopt::Invalid_Number_Detected, false), tolerance, violation, within));
  EXPECT_FALSE(tightensAfter(with(Ipopt::Restoration_Failed, false), tolerance, violation, 100)) << "beyond the ratio";
  EXPECT_TRUE(tightensAfter(with(Ipopt::Restoration_Failed, false), tolerance, violation, 200));
  StageReport feasible = with(Ipopt::Restoration_Failed, false);
  feasible.largest_product = 9e-5;
  EXPECT_FALSE(tightensAfter(feasible, tolerance, violation, within)) << "nothing to tighten";
  feasible.largest_violation = 1e-3;  // products met, a constraint not: tightened
  EXPECT_TRUE(tightensAfter(feasible, tolerance, violation, within));
  StageReport nan = with(Ipopt::Maximum_Iterations_Exceeded, false);
  nan.largest_product = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(tightensAfter(nan, tolerance, violation, within)) << "a point that is not finite";
  nan.largest_product = 0.015;
  nan.largest_violation = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(tightensAfter(nan, tolerance, violation, within));
}

}  // namespace
}  // namespace saltus::collocation
