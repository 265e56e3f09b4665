// How a problem file says to solve it (collocation/problem_file_solve.cpp): the `solve` section
// with each method's own penalty keys, and the `ipopt` and `task_ipopt` sections, read from the
// full fixture (tests/data/problems/full.yaml) and from fixtures broken on purpose (the offending
// line marked `# <-- error`), whose message must name the file, the line and the key path, and say
// what was expected.
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collocation/problem_file.hpp"
#include "saltus/build_paths.hpp"
#include "scene/scenario.hpp"
#include "tests/support/errors.hpp"
#include "tests/support/problem_errors.hpp"

// A namespace of its own: the unity build may join this file with the other problem-file tests.
namespace saltus::collocation::problem_file_solve {
namespace {

const std::string& kDataDir = testing::kProblemDataDir;

using testing::expectProblemError;

TEST(ProblemFileSolve, EveryKeyOfTheFullFixture) {
  const std::string path = kDataDir + "full.yaml";
  const Problem p = loadProblem(path);
  EXPECT_EQ(p.complementarity_tolerance, 1e-5);
  EXPECT_FALSE(p.task_stage);
  EXPECT_EQ(p.seed_kind, SeedKind::Solution);
  EXPECT_EQ(p.seed_scale, 0.2);
  EXPECT_EQ(p.random_seed, 7u);
  EXPECT_EQ(p.resimulations, 3);
  EXPECT_EQ(p.resimulation_tracking, 15);
  EXPECT_EQ(p.seed_solution, kDataDir + "earlier/run");      // relative to the problem file
  EXPECT_EQ(p.seed_inputs, kDataDir + "scripts/push.csv");   // relative to the problem file as well
  EXPECT_EQ(p.seed_inputs_origin,
            path + ":" + std::to_string(testing::lineOf(path, "seed_inputs:")) + ": solve.seed_inputs");
  EXPECT_FALSE(p.exact_hessian);              // hessian: every stage's,
  EXPECT_TRUE(p.feasibility_exact_hessian);   // then feasibility_hessian for the feasibility stage
  EXPECT_TRUE(p.derivative_check);
  EXPECT_EQ(p.penalty_iterations, 300);
  EXPECT_TRUE(p.task_penalty);
  // solve.<method>: only the keys given (an empty map gives none).
  ASSERT_EQ(p.method_solve.size(), 2u);
  EXPECT_EQ(p.method_solve.at(Method::Impulsive).penalty_iterations, 250);
  EXPECT_FALSE(p.method_solve.at(Method::Impulsive).task_penalty);
  EXPECT_EQ(p.method_solve.at(Method::Impulsive).penalty_weight, 10.0);
  EXPECT_FALSE(p.method_solve.at(Method::FirstOrder).penalty_weight);
  EXPECT_FALSE(p.method_solve.at(Method::FirstOrder).penalty_iterations);
  EXPECT_EQ(p.method_solve.at(Method::FirstOrder).task_penalty, false);
  EXPECT_EQ(p.ipopt_options, (std::map<std::string, std::string>{
                                 {"tol", "1e-8"}, {"max_iter", "500"}, {"mu_strategy", "adaptive"}}));
  EXPECT_EQ(p.task_ipopt_options,
            (std::map<std::string, std::string>{{"obj_scaling_factor", "10"}, {"max_iter", "200"}}));
}

TEST(ProblemFileSolve, UnknownHessian) {
  expectProblemError("bad_hessian.yaml", "solve.feasibility_hessian",
              {"unknown hessian 'limited_memory'", "did you mean 'limited-memory'", "expected one of: exact, limited-memory"});
}
TEST(ProblemFileSolve, NegativePenaltyIterations) {
  expectProblemError("bad_penalty_iterations.yaml", "solve.penalty_iterations",
              {"expected a non-negative iteration count", "got -5"});
}
TEST(ProblemFileSolve, NegativeResimulations) {
  expectProblemError("bad_resimulations.yaml", "solve.resimulations", {"expected a non-negative integer", "got -2"});
}
TEST(ProblemFileSolve, NegativeResimulationTracking) {
  expectProblemError("bad_resimulation_tracking.yaml", "solve.resimulation_tracking",
                     {"expected a natural frequency >= 0 rad/s", "got -30"});
}
TEST(ProblemFileSolve, AMethodsOwnPenaltyKeys) {
  expectProblemError("bad_method_solve.yaml", "solve.continuous.penalty_iterations",
              {"expected a non-negative iteration count", "got -1"});
  expectProblemError("bad_method_solve_key.yaml", "solve.first-order.restarts",
              {"unknown key 'restarts'", "expected one of: penalty_iterations, task_penalty, penalty_weight"});
  expectProblemError("bad_method_penalty_weight.yaml", "solve.impulsive.penalty_weight",
              {"a weight must be non-negative", "got -10"});
}
// solve.continuation: each step's values (expressions of the parameters in use) and its problem,
// read again with them; a step's problem has no continuation of its own.
TEST(ProblemFileSolve, AContinuationsStepsAreTheProblemWithTheirValues) {
  const std::string path = kDataDir + "continuation.yaml";
  const Problem p = loadProblem(path);
  ASSERT_EQ(p.continuation.size(), 2u);
  EXPECT_EQ(p.continuation[0].parameters, (std::map<std::string, double>{{"g", 9.81 / 2}, {"limit", 4}}));
  EXPECT_EQ(p.continuation[1].parameters, (std::map<std::string, double>{{"limit", 3}}));
  const Problem& half = *p.continuation[0].problem;
  EXPECT_NEAR(half.scene.model.gravity.z(), -9.81 / 2, 1e-12);  // the scene's parameter
  EXPECT_NEAR(half.input_upper[0], p.input_upper[0], 1e-9);     // 4 × 36.5 × 4.905 = 2 × 36.5 × 9.81 N
  EXPECT_TRUE(half.continuation.empty());
  const Problem& third = *p.continuation[1].problem;
  EXPECT_NEAR(third.scene.model.gravity.z(), -9.81, 1e-12);
  EXPECT_NEAR(third.input_upper[0], 3 * 36.5 * 9.81, 1e-9);
  EXPECT_EQ(third.parameters.at("limit"), 3);
  EXPECT_NEAR(p.input_upper[0], 2 * 36.5 * 9.81, 1e-9);  // the problem itself unchanged
  // --set values are the steps' starting values, and stay in every step unless it changes them.
  const Problem set = loadProblem(path, {{"limit", 1}, {"rider_mass", 40}});
  EXPECT_EQ(set.continuation[0].parameters.at("limit"), 2);
  EXPECT_NEAR(set.continuation[0].problem->input_upper[0], 2 * 40 * 9.81 / 2, 1e-9);
  EXPECT_NEAR(set.continuation[1].problem->input_upper[0], 3 * 40 * 9.81, 1e-9);
}
TEST(ProblemFileSolve, AContinuationStepNamingNoParameter) {
  expectProblemError("bad_continuation_parameter.yaml", "solve.continuation[0].heigth",
                     {"no parameter 'heigth'", "did you mean 'height'", "the parameters are: height"});
}
TEST(ProblemFileSolve, AnEmptyContinuationStep) {
  expectProblemError("bad_continuation_empty.yaml", "solve.continuation[1]", {"a step changes at least one parameter"});
}
TEST(ProblemFileSolve, SeedSolutionWithoutPath) {
  expectProblemError("seed_solution_missing.yaml", "solve.seed_solution", {"seed: solution needs seed_solution"});
}

// Ipopt's options are checked against Ipopt's own registry when the file is read, not when the
// solve starts; the two it has keys of its own for are refused with the key to use.
TEST(ProblemFileSolve, AnIpoptOptionTheFileHasAKeyFor) {
  expectProblemError("bad_ipopt_owned.yaml", "ipopt.hessian_approximation", {"set this through solve.hessian instead"});
}
TEST(ProblemFileSolve, AnUnknownIpoptOption) {
  expectProblemError("bad_ipopt_unknown.yaml", "ipopt.mu_stratgy", {"unknown Ipopt option 'mu_stratgy'"});
}
TEST(ProblemFileSolve, AnIpoptValueOfTheWrongType) {
  expectProblemError("bad_ipopt_value.yaml", "task_ipopt.max_iter",
              {"Ipopt option 'max_iter': invalid value 'many'", "expected an integer"});
}
TEST(ProblemFileSolve, AnIpoptValueThatIsNotAScalar) {
  expectProblemError("bad_ipopt_nested.yaml", "ipopt.tol", {"expected the option's value (a number or a word)"});
}

}  // namespace
}  // namespace saltus::collocation::problem_file_solve
