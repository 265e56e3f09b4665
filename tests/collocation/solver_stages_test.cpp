// The solver's task stage (collocation/solver.hpp): its best feasible point wherever it stops,
// its own options and limits, each stage's Hessian, and the penalty stage before it. The
// tightening: solver_tightening_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "collocation/nlp.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solution.hpp"
#include "collocation/solver.hpp"
#include "tests/support/drop_checks.hpp"
#include "tests/support/near_miss_drop.hpp"

namespace saltus::collocation {
namespace {

using testing::checkDrop;
using testing::heightCostDrop;
using testing::nearMissDrop;
using testing::Solved;
using testing::withHeightCost;

// A task stage stopped after any number of iterations leaves a feasible point no worse than its
// start (the best feasible point it evaluated, when its end is off the constraints or worse).
// The mechanism itself: Nlp.KeepsTheBestFeasiblePointItEvaluates.
TEST(Solver, ATaskStageStoppedAnywhereKeepsItsBestFeasiblePoint) {
  Problem p = heightCostDrop();
  const Transcription t(p, Method::Impulsive);
  SolveOptions o;
  o.warm_seed = true;
  // A solution with x_m 0.4 m above the largest height, which the feasibility stage does not
  // lower (it is not in the penalty): the task stage starts from x_m = 0.1 m, the largest height.
  Eigen::VectorXd seed = solve(t, seedFromSimulation(t), o).x;
  const auto names = t.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, t.variables());
  seed[x_m] += 0.4;
  o.task_max_iter = 0;
  const double start = solve(t, seed, o).objective;
  EXPECT_NEAR(start, 0.1, 1e-3);
  int kept = 0;
  double best = start;
  for (int k : {1, 2, 4, 8}) {
    o.task_max_iter = k;
    const SolveReport r = solve(t, seed, o);
    ASSERT_EQ(r.stages.size(), 2u);
    EXPECT_TRUE(r.feasible) << k << " iterations: product " << r.largest_product << ", violation " << r.largest_violation;
    EXPECT_LE(r.objective, start + 1e-12) << k;
    // Checked again from the point itself.
    Nlp nlp(t, Stage::Task, r.x);
    const Eigen::VectorXd g = nlp.constraints(r.x);
    EXPECT_LE(std::max((t.constraintLower() - g).maxCoeff(), (g - t.constraintUpper()).maxCoeff()), o.violation_tolerance) << k;
    EXPECT_NEAR(nlp.cost(r.x), r.objective, 1e-12) << k;
    best = std::min(best, r.objective);
    if (r.stages[1].kept_iteration >= 0) {
      ++kept;
      EXPECT_FALSE(r.converged) << k;
      EXPECT_LE(r.stages[1].kept_iteration, k);
      EXPECT_NE(r.note.find("best feasible point"), std::string::npos) << r.note;
    }
  }
  std::printf("task stage capped at 1, 2, 4, 8 iterations: objective %g from %g, %d kept an earlier point\n", best, start, kept);
  // The drop's first task iterations leave its optimal start for worse or infeasible points.
  EXPECT_GE(kept, 1);
}

// The task stage's own Ipopt options (the problem's task_ipopt, then SolveOptions::task_ipopt)
// reach that stage and no other: max_iter 0 there stops the task stage at its start while the
// feasibility stage iterates; the command line's value overrides the problem's.
TEST(Solver, TaskStageOptionsReachTheTaskStageOnly) {
  Problem p = heightCostDrop();
  p.task_ipopt_options["max_iter"] = "0";
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd seed = seedFromSimulation(t);
  SolveOptions o;
  o.warm_seed = true;
  const SolveReport stopped = solve(t, seed, o);
  ASSERT_EQ(stopped.stages.size(), 2u);
  EXPECT_GT(stopped.stages[0].iterations, 0);
  EXPECT_TRUE(stopped.stages[0].succeeded) << stopped.stages[0].status;
  EXPECT_EQ(stopped.stages[1].iterations, 0);
  EXPECT_EQ(stopped.stages[1].status, "Maximum_Iterations_Exceeded");
  o.task_ipopt["max_iter"] = "3000";
  const SolveReport full = solve(t, seed, o);
  ASSERT_EQ(full.stages.size(), 2u);
  EXPECT_GT(full.stages[1].iterations, 0);
  EXPECT_TRUE(full.stages[1].succeeded) << full.stages[1].status;
}

// The task stage starts at the stage before's end and keeps it, as a tightening stage does: the
// caller's bound_push and bound_frac for every stage (0.1 here: a cold first stage's start) do not
// move a feasible point into its bounds before the task stage's first step; the task stage's own
// options (task_ipopt) still set them for it. The drop with a task cost from the time-stepper's
// seed, kept warm: the same stages iteration for iteration with and without the caller's push.
TEST(Solver, TheTaskStageStartsAtTheStageBeforesEndWhateverTheCallersBoundPush) {
  Problem p = heightCostDrop();
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd seed = seedFromSimulation(t);
  SolveOptions plain;
  plain.warm_seed = true;
  plain.keep_warm_start = true;
  const SolveReport a = solve(t, seed, plain);
  SolveOptions pushed = plain;
  pushed.ipopt["bound_push"] = "0.1";
  pushed.ipopt["bound_frac"] = "0.1";
  const SolveReport b = solve(t, seed, pushed);
  ASSERT_EQ(a.stages.size(), 2u);
  ASSERT_EQ(b.stages.size(), 2u);
  EXPECT_TRUE(a.converged && b.converged) << a.stages[1].status << ", " << b.stages[1].status;
  EXPECT_EQ(b.stages[0].iterations, a.stages[0].iterations);
  EXPECT_EQ(b.stages[1].iterations, a.stages[1].iterations);
  EXPECT_LE((b.x - a.x).lpNorm<Eigen::Infinity>(), 1e-12);
  SolveOptions own = plain;
  own.task_ipopt["bound_push"] = "0.1";
  own.task_ipopt["bound_frac"] = "0.1";
  const SolveReport c = solve(t, seed, own);
  ASSERT_EQ(c.stages.size(), 2u);
  EXPECT_EQ(c.stages[0].iterations, a.stages[0].iterations);
  EXPECT_TRUE(c.stages[1].iterations != a.stages[1].iterations || (c.x - a.x).lpNorm<Eigen::Infinity>() > 1e-9)
      << "the task stage's own bound_push reaches it";
}

// A task stage stopped by its iteration limit at a feasible point leaves a feasible, not
// converged, solution. The inelastic drop with a task cost (the lowest largest height, x_m): its
// feasibility stage ends at a solution; a task stage allowed no iteration stops at that point
// (Maximum_Iterations_Exceeded) and the result is the drop, feasible and not converged; allowed
// its iterations, the task stage converges.
TEST(Solver, ATaskStageStoppedAtAFeasiblePointIsFeasibleNotConverged) {
  Problem p = heightCostDrop();
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd seed = seedFromSimulation(t);
  SolveOptions stopped;
  stopped.warm_seed = true;
  stopped.task_max_iter = 0;
  const SolveReport r = solve(t, seed, stopped);
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_TRUE(r.stages[0].succeeded);
  EXPECT_EQ(r.stages[1].status, "Maximum_Iterations_Exceeded");
  EXPECT_EQ(r.stages[1].iterations, 0);
  EXPECT_EQ(r.kept_stage, 1);  // its start is feasible: the task stage's point is the result
  EXPECT_TRUE(r.feasible) << "largest product " << r.largest_product << ", violation " << r.largest_violation;
  EXPECT_FALSE(r.converged);
  EXPECT_LE(r.largest_violation, stopped.violation_tolerance);
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);

  SolveOptions full;
  full.warm_seed = true;
  const SolveReport c = solve(t, seed, full);
  ASSERT_EQ(c.stages.size(), 2u);
  EXPECT_TRUE(c.stages[1].succeeded) << c.stages[1].status;
  EXPECT_TRUE(c.feasible);
  EXPECT_TRUE(c.converged);
  // x_m is the largest height: the drop's start, 0.1 m.
  EXPECT_NEAR(c.objective, 0.1, 1e-3);

  // A feasibility stage's point leaves x_m anywhere above the heights: tightened, it is the
  // largest height, and the task objective there is x_m plus the (tiny) weighted penalty.
  Eigen::VectorXd x = r.x;
  const auto names = t.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, t.variables());
  x[x_m] = 7.0;
  t.tightenMaxVariable(x);
  double highest = 0;
  for (const ElementLayout& L : t.layout())
    for (const auto& point : L.points) highest = std::max(highest, x[point.q]);
  EXPECT_DOUBLE_EQ(x[x_m], highest);
  EXPECT_NEAR(x[x_m], 0.1, 1e-9);
  EXPECT_NEAR(Nlp(t, Stage::Task, x).cost(x), 0.1, 1e-3);
}

// The feasibility stage with Ipopt's quasi-Newton Hessian (no second derivatives evaluated) and
// the task stage with the exact one: the same physics as with the exact Hessian throughout.
TEST(Solver, AQuasiNewtonFeasibilityStageAndAnExactTaskStage) {
  Problem p = loadProblem("point_mass_drop");
  withHeightCost(p);  // a task stage: minimise the largest height
  for (const bool exact_feasibility : {false, true}) {
    SCOPED_TRACE(exact_feasibility ? "exact" : "limited-memory");
    p.feasibility_exact_hessian = exact_feasibility;
    const Transcription t(p, Method::Impulsive);
    SolveOptions o;
    o.warm_seed = true;
    const SolveReport r = solve(t, seedFromSimulation(t), o);
    ASSERT_GE(r.stages.size(), 2u);
    const StageReport &feasibility = r.stages.front(), &task = r.stages.back();
    EXPECT_EQ(feasibility.exact_hessian, exact_feasibility);
    EXPECT_EQ(feasibility.hessian_evaluations > 0, exact_feasibility) << feasibility.hessian_evaluations;
    EXPECT_TRUE(task.exact_hessian);
    EXPECT_GT(task.hessian_evaluations, 0);
    EXPECT_TRUE(r.converged) << task.status << ", largest product " << r.largest_product;
    EXPECT_NEAR(r.objective, 0.1, 1e-3);  // x_m: the drop's start
    Solved s;
    s.report = r;
    s.rows = trajectory(t, r.x);
    checkDrop(s, 0.0);
  }
}

// Without a task cost a solve that Ipopt solved is converged; a feasibility stage stopped by its
// iteration limit before the products are small is neither feasible nor converged.
TEST(Solver, FeasibleAndConvergedWithoutATaskCost) {
  const Problem p = loadProblem("point_mass_drop");
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd seed = seedFromSimulation(t);
  SolveOptions o;
  o.warm_seed = true;
  const SolveReport r = solve(t, seed, o);
  EXPECT_TRUE(r.feasible);
  EXPECT_TRUE(r.converged);
  SolveOptions cut;
  cut.ipopt["max_iter"] = "1";
  cut.tighten_within = 0;
  const SolveReport n = solve(t, t.nullSeed(), cut);
  EXPECT_EQ(n.stages.back().status, "Maximum_Iterations_Exceeded");
  EXPECT_FALSE(n.feasible) << "largest product " << n.largest_product;
  EXPECT_FALSE(n.converged);
  // The constraint furthest outside its bounds is named, here and in its stage's report: checked
  // against the constraints evaluated again at the point.
  const Eigen::VectorXd g = Nlp(t, Stage::Feasibility, n.x).constraints(n.x);
  const Eigen::VectorXd off = (t.constraintLower() - g).cwiseMax(g - t.constraintUpper());
  Eigen::Index worst = 0;
  ASSERT_GT(off.maxCoeff(&worst), 1e-3);  // the null seed's velocities ignore gravity
  EXPECT_EQ(n.largest_violation, off[worst]);
  EXPECT_EQ(n.largest_violation_at, t.constraintNames()[static_cast<std::size_t>(worst)]);
  EXPECT_EQ(n.stages.back().largest_violation_at, n.largest_violation_at);
  EXPECT_LE(r.largest_violation, o.violation_tolerance);
  // A stage stopped by its CPU-time limit reports the objective at its end point (Ipopt 3.11
  // hands over 0 then).
  SolveOptions timed = cut;
  timed.ipopt = {{"max_cpu_time", "1e-9"}};
  const SolveReport c = solve(t, t.nullSeed(), timed);
  EXPECT_EQ(c.stages.back().status, "Maximum_CpuTime_Exceeded");
  const double penalty = Nlp(t, Stage::Feasibility, c.x).cost(c.x);
  EXPECT_GT(penalty, 0);
  EXPECT_EQ(c.stages.back().objective, penalty);
}

// The penalty stage (Problem::penalty_iterations): the drop with a task cost (x_m) from the
// perturbed simulation seed 1, whose feasibility stage ends at a near miss (the test above). The
// penalty stage reaches a feasible point within its cap and stops there, and the task stage
// converges from it. Capped at one iteration it stops short, and the solve goes on as one without
// it: the feasibility stage from the same seed, the same iterations to the same point.
// The near-miss drop with x_m as its task cost and the penalty stage capped at 200 iterations.
Problem penaltyStageDrop() {
  Problem p = nearMissDrop();
  withHeightCost(p);
  p.random_seed = 1;
  p.penalty_iterations = 200;
  return p;
}

TEST(Solver, APenaltyStageStopsAtItsFirstFeasiblePointOrHandsOver) {
  Problem p = penaltyStageDrop();
  const Transcription t(p, Method::Impulsive);
  const SolveReport r = solve(t, makeSeeding(t).seed, SolveOptions{});
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[0].name, "penalty");
  EXPECT_EQ(r.stages[0].status, "Stopped_At_Feasible_Point");
  EXPECT_LE(r.stages[0].largest_product, p.complementarity_tolerance);
  EXPECT_LT(r.stages[0].iterations, 200);
  EXPECT_EQ(r.stages[1].name, "task");
  EXPECT_TRUE(r.converged) << r.stages[1].status << ": " << r.note;
  EXPECT_NEAR(r.objective, 0.1, 1e-3);  // x_m: the drop's start
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);

  p.penalty_iterations = 1;
  const Transcription capped(p, Method::Impulsive);
  const SolveReport c = solve(capped, makeSeeding(capped).seed, SolveOptions{});
  p.penalty_iterations = 0;
  const Transcription plain(p, Method::Impulsive);
  const SolveReport without = solve(plain, makeSeeding(plain).seed, SolveOptions{});
  ASSERT_EQ(c.stages.size(), without.stages.size() + 1);
  EXPECT_EQ(c.stages[0].name, "penalty");
  EXPECT_EQ(c.stages[0].status, "Maximum_Iterations_Exceeded");
  EXPECT_EQ(c.stages[0].iterations, 1);
  EXPECT_GT(c.stages[0].largest_product, p.complementarity_tolerance);
  for (std::size_t i = 0; i < without.stages.size(); ++i) {
    EXPECT_EQ(c.stages[i + 1].name, without.stages[i].name);
    EXPECT_EQ(c.stages[i + 1].iterations, without.stages[i].iterations) << without.stages[i].name;
  }
  EXPECT_EQ(c.x, without.x);
  EXPECT_TRUE(c.converged) << c.stages.back().status << ": " << c.note;
  EXPECT_NEAR(c.objective, 0.1, 1e-3);
}

// The task stage in the penalty form (Problem::task_penalty): the products in its cost, not
// bounded. Its result is still a point with every product within the tolerance: the drop of the
// test above lands at the analytic time with the same x_m.
TEST(Solver, ATaskStageWithTheProductsInItsCostEndsFeasible) {
  Problem p = penaltyStageDrop();
  p.task_penalty = true;
  const Transcription t(p, Method::Impulsive);
  const SolveReport r = solve(t, makeSeeding(t).seed, SolveOptions{});
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[1].name, "task");
  EXPECT_TRUE(r.feasible) << r.stages[1].status << ": " << r.note;
  EXPECT_LE(r.largest_product, p.complementarity_tolerance);
  EXPECT_NEAR(r.objective, 0.1, 1e-3);
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);
}

}  // namespace
}  // namespace saltus::collocation
