// The solver's repeats of the feasibility stage (SolveOptions::feasibility_repeats): a stage that
// Ipopt solved to its tolerance at a local minimum of the penalty above the tolerance runs again
// from its end, warm, under the caller's bound push; not after a stage ended at Ipopt's acceptable
// level or stopped at its limit, and not once feasible.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/solution.hpp"
#include "collocation/solver.hpp"
#include "tests/support/drop_checks.hpp"
#include "tests/support/near_miss_drop.hpp"

namespace saltus::collocation {
namespace {

using testing::checkDrop;
using testing::nearMissDrop;
using testing::Solved;

// Without the tightening, so that a stage's end is the solve's result.
SolveOptions untightened() {
  SolveOptions o;
  o.tighten_within = 0;
  return o;
}

// The stage's end from the problem's own seeding, untightened: on the near miss a local minimum of
// the penalty above the tolerance.
SolveReport untightenedEnd(const Transcription& t) { return solve(t, makeSeeding(t).seed, untightened()); }

// A solve's end as a warm seed that keeps its warm start, as a continuation's last step hands over.
SeedFunction warmFrom(const SolveReport& r) {
  return [x = r.x](int) { return Seed{x, true, true, true}; };
}

// The near miss's local minimum (products 1.5e-4, constraints met) as a warm seed that keeps its
// warm start, as a continuation's last step hands over: its first stage starts at μ₀ = 1e-4, 1e-6
// inside its bounds, whatever the caller's options, and ends at the same minimum. A repeat is warm
// without that: under the caller's barrier start (1e-2) and bound push (0.05) it leaves the
// minimum and, untightened, reaches the drop, which lands at the analytic time. Without the repeat
// the solve ends at the minimum.
TEST(Solver, ARepeatedFeasibilityStageLeavesALocalMinimumAboveTheTolerance) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const SolveReport near = untightenedEnd(t);
  ASSERT_FALSE(near.feasible);
  ASSERT_EQ(near.stages.at(0).status, "Solve_Succeeded");
  ASSERT_GT(near.largest_product, p.complementarity_tolerance);

  const SeedFunction warm = warmFrom(near);
  SolveOptions caller = untightened();
  caller.ipopt = {{"mu_init", "1e-2"}, {"bound_push", "0.05"}, {"bound_frac", "0.05"}};
  const SolveReport stuck = solve(t, warm, caller);
  ASSERT_EQ(stuck.stages.size(), 1u);
  EXPECT_FALSE(stuck.feasible);
  EXPECT_EQ(stuck.stages[0].status, "Solve_Succeeded");
  EXPECT_GT(stuck.largest_product, p.complementarity_tolerance);

  SolveOptions repeated = caller;
  repeated.feasibility_repeats = 3;
  const SolveReport r = solve(t, warm, repeated);
  ASSERT_EQ(r.stages.size(), 2u);  // the first repeat is feasible: no more
  EXPECT_EQ(r.stages[0].name, "feasibility");
  EXPECT_EQ(r.stages[0].iterations, stuck.stages[0].iterations);
  EXPECT_EQ(r.stages[1].name, "feasibility");
  EXPECT_EQ(r.stages[1].barrier, "monotone");  // warm
  EXPECT_EQ(r.kept_stage, 1);
  EXPECT_TRUE(r.feasible) << r.stages[1].status << ", largest product " << r.largest_product;
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, r.stages[0].iterations + r.stages[1].iterations);
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);

  // A repeat that ends at higher products (here under μ₀ = 1e-3 and a push of 0.1, at 3e-3) ends
  // the repeats, and the point before it is the result, as the note says.
  caller.ipopt = {{"mu_init", "1e-3"}, {"bound_push", "0.1"}, {"bound_frac", "0.1"}};
  caller.feasibility_repeats = 3;
  const SolveReport farther = solve(t, warm, caller);
  ASSERT_EQ(farther.stages.size(), 2u);
  EXPECT_GT(farther.stages[1].largest_product, farther.stages[0].largest_product);
  EXPECT_EQ(farther.kept_stage, 0);
  EXPECT_FALSE(farther.feasible);
  EXPECT_EQ(farther.largest_product, farther.stages[0].largest_product);
  EXPECT_EQ(farther.x, stuck.x);
  EXPECT_NE(farther.note.find("no lower; kept the point before it"), std::string::npos) << farther.note;
}

// A stage that Ipopt ends at its acceptable level above the tolerance is not repeated (on the
// full-body Ollie's quarter-gravity sweep repeating those lost more seeds than it rescued, README).
// Under tolerances it cannot reach (tol and constr_viol_tol 1e-30) and with the first acceptable
// iterate ending it (acceptable_iter 1), the near miss's warm stage stops at the acceptable level at
// its local minimum whatever path the linear algebra takes (with the solver's 10 acceptable iterates
// in a row it did on an AMD EPYC, and ended Infeasible_Problem_Detected on an Intel Xeon); with
// repeats allowed, under the barrier start and bound push with which a repeat of a solved stage
// leaves that minimum (the first test), the solve is still that one stage.
TEST(Solver, AStageEndedAtTheAcceptableLevelIsNotRepeated) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const SolveReport near = untightenedEnd(t);
  ASSERT_FALSE(near.feasible);

  const SeedFunction warm = warmFrom(near);
  SolveOptions caller = untightened();
  caller.ipopt = {{"mu_init", "1e-2"}, {"bound_push", "0.05"}, {"bound_frac", "0.05"}, {"tol", "1e-30"},
                  {"constr_viol_tol", "1e-30"}, {"acceptable_iter", "1"}};
  const SolveReport stuck = solve(t, warm, caller);
  ASSERT_EQ(stuck.stages.size(), 1u);
  ASSERT_EQ(stuck.stages[0].status, "Solved_To_Acceptable_Level");
  ASSERT_FALSE(stuck.feasible);
  ASSERT_GT(stuck.largest_product, p.complementarity_tolerance);

  caller.feasibility_repeats = 3;
  const SolveReport r = solve(t, warm, caller);
  ASSERT_EQ(r.stages.size(), 1u);
  EXPECT_EQ(r.stages[0].iterations, stuck.stages[0].iterations);
  EXPECT_EQ(r.x, stuck.x);
  EXPECT_FALSE(r.feasible);
}

// The result's note tells each stage's end in turn. A repeat stopped at its iteration limit (70
// here) below the products it started from, with the constraints still 6e-5 off, is "lower but not
// solved". On the drop with a task cost the repeat ends no lower, and the tightening and the task
// stage both fail after it: each adds its remark, and none replaces the one before it.
TEST(Solver, TheNoteTellsEachStagesEnd) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const SeedFunction warm = warmFrom(untightenedEnd(t));
  SolveOptions limited = untightened();
  limited.feasibility_repeats = 1;
  limited.ipopt = {{"mu_init", "1e-2"}, {"bound_push", "0.05"}, {"bound_frac", "0.05"}, {"max_iter", "70"}};
  const SolveReport unsolved = solve(t, warm, limited);
  ASSERT_EQ(unsolved.stages.size(), 2u);
  ASSERT_EQ(unsolved.stages[1].status, "Maximum_Iterations_Exceeded");
  ASSERT_LT(unsolved.stages[1].largest_product, unsolved.stages[0].largest_product);
  ASSERT_GT(unsolved.stages[1].largest_violation, SolveOptions{}.violation_tolerance);
  EXPECT_EQ(unsolved.kept_stage, 0);
  EXPECT_NE(unsolved.note.find("repeat ended Maximum_Iterations_Exceeded"), std::string::npos) << unsolved.note;
  EXPECT_NE(unsolved.note.find("lower but not solved; kept the point before it"), std::string::npos)
      << unsolved.note;

  Problem task_problem = nearMissDrop();
  testing::withHeightCost(task_problem);
  const Transcription task(task_problem, Method::Impulsive);
  const SeedFunction task_warm = warmFrom(untightenedEnd(task));
  SolveOptions repeated;
  repeated.feasibility_repeats = 1;
  repeated.ipopt = {{"mu_init", "1e-3"}, {"bound_push", "0.1"}, {"bound_frac", "0.1"}};
  const SolveReport r = solve(task, task_warm, repeated);
  ASSERT_GE(r.stages.size(), 4u);
  EXPECT_FALSE(r.feasible);
  EXPECT_EQ(r.kept_stage, 0);
  const std::vector<std::string> remarks = {"repeat ended Solve_Succeeded", "no lower; kept the point before it",
                                            "the tightening stage ended", "the task stage ended"};
  std::size_t at = 0;
  for (const std::string& remark : remarks) {
    const std::size_t found = r.note.find(remark, at);
    EXPECT_NE(found, std::string::npos) << "'" << remark << "' after character " << at << " of: " << r.note;
    if (found != std::string::npos) at = found + remark.size();
  }
}

// A stage that Ipopt did not solve is not repeated (the tightening takes a stage stopped on its
// way down), nor is one that ends feasible. With the repeat's own bound push the near miss's cold
// stage is feasible at once: the repeats change nothing.
TEST(Solver, OnlyASolvedStageAboveTheToleranceIsRepeated) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions limited = untightened();
  limited.feasibility_repeats = 2;
  limited.ipopt["max_iter"] = "5";
  const SolveReport stopped = solve(t, seeding.seed, limited);
  ASSERT_EQ(stopped.stages.size(), 1u);
  EXPECT_EQ(stopped.stages[0].status, "Maximum_Iterations_Exceeded");
  EXPECT_FALSE(stopped.feasible);

  SolveOptions pushed = untightened();
  pushed.ipopt = {{"bound_push", "0.01"}, {"bound_frac", "0.01"}};
  const SolveReport once = solve(t, seeding.seed, pushed);
  ASSERT_TRUE(once.feasible) << once.stages[0].status << ", largest product " << once.largest_product;
  pushed.feasibility_repeats = 2;
  const SolveReport same = solve(t, seeding.seed, pushed);
  ASSERT_EQ(same.stages.size(), 1u);
  EXPECT_EQ(same.stages[0].iterations, once.stages[0].iterations);
  EXPECT_EQ(same.x, once.x);
}

}  // namespace
}  // namespace saltus::collocation
