// saltus/optimize.cpp: the library API's solve and its files. The paper's point-mass drop
// (e = 0.5, h = 0.1 m) through the API: the velocity jumps from −sqrt(2 g h) to e sqrt(2 g h) at
// sqrt(2 h / g); saveSolution writes the three files, summary.json says what the result object
// says, and the saved variables read back (collocation/saved_solution.hpp) are the solution.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "collocation/saved_solution.hpp"
#include "collocation/seeding.hpp"
#include "saltus/saltus.hpp"
#include "tests/support/near_miss_drop.hpp"

namespace {

namespace fs = std::filesystem;

class ApiOptimize : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("saltus_api_optimize_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    const saltus::collocation::Problem problem = saltus::loadProblem("point_mass_drop", {{"restitution", 0.5}});
    result_ = new saltus::OptimizeResult(saltus::optimize(problem, saltus::OptimizeOptions{}));
    saltus::saveSolution(dir_.string(), *result_);
  }
  static void TearDownTestSuite() {
    delete result_;
    fs::remove_all(dir_);
  }
  static fs::path dir_;
  static saltus::OptimizeResult* result_;
};
fs::path ApiOptimize::dir_;
saltus::OptimizeResult* ApiOptimize::result_ = nullptr;

TEST_F(ApiOptimize, TheDropBouncesWithNewtonsRestitution) {
  const saltus::OptimizeResult& r = *result_;
  ASSERT_TRUE(r.feasible()) << r.report.stages.back().status;
  const double g = 9.81, h = 0.1, speed = std::sqrt(2 * g * h), t_impact = std::sqrt(2 * h / g);
  // The largest downward and upward speeds are the ones just before and just after the impact.
  double down = 0, up = 0, t_down = 0;
  for (const saltus::collocation::Sample& s : r.samples) {
    if (s.v[0] < down) {
      down = s.v[0];
      t_down = s.t;
    }
    up = std::max(up, s.v[0]);
  }
  EXPECT_NEAR(down, -speed, 1e-3 * speed);
  EXPECT_NEAR(up, 0.5 * speed, 1e-3 * speed);
  EXPECT_NEAR(t_down, t_impact, 1e-3);
  EXPECT_EQ(&r.problem(), &r.transcription->problem());
  EXPECT_EQ(r.problem().parameters.at("restitution"), 0.5);
}

TEST_F(ApiOptimize, TheSavedFilesAreTheResult) {
  const saltus::OptimizeResult& r = *result_;
  for (const char* f : {"trajectory.csv", "variables.csv", "summary.json"}) EXPECT_TRUE(fs::exists(dir_ / f)) << f;
  std::ifstream in(dir_ / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("problem"), "point_mass_drop");
  EXPECT_EQ(j.at("method"), "impulsive");
  EXPECT_EQ(j.at("feasible").get<bool>(), r.feasible());
  EXPECT_EQ(j.at("iterations").get<int>(), r.report.iterations);
  EXPECT_EQ(j.at("largest_product").get<double>(), r.report.largest_product);
  EXPECT_EQ(j.at("stages").size(), r.report.stages.size());
  EXPECT_EQ(j.at("stages").back().at("status"), r.report.stages.back().status);
  ASSERT_EQ(j.at("kept_stage").get<int>(), r.report.kept_stage);
  ASSERT_GE(r.report.kept_stage, 0);
  EXPECT_EQ(j.at("status"), j.at("stages").at(r.report.kept_stage).at("status"));
  EXPECT_EQ(j.at("parameters").at("restitution").get<double>(), 0.5);
  EXPECT_EQ(j.dump(2) + "\n", nlohmann::json::parse(saltus::summaryJson(r)).dump(2) + "\n");

  const saltus::collocation::SavedSolution saved = saltus::collocation::loadSolution(dir_.string());
  ASSERT_EQ(saved.x.size(), r.report.x.size());
  EXPECT_LE((saved.x - r.report.x).cwiseAbs().maxCoeff(), 1e-12 * (1 + r.report.x.cwiseAbs().maxCoeff()));
}

// A hint the motion cannot meet (the drop's ball on the ground at [2, 0], t ≤ 0.04 s after its
// release from 0.1 m): the solve ends infeasible, and summary.json counts the hints imposed and
// reports each one's reach; without the hints (--no-hints) the same problem solves.
TEST(ApiOptimizeHints, AnUnreachableHintIsReportedAndDroppedByNoHints) {
  saltus::collocation::Problem p = saltus::loadProblem("point_mass_drop", {});
  saltus::collocation::PointBound hint;
  hint.quantity = {saltus::collocation::Quantity::Kind::Gap, 0};
  hint.element = 1;
  hint.point = 0;
  hint.lower = hint.upper = 0;
  hint.origin = "test";
  p.hints.push_back(hint);
  saltus::OptimizeOptions options;
  options.restarts = 0;
  const saltus::OptimizeResult hinted = saltus::optimize(p, options);
  ASSERT_FALSE(hinted.feasible());
  const nlohmann::json j = nlohmann::json::parse(saltus::summaryJson(hinted));
  EXPECT_EQ(j.at("hints_used").get<int>(), 1);
  ASSERT_EQ(j.at("hints").size(), 1u);
  EXPECT_EQ(j.at("hints")[0].at("origin"), "test");
  EXPECT_FALSE(j.at("hints")[0].at("reachable").get<bool>());
  EXPECT_FALSE(j.at("hints")[0].at("actuated").get<bool>());  // the drop has no inputs: it cannot be met
  options.hints = false;
  const saltus::OptimizeResult unhinted = saltus::optimize(p, options);
  EXPECT_TRUE(unhinted.feasible());
  const nlohmann::json u = nlohmann::json::parse(saltus::summaryJson(unhinted));
  EXPECT_EQ(u.at("hints_used").get<int>(), 0);
  EXPECT_FALSE(u.contains("hints"));
}

TEST_F(ApiOptimize, AMethodThatCannotRepresentTheProblemIsRefused) {
  // The continuous-velocity method admits e = 0 only.
  const saltus::collocation::Problem problem = saltus::loadProblem("point_mass_drop", {{"restitution", 0.5}});
  saltus::OptimizeOptions options;
  options.method = saltus::collocation::Method::Continuous;
  EXPECT_THROW(saltus::optimize(problem, options), std::invalid_argument);
}

// adjustedProblem's refusal of the options, or "accepted".
std::string adjustError(const saltus::collocation::Problem& problem, const saltus::OptimizeOptions& options) {
  try {
    saltus::adjustedProblem(problem, options);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

// A two-step solve (OptimizeOptions::seed_method) is the first method's solve, then the second
// method's from its solution as --seed-from would give it (unperturbed): the same point to the
// last digit. Both cut at 20 iterations of the feasibility stage (the second solve starts from the
// first's end, feasible or not); the result counts both solves.
TEST(ApiOptimizeTwoStep, IsTheSecondSolveFromTheFirstsSolution) {
  const saltus::collocation::Problem problem = saltus::loadProblem("point_mass_throw", {});
  saltus::OptimizeOptions options;
  options.seed_method = saltus::collocation::Method::FirstOrder;
  options.restarts = 0;
  options.solve.ipopt["max_iter"] = "20";
  options.solve.tighten_within = 0;
  options.solve.task_max_iter = 0;
  const saltus::OptimizeResult r = saltus::optimize(problem, options);
  EXPECT_EQ(r.transcription->method(), saltus::collocation::Method::Impulsive);
  ASSERT_TRUE(r.seed_solve);
  EXPECT_EQ(r.seed_solve->transcription->method(), saltus::collocation::Method::FirstOrder);
  const fs::path dir = fs::temp_directory_path() / ("saltus_api_two_step_" + std::to_string(::getpid()));
  saltus::saveSolution(dir.string(), *r.seed_solve);
  saltus::OptimizeOptions by_hand = options;
  by_hand.seed_method.reset();
  by_hand.seed_from = dir.string();
  by_hand.seed_scale = 0;
  const saltus::OptimizeResult second = saltus::optimize(problem, by_hand);
  fs::remove_all(dir);
  ASSERT_EQ(second.report.x.size(), r.report.x.size());
  EXPECT_EQ((second.report.x - r.report.x).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(second.report.stages.front().iterations, r.report.stages.front().iterations);
  int own = 0;
  for (const auto& s : r.report.stages) own += s.iterations;
  EXPECT_EQ(r.report.iterations, own + r.seed_solve->report.iterations);
  EXPECT_GT(r.report.wall_seconds, r.seed_solve->report.wall_seconds);
  const nlohmann::json j = nlohmann::json::parse(saltus::summaryJson(r));
  EXPECT_EQ(j.at("seed_method"), "first-order");
  EXPECT_EQ(j.at("seed_solve").at("iterations").get<int>(), r.seed_solve->report.iterations);
  EXPECT_EQ(j.at("seed_solve").at("feasible").get<bool>(), r.seed_solve->feasible());
  EXPECT_EQ(j.at("iterations").get<int>(), r.report.iterations);
  EXPECT_EQ(j.at("tighten_factor").get<double>(), 10.0);  // the default
  EXPECT_EQ(j.at("feasibility_repeats").get<int>(), 0);    // the default
  // Without a seed method, no such keys.
  EXPECT_FALSE(nlohmann::json::parse(saltus::summaryJson(*r.seed_solve)).contains("seed_solve"));

  saltus::OptimizeOptions same;
  same.seed_method = saltus::collocation::Method::Impulsive;
  EXPECT_EQ(adjustError(problem, same), "seed_method: expected another method than the solve's own (impulsive)");
  saltus::OptimizeOptions factor;
  factor.solve.tighten_factor = -1;
  EXPECT_EQ(adjustError(problem, factor), "tighten_factor: expected a finite non-negative factor (at most 1: one step)");
  saltus::OptimizeOptions repeats;
  repeats.solve.feasibility_repeats = -1;
  EXPECT_EQ(adjustError(problem, repeats), "feasibility_repeats: expected a non-negative integer, got -1");
  saltus::OptimizeOptions both = options;
  both.seed_from = "/some/solution";
  EXPECT_EQ(adjustError(problem, both).rfind("seed_method: not with seed_from", 0), 0u);
  const saltus::collocation::Problem bouncing = saltus::loadProblem("point_mass_drop", {{"restitution", 0.5}});
  EXPECT_EQ(adjustError(bouncing, options).rfind("seed_method: the first-order method cannot represent restitution", 0), 0u)
      << adjustError(bouncing, options);
}

// The bouncing drop (restitution 0.5) with one continuation step that is the problem itself.
saltus::collocation::Problem withItselfAsAStep(saltus::collocation::Problem problem) {
  saltus::collocation::ContinuationStep itself;
  itself.parameters = {{"restitution", 0.5}};
  itself.problem = std::make_shared<const saltus::collocation::Problem>(problem);
  problem.continuation = {itself};
  return problem;
}

// A continuation (Problem::continuation) carries each attempt's seed through its steps, a
// feasibility stage on each, and the solve starts from the last end, warm and without hints. With
// one step that is the problem itself (the bouncing drop, e = 0.5, from its simulation seed)
// the step's stage is the plain solve's feasibility stage, iteration for iteration, and the solve
// is the one from that stage's end done by hand, to the last digit. The result counts the step.
TEST(ApiOptimizeContinuation, EachSeedIsCarriedThroughTheSteps) {
  using saltus::collocation::Problem;
  namespace c = saltus::collocation;
  Problem problem = withItselfAsAStep(saltus::loadProblem("point_mass_drop", {{"restitution", 0.5}}));
  const c::ContinuationStep& itself = problem.continuation[0];
  saltus::OptimizeOptions options;
  options.restarts = 0;
  const saltus::OptimizeResult r = saltus::optimize(problem, options);
  ASSERT_EQ(r.continuation.size(), 1u);
  const saltus::ContinuationStepReport& step = r.continuation[0];
  EXPECT_EQ(step.attempt, 0);
  EXPECT_EQ(step.step, 0);
  EXPECT_EQ(step.stage.name, "feasibility");
  EXPECT_TRUE(r.feasible()) << r.report.keptStage().status << ", products " << r.report.largest_product << " at "
                            << r.report.largest_product_at << ", constraints " << r.report.largest_violation << " off at "
                            << r.report.largest_violation_at << "; the step's products " << step.stage.largest_product;

  saltus::OptimizeOptions plain_options = options;
  plain_options.continuation = false;
  const saltus::OptimizeResult plain = saltus::optimize(problem, plain_options);
  EXPECT_TRUE(plain.continuation.empty());
  EXPECT_EQ(plain.report.stages.front().iterations, step.stage.iterations);
  EXPECT_EQ(plain.report.stages.front().largest_product, step.stage.largest_product);

  // By hand: the step's feasibility stage from the seed, then the solve from its end.
  const c::Transcription& t = *r.transcription;
  const c::Seed seed = c::makeSeeding(t).seed(0);
  c::SolveOptions only = options.solve;
  only.feasibility_only = true;
  only.warm_seed = seed.warm;
  const Eigen::VectorXd end = c::solve(t, seed.x, only).x;
  c::SolveOptions rest = options.solve;
  const c::SolveReport by_hand = c::solve(t, [&](int) { return c::Seed{end, true, false, true}; }, rest);
  ASSERT_EQ(by_hand.x.size(), r.report.x.size());
  EXPECT_EQ((by_hand.x - r.report.x).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(by_hand.stages.front().iterations, r.report.stages.front().iterations);

  int own = 0;
  for (const auto& s : r.report.stages) own += s.iterations;
  EXPECT_EQ(r.report.iterations, own + step.stage.iterations);
  EXPECT_GT(r.report.wall_seconds, step.stage.wall_seconds);
  const nlohmann::json j = nlohmann::json::parse(saltus::summaryJson(r));
  ASSERT_EQ(j.at("continuation").size(), 1u);
  EXPECT_EQ(j.at("continuation")[0].at("parameters").at("restitution").get<double>(), 0.5);
  EXPECT_EQ(j.at("continuation")[0].at("iterations").get<int>(), step.stage.iterations);
  EXPECT_EQ(j.at("continuation")[0].at("status").get<std::string>(), step.stage.status);
  EXPECT_FALSE(nlohmann::json::parse(saltus::summaryJson(plain)).contains("continuation"));

  // From an earlier solution (a point of the problem already) there is no continuation.
  const fs::path dir = fs::temp_directory_path() / ("saltus_api_continuation_" + std::to_string(::getpid()));
  saltus::saveSolution(dir.string(), r);
  saltus::OptimizeOptions from = options;
  from.seed_from = dir.string();
  from.seed_scale = 0;
  const saltus::OptimizeResult again = saltus::optimize(problem, from);
  fs::remove_all(dir);
  EXPECT_TRUE(again.continuation.empty());
  EXPECT_TRUE(again.feasible());

  // A step whose transcription is not the problem's (another mesh) is refused before any solve.
  Problem remeshed = *itself.problem;
  saltus::collocation::remesh(remeshed, 10, remeshed.P);
  problem.continuation[0].problem = std::make_shared<const Problem>(remeshed);
  try {
    saltus::optimize(problem, options);
    ADD_FAILURE() << "a step of another mesh was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("continuation[0] (restitution = 0.5): its transcription has ", 0), 0u) << what;
    EXPECT_NE(what.find("not the mesh"), std::string::npos) << what;
  }
}

// The problem's own solve after a continuation takes the seed's hints in its first stage, as a
// solve from an earlier solution does (the later steps go without them). The bouncing drop with a
// hint that never binds (its speed at most 10 m/s at [1, 0]) and one step that is the problem
// itself: the solve is, to the last digit, the one by hand from the step's end with the hints, and
// not the one without them.
TEST(ApiOptimizeContinuation, TheProblemsOwnSolveKeepsTheSeedsHints) {
  using saltus::collocation::Problem;
  namespace c = saltus::collocation;
  Problem problem = saltus::loadProblem("point_mass_drop", {{"restitution", 0.5}});
  c::PointBound hint;
  hint.quantity = {c::Quantity::Kind::Velocity, 0};
  hint.element = 1;
  hint.point = 0;
  hint.upper = 10;
  hint.origin = "the test's hint";
  problem.hints = {hint};
  problem = withItselfAsAStep(problem);
  saltus::OptimizeOptions options;
  options.restarts = 0;
  const saltus::OptimizeResult r = saltus::optimize(problem, options);
  ASSERT_EQ(r.continuation.size(), 1u);
  EXPECT_TRUE(r.feasible()) << r.report.keptStage().status;

  const c::Transcription& t = *r.transcription;
  const c::Seed seed = c::makeSeeding(t).seed(0);
  ASSERT_TRUE(seed.hinted);
  c::SolveOptions only = options.solve;
  only.feasibility_only = true;
  only.warm_seed = seed.warm;
  const Eigen::VectorXd end = c::solve(t, seed.x, only).x;
  const auto from_end = [&](bool hinted) {
    return c::solve(t, [&](int) { return c::Seed{end, true, hinted, true}; }, options.solve);
  };
  const c::SolveReport with = from_end(true), without = from_end(false);
  ASSERT_EQ(with.x.size(), r.report.x.size());
  EXPECT_EQ((with.x - r.report.x).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(with.stages.front().iterations, r.report.stages.front().iterations);
  EXPECT_GT((without.x - r.report.x).cwiseAbs().maxCoeff(), 0.0) << "the hint changes the first stage";
}

// A step whose feasibility stage Ipopt solves at a local minimum above the tolerance is repeated
// from its end as the problem's own stage is (SolveOptions::feasibility_repeats), and the repeat's
// end seeds the solve. The near-miss drop (its stage from the perturbed simulation seed 5 ends so)
// with one step that is the problem itself: the step's two stages are, iteration for iteration,
// the feasibility stage and its repeat of the problem solved by hand; each is reported, the
// repeat kept; without the repeat the step is the one stage, kept. A step's repeat that is not
// kept is named in the solve's note.
TEST(ApiOptimizeContinuation, AStepSolvedAboveTheToleranceIsRepeated) {
  using saltus::collocation::Problem;
  namespace c = saltus::collocation;
  Problem problem = saltus::testing::nearMissDrop();
  c::ContinuationStep itself;
  itself.parameters = {{"restitution", 0}};
  itself.problem = std::make_shared<const Problem>(problem);
  problem.continuation = {itself};
  saltus::OptimizeOptions options;
  options.restarts = 0;
  options.solve.feasibility_repeats = 1;
  const saltus::OptimizeResult r = saltus::optimize(problem, options);
  ASSERT_EQ(r.continuation.size(), 2u);
  const c::StageReport& first = r.continuation[0].stage;
  const c::StageReport& repeat = r.continuation[1].stage;
  EXPECT_EQ(first.status, "Solve_Succeeded");
  EXPECT_GT(first.largest_product, problem.complementarity_tolerance);
  EXPECT_FALSE(r.continuation[0].kept);
  EXPECT_TRUE(r.continuation[1].kept);
  EXPECT_EQ(r.continuation[1].step, 0);
  EXPECT_EQ(repeat.name, "feasibility");
  EXPECT_LT(repeat.largest_product, first.largest_product);
  EXPECT_TRUE(r.feasible()) << r.report.keptStage().status << ", products " << r.report.largest_product;

  // By hand: the step's stage and its repeat, as the problem's own feasibility stage.
  const c::Transcription& t = *r.transcription;
  const c::Seed seed = c::makeSeeding(t).seed(0);
  c::SolveOptions only = options.solve;
  only.feasibility_only = true;
  only.warm_seed = seed.warm;
  const c::SolveReport by_hand = c::solve(t, seed.x, only);
  ASSERT_EQ(by_hand.stages.size(), 2u);
  EXPECT_EQ(by_hand.stages[0].iterations, first.iterations);
  EXPECT_EQ(by_hand.stages[1].iterations, repeat.iterations);
  EXPECT_EQ(by_hand.kept_stage, 1);
  const c::SolveReport rest =
      c::solve(t, [&](int) { return c::Seed{by_hand.x, true, false, true}; }, options.solve);
  EXPECT_EQ((rest.x - r.report.x).cwiseAbs().maxCoeff(), 0.0);

  // Both stages count in the totals and are in summary.json, the one kept marked.
  int own = 0;
  for (const auto& s : r.report.stages) own += s.iterations;
  EXPECT_EQ(r.report.iterations, own + first.iterations + repeat.iterations);
  const nlohmann::json j = nlohmann::json::parse(saltus::summaryJson(r));
  ASSERT_EQ(j.at("continuation").size(), 2u);
  EXPECT_FALSE(j.at("continuation")[0].at("kept").get<bool>());
  EXPECT_TRUE(j.at("continuation")[1].at("kept").get<bool>());
  EXPECT_EQ(j.at("continuation")[1].at("stage").get<std::string>(), "feasibility");
  EXPECT_EQ(j.at("continuation")[1].at("iterations").get<int>(), repeat.iterations);

  saltus::OptimizeOptions once = options;
  once.solve.feasibility_repeats = 0;
  const saltus::OptimizeResult unrepeated = saltus::optimize(problem, once);
  ASSERT_EQ(unrepeated.continuation.size(), 1u);
  EXPECT_TRUE(unrepeated.continuation[0].kept);
  EXPECT_EQ(unrepeated.continuation[0].stage.iterations, first.iterations);
  EXPECT_EQ(r.report.note.find("continuation["), std::string::npos) << r.report.note;

  // A step's repeat that ends no lower is not kept, and the step says so in the solve's note,
  // ahead of the problem's own remarks. Under μ₀ = 1e-2 and a push of 0.5 the first step ends at a
  // local minimum that its repeat lowers (kept); a second step, the problem once more, starts
  // there in that warm start and its repeat ends no lower.
  Problem twice = problem;
  twice.continuation = {itself, itself};
  saltus::OptimizeOptions pushed = options;
  pushed.solve.ipopt = {{"mu_init", "1e-2"}, {"bound_push", "0.5"}, {"bound_frac", "0.5"}};
  const saltus::OptimizeResult f = saltus::optimize(twice, pushed);
  ASSERT_EQ(f.continuation.size(), 4u);
  EXPECT_EQ(f.continuation[2].step, 1);
  EXPECT_EQ(f.continuation[3].step, 1);
  EXPECT_GT(f.continuation[2].stage.largest_product, problem.complementarity_tolerance);
  EXPECT_GE(f.continuation[3].stage.largest_product, f.continuation[2].stage.largest_product);
  EXPECT_TRUE(f.continuation[2].kept);
  EXPECT_FALSE(f.continuation[3].kept);
  EXPECT_EQ(f.report.note.rfind("continuation[1] of attempt 0: the feasibility stage's repeat ended ", 0), 0u)
      << f.report.note;
  EXPECT_NE(f.report.note.find("no lower; kept the point before it"), std::string::npos) << f.report.note;
  EXPECT_EQ(f.report.note.find("continuation[0]"), std::string::npos) << f.report.note;  // its repeat kept
  EXPECT_EQ(nlohmann::json::parse(saltus::summaryJson(f)).at("note").get<std::string>(), f.report.note);
}

// A problem file's solve.<method> keys (Problem::method_solve) take the place of the problem's
// own for a solve with that method only, and a solve's options come after them.
TEST(ApiProblemOptions, AMethodsOwnPenaltyKeysApplyToItsSolvesOnly) {
  using saltus::collocation::Method;
  saltus::collocation::Problem problem = saltus::loadProblem("point_mass_drop", {});
  problem.penalty_iterations = 100;
  problem.cost.penalty_weight = 2;
  problem.method_solve[Method::Impulsive] = {300, true, 10.0};
  problem.method_solve[Method::FirstOrder].task_penalty = true;
  saltus::OptimizeOptions options;
  const auto adjusted = [&](Method m) {
    options.method = m;
    const saltus::collocation::Problem a = saltus::adjustedProblem(problem, options);
    EXPECT_TRUE(a.method_solve.empty());  // applied
    EXPECT_EQ(a.cost.penalty_weight, m == Method::Impulsive ? 10.0 : 2.0);
    return std::pair{a.penalty_iterations, a.task_penalty};
  };
  EXPECT_EQ(adjusted(Method::Impulsive), std::pair(300, true));
  EXPECT_EQ(adjusted(Method::Continuous), std::pair(100, false));  // none of its own
  EXPECT_EQ(adjusted(Method::FirstOrder), std::pair(100, true));   // only the key it gives
  options.penalty_iterations = 0;
  options.task_penalty = false;
  EXPECT_EQ(adjusted(Method::Impulsive), std::pair(0, false));  // the options last
  // A solve with the method's own keys starts with the penalty stage, and summary.json records
  // the values it was solved with.
  problem.method_solve[Method::Impulsive] = {50, false, 3.0};
  saltus::OptimizeOptions solve;
  solve.restarts = 0;
  const saltus::OptimizeResult r = saltus::optimize(problem, solve);
  ASSERT_FALSE(r.report.stages.empty());
  EXPECT_EQ(r.report.stages.front().name, "penalty");
  EXPECT_LE(r.report.stages.front().iterations, 50);
  const nlohmann::json j = nlohmann::json::parse(saltus::summaryJson(r));
  EXPECT_EQ(j.at("penalty_iterations").get<int>(), 50);
  EXPECT_FALSE(j.at("task_penalty").get<bool>());
  EXPECT_EQ(j.at("penalty_weight").get<double>(), 3.0);
}

TEST(ApiProblemOptions, ChangesAreAppliedAndBadOnesNamed) {
  const saltus::collocation::Problem problem = saltus::loadProblem("point_mass_drop", {});
  saltus::OptimizeOptions options;
  options.N = 10;
  options.P = 3;
  options.random_seed = 7;
  options.seed_scale = 0.25;
  options.restarts = 2;
  options.exact_hessian = false;
  const saltus::collocation::Problem adjusted = saltus::adjustedProblem(problem, options);
  EXPECT_EQ(adjusted.N, 10);
  EXPECT_EQ(adjusted.P, 3);
  EXPECT_EQ(adjusted.random_seed, 7u);
  EXPECT_EQ(adjusted.seed_scale, 0.25);
  EXPECT_EQ(adjusted.restarts, 2);
  EXPECT_FALSE(adjusted.exact_hessian);  // every stage's
  EXPECT_FALSE(adjusted.feasibility_exact_hessian);
  options.feasibility_exact_hessian = true;  // then the feasibility stage's
  const saltus::collocation::Problem mixed = saltus::adjustedProblem(problem, options);
  EXPECT_FALSE(mixed.exact_hessian);
  EXPECT_TRUE(mixed.feasibility_exact_hessian);
  // hints = false (--no-hints) drops the problem's hints; the default keeps them.
  const saltus::collocation::Problem hinted = saltus::loadProblem("ollie_simple", {});
  ASSERT_FALSE(hinted.hints.empty());
  EXPECT_EQ(saltus::adjustedProblem(hinted, saltus::OptimizeOptions{}).hints.size(), hinted.hints.size());
  saltus::OptimizeOptions unhinted;
  unhinted.hints = false;
  EXPECT_TRUE(saltus::adjustedProblem(hinted, unhinted).hints.empty());
  EXPECT_EQ(saltus::adjustedProblem(hinted, unhinted).bounds.size(), hinted.bounds.size());
  auto message = [&](const saltus::OptimizeOptions& o) { return adjustError(problem, o); };
  saltus::OptimizeOptions bad;
  bad.P = 12;
  EXPECT_EQ(message(bad).rfind("P: expected an order from 1 to 9, got 12", 0), 0u);
  bad = {};
  bad.N = 0;
  EXPECT_EQ(message(bad).rfind("N: ", 0), 0u);
  bad = {};
  bad.seed_kind = saltus::collocation::SeedKind::Solution;
  EXPECT_EQ(message(bad).rfind("seed_kind: ", 0), 0u);
  bad = {};
  bad.seed_scale = -1;
  EXPECT_EQ(message(bad).rfind("seed_scale: ", 0), 0u);
  bad = {};
  bad.restarts = -1;
  EXPECT_EQ(message(bad).rfind("restarts: ", 0), 0u);
  for (int level : {-5, 13, 99}) {
    bad = {};
    bad.solve.print_level = level;
    EXPECT_EQ(message(bad).rfind("print_level: expected Ipopt's print level, 0 … 12", 0), 0u) << level;
  }
}

}  // namespace
