// Sweep specs (sweep/spec.hpp): the grid they expand to (counts, order, stable ids, the
// saltus optimize arguments of a solve), paths relative to the spec, and refusals that name the
// file, line and key before any solve starts.
#include "sweep/spec.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "collocation/nlp.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/transcription.hpp"
#include "saltus/build_paths.hpp"
#include "scene/yaml_reader.hpp"

namespace saltus::sweep {
namespace {

namespace fs = std::filesystem;

std::string errorOf(const std::string& text, const std::string& file = "spec.yaml") {
  try {
    expandSweep(parseSweepSpec(text, file));
  } catch (const scene::ScenarioError& e) {
    return e.what();
  }
  return "";
}

TEST(SweepSpec, ExpandsEveryCombinationInAFixedOrder) {
  const SweepSpec spec = parseSweepSpec(R"(
problems:
  - point_mass_drop
  - {problem: pendulum_conveyor, set: {friction: [0.5, 2]}}
methods: [impulsive, first-order]
set: {}
seeds: {from: 3, count: 2}
options: {N: 10, restarts: 0, resimulations: 2, resimulation_tracking: 12.5, hints: false, continuation: false, tighten_within: 0, tighten_factor: 4, feasibility_repeats: 1, task_max_iter: 500, penalty_iterations: 300,
          task_penalty: true, feasibility_hessian: limited-memory,
          ipopt: {bound_push: 1e-6}, task_ipopt: {obj_scaling_factor: 10}}
)",
                                        "spec.yaml");
  ASSERT_EQ(spec.problems.size(), 2u);
  EXPECT_EQ(spec.seeds, (std::vector<unsigned>{3, 4}));
  EXPECT_EQ(*spec.options.N, 10);
  EXPECT_EQ(spec.options.ipopt.at("bound_push"), "1e-6");
  const std::vector<SweepCase> cases = expandSweep(spec);
  // drop: 2 methods × 2 seeds; pendulum: 2 frictions × 2 methods × 2 seeds
  ASSERT_EQ(cases.size(), 4u + 8u);
  EXPECT_EQ(cases[0].id, "point_mass_drop__impulsive__seed=3");
  EXPECT_EQ(cases[1].id, "point_mass_drop__impulsive__seed=4");
  EXPECT_EQ(cases[2].method, "first-order");
  EXPECT_EQ(cases[4].id, "pendulum_conveyor__impulsive__friction=0.5__seed=3");
  EXPECT_EQ(cases[4].cell(), "pendulum_conveyor impulsive friction=0.5");
  std::set<std::string> ids;
  for (const SweepCase& c : cases) ids.insert(c.id);
  EXPECT_EQ(ids.size(), cases.size());

  const std::vector<std::string> args = cases[5].optimizeArguments("OUT");
  const std::vector<std::string> expected = {"optimize", "pendulum_conveyor", "--method", "impulsive", "--seed", "4",
                                             "--set", "friction=0.5", "--N", "10", "--restarts", "0", "--resimulations", "2",
                                             "--resimulation-tracking", "12.5", "--no-hints", "--no-continuation",
                                             "--tighten-within", "0", "--tighten-factor", "4",
                                             "--feasibility-repeats", "1", "--task-max-iter", "500",
                                             "--task-penalty", "on", "--penalty-iterations", "300",
                                             "--feasibility-hessian", "limited-memory", "--ipopt", "bound_push=1e-6",
                                             "--task-ipopt", "obj_scaling_factor=10", "--out", "OUT"};
  EXPECT_EQ(args, expected);
}

TEST(SweepSpec, TopLevelGridCombinesWithAProblemsOwn) {
  const SweepSpec spec = parseSweepSpec(R"(
problems: [{problem: point_mass_drop, set: {height: [0.1, 0.2, 0.3]}}]
methods: [impulsive]
set: {restitution: [0, 0.5]}
seeds: [1]
)",
                                        "spec.yaml");
  const std::vector<SweepCase> cases = expandSweep(spec);
  ASSERT_EQ(cases.size(), 6u);
  std::set<std::pair<double, double>> pairs;
  for (const SweepCase& c : cases) pairs.insert({c.set.at("height"), c.set.at("restitution")});
  EXPECT_EQ(pairs.size(), 6u);
}

TEST(SweepSpec, ProblemPathsAreRelativeToTheSpec) {
  const fs::path dir = fs::temp_directory_path() / ("saltus_sweep_spec_" + std::to_string(::getpid()));
  fs::create_directories(dir / "problems");
  fs::copy_file(fs::path(SALTUS_SOURCE_DIR) / "models/problems/point_mass_drop.yaml", dir / "problems/drop.yaml",
                fs::copy_options::overwrite_existing);
  {
    std::ofstream(dir / "spec.yaml") << "problems: [problems/drop.yaml]\nmethods: [impulsive]\nseeds: [1]\n";
  }
  const SweepSpec spec = readSweepSpec((dir / "spec.yaml").string());
  EXPECT_EQ(fs::path(spec.problems[0].problem), (dir / "problems/drop.yaml").lexically_normal());
  EXPECT_EQ(expandSweep(spec).size(), 1u);
  fs::remove_all(dir);
}

// seed_from: an earlier solution's folder, relative to the spec, passed to every solve; not with
// a seed kind or a two-step method (which seed otherwise), nor a folder that is not there.
TEST(SweepSpec, AnEarlierSolutionIsRelativeToTheSpecAndSeedsEverySolve) {
  const fs::path dir = fs::temp_directory_path() / ("saltus_sweep_seed_from_" + std::to_string(::getpid()));
  fs::create_directories(dir / "solutions/drop");
  const std::string head = "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1, 2]\n";
  {
    std::ofstream(dir / "spec.yaml") << head << "options: {seed_from: solutions/drop, seed_scale: 0.001}\n";
  }
  const SweepSpec spec = readSweepSpec((dir / "spec.yaml").string());
  EXPECT_EQ(fs::path(spec.options.seed_from), (dir / "solutions/drop").lexically_normal());
  for (const SweepCase& c : expandSweep(spec)) {
    const std::vector<std::string> args = c.optimizeArguments("OUT");
    const std::vector<std::string> from = {"--seed-from", spec.options.seed_from}, scale = {"--seed-scale", "0.001"};
    EXPECT_NE(std::search(args.begin(), args.end(), from.begin(), from.end()), args.end()) << c.id;
    EXPECT_NE(std::search(args.begin(), args.end(), scale.begin(), scale.end()), args.end()) << c.id;
  }
  const std::string file = (dir / "spec.yaml").string();
  const std::string missing = errorOf(head + "options: {seed_from: solutions/none}\n", file);
  EXPECT_NE(missing.find(file + ":4:22: options.seed_from: no earlier solution at '" + (dir / "solutions/none").string() + "'"),
            std::string::npos)
      << missing;
  const std::string with_kind = errorOf(head + "options: {seed: perturbed, seed_from: solutions/drop}\n", file);
  EXPECT_NE(with_kind.find("options.seed_from: not with options.seed"), std::string::npos) << with_kind;
  const std::string two_step = errorOf(
      "problems: [point_mass_drop]\nmethods: [impulsive, impulsive from first-order]\nseeds: [1]\n"
      "options: {seed_from: solutions/drop}\n",
      file);
  EXPECT_NE(two_step.find(file + ":2:22: methods[1]: a two-step method is seeded by its first method's solution"),
            std::string::npos)
      << two_step;
  fs::remove_all(dir);
}

// The paper's strategy 1 written as YAML reads it: a bare null is the null seed (as in a problem
// file's solve.seed), quoted or not.
TEST(SweepSpec, ABareNullSeedIsTheNullSeed) {
  for (const std::string value : {"null", "\"null\"", "~"}) {
    const SweepSpec spec =
        parseSweepSpec("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\noptions: {seed: " + value + "}\n",
                       "spec.yaml");
    EXPECT_EQ(spec.options.seed_kind, "null") << value;
    const std::vector<std::string> args = expandSweep(spec).front().optimizeArguments("OUT");
    const std::vector<std::string> kind = {"--seed-kind", "null"};
    EXPECT_NE(std::search(args.begin(), args.end(), kind.begin(), kind.end()), args.end()) << value;
  }
}

TEST(SweepSpec, RefusesBadSpecsNamingFileLineAndKey) {
  EXPECT_EQ(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\nrepeats: 3\n"),
            "spec.yaml:4:1: repeats: unknown key 'repeats'; expected one of: problems, methods, set, seeds, options, "
            "variants, replay, success");
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [implicit]\nseeds: [1]\n")
                .find("spec.yaml:2:11: methods[0]: expected impulsive, continuous or first-order, or 'M from S' (M "
                      "solved from S's solution), got 'implicit'"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: []\n").find("seeds: expected at least one seed"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1, 1]\n").find("a seed is listed twice"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: {from: 1}\n").find("seeds.count: missing required key 'count'"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\noptions: {N: 0}\n")
                .find("options.N: expected an integer ≥ 1"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\noptions: {tighten_factor: -2}\n")
                .find("spec.yaml:4:27: options.tighten_factor: expected a finite non-negative factor (at most 1: one step)"),
            std::string::npos);
  const std::string hessian =
      errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\noptions: {feasibility_hessian: bfgs}\n");
  EXPECT_NE(hessian.find("spec.yaml:4:"), std::string::npos) << hessian;
  EXPECT_NE(hessian.find("options.feasibility_hessian: expected exact or limited-memory, got 'bfgs'"), std::string::npos)
      << hessian;
  const std::string seed = errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\noptions: {seed: simulatoin}\n");
  EXPECT_NE(seed.find("options.seed: unknown seed 'simulatoin' (did you mean 'simulation'?)"), std::string::npos) << seed;
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\n---\nseeds: [2]\n")
                .find("a sweep spec is one YAML document"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\nreplay: {restart: element}\n")
                .find("spec.yaml:4:19: replay.restart: expected none, mesh or mesh-after-jumps, got 'element'"),
            std::string::npos);
  EXPECT_EQ(parseSweepSpec("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\nreplay: {restart: mesh}\n",
                           "spec.yaml")
                .replay.restart,
            verify::Restart::Mesh);
  EXPECT_EQ(parseSweepSpec("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\nreplay: {restart: mesh-after-jumps}\n",
                           "spec.yaml")
                .replay.restart,
            verify::Restart::MeshAfterJumps);
  EXPECT_EQ(parseSweepSpec("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\n", "spec.yaml").replay.restart,
            verify::Restart::None);
  // The success rule: physical by default, feasible on request (every case carries it); physical
  // without the replay that decides it, or another word, is refused.
  const std::string base = "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1, 2]\n";
  EXPECT_TRUE(parseSweepSpec(base, "spec.yaml").physical_success);
  for (const SweepCase& c : expandSweep(parseSweepSpec(base, "spec.yaml"))) EXPECT_TRUE(c.physical_required);
  const SweepSpec feasible = parseSweepSpec(base + "success: feasible\n", "spec.yaml");
  EXPECT_FALSE(feasible.physical_success);
  EXPECT_TRUE(feasible.replay.enabled) << "the replay still runs";
  for (const SweepCase& c : expandSweep(feasible)) EXPECT_FALSE(c.physical_required);
  EXPECT_NE(errorOf(base + "success: converged\n")
                .find("spec.yaml:4:10: success: expected physical (feasible and its replay within tolerance) or "
                      "feasible, got 'converged'"),
            std::string::npos);
  EXPECT_NE(errorOf(base + "replay: false\nsuccess: physical\n")
                .find("spec.yaml:5:10: success: physical needs the replay check, which replay: false turns off"),
            std::string::npos);
  // A parameter the problem does not have: found before any solve, naming the entry.
  const std::string unknown = errorOf("problems: [point_mass_drop]\nmethods: [impulsive]\nset: {mass: [1]}\nseeds: [1]\n");
  EXPECT_NE(unknown.find("spec.yaml: problems[0] (point_mass_drop) with mass=1: "), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("mass"), std::string::npos);
  // A method that can take no cell of the grid.
  const std::string method =
      errorOf("problems: [point_mass_drop]\nmethods: [continuous]\nset: {restitution: [0.5]}\nseeds: [1]\n");
  EXPECT_NE(method.find("method continuous: the continuous method cannot represent restitution"), std::string::npos)
      << method;
  EXPECT_NE(method.find("no other solve is left in the grid"), std::string::npos) << method;
}

TEST(SweepSpec, LeavesOutTheCellsAMethodCannotRepresent) {
  // Restitution: the impulsive method takes every cell, the first-order and continuous ones only e = 0.
  const SweepSpec spec = parseSweepSpec(
      "problems: [point_mass_drop]\nmethods: [impulsive, first-order, continuous]\n"
      "set: {restitution: [0, 0.5]}\nseeds: [1, 2]\n",
      "spec.yaml");
  std::vector<SkippedCell> skipped;
  const std::vector<SweepCase> cases = expandSweep(spec, &skipped);
  EXPECT_EQ(cases.size(), 8u);  // impulsive 2 cells, the others 1 cell each; 2 seeds
  for (const SweepCase& c : cases) {
    if (c.method != "impulsive") {
      EXPECT_EQ(c.set.at("restitution"), 0.0) << c.id;
    }
  }
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_EQ(skipped[0].method, "first-order");
  EXPECT_EQ(skipped[0].set.at("restitution"), 0.5);
  EXPECT_NE(skipped[0].reason.find("first-order method cannot represent restitution: contact 'ball' has e = 0.5"),
            std::string::npos)
      << skipped[0].reason;
  EXPECT_EQ(skipped[1].method, "continuous");
}

TEST(SweepSpec, ATwoStepMethodIsSolvedFromTheOtherMethodsSolution) {
  const SweepSpec spec = parseSweepSpec(
      "problems: [point_mass_drop]\nmethods: [first-order, impulsive from first-order]\n"
      "set: {restitution: [0, 0.5]}\nseeds: [1]\noptions: {seed: perturbed, seed_scale: 0.1}\n",
      "spec.yaml");
  std::vector<SkippedCell> skipped;
  const std::vector<SweepCase> cases = expandSweep(spec, &skipped);
  // e = 0.5: neither (the two-step solve starts with the first-order method, which has no restitution)
  ASSERT_EQ(cases.size(), 2u);
  EXPECT_EQ(cases[1].id, "point_mass_drop__impulsive_from_first-order__restitution=0__seed=1");
  EXPECT_EQ(cases[1].cell(), "point_mass_drop impulsive from first-order restitution=0");
  const std::vector<std::string> args = cases[1].optimizeArguments("OUT");
  const std::vector<std::string> expected = {"optimize", "point_mass_drop", "--method", "impulsive", "--seed", "1",
                                             "--seed-method", "first-order", "--set", "restitution=0",
                                             "--seed-kind", "perturbed", "--seed-scale", "0.1", "--out", "OUT"};
  EXPECT_EQ(args, expected);
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_EQ(skipped[1].method, "impulsive from first-order");
  EXPECT_NE(skipped[1].reason.find("first-order method cannot represent restitution"), std::string::npos)
      << skipped[1].reason;

  EXPECT_EQ(splitMethod("continuous from first-order").method, "continuous");
  EXPECT_EQ(splitMethod("continuous from first-order").seed_method, "first-order");
  EXPECT_EQ(splitMethod("impulsive").seed_method, "");
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive from impulsive]\nseeds: [1]\n")
                .find("spec.yaml:2:11: methods[0]: 'impulsive from impulsive': a method cannot seed itself"),
            std::string::npos);
  EXPECT_NE(errorOf("problems: [point_mass_drop]\nmethods: [impulsive from euler]\nseeds: [1]\n")
                .find("methods[0]: expected impulsive, continuous or first-order, or 'M from S'"),
            std::string::npos);
}

// Variants: every one over the whole grid, each a cell of its own (its name in the id and the
// cell), its options `options` with its own keys in place (ipopt entries added, a mesh of its own);
// a variant that is not a map of options, or a bad name, is refused naming the key.
TEST(SweepSpec, EachVariantRunsTheWholeGridWithItsOwnOptions) {
  const SweepSpec spec = parseSweepSpec(R"(
problems: [point_mass_drop]
methods: [impulsive]
seeds: [1, 2]
options: {restarts: 0, ipopt: {max_cpu_time: 150}}
variants:
  baseline: {}
  monotone: {ipopt: {mu_strategy: monotone}, restarts: 1}
  coarse: {N: 10}
)",
                                        "spec.yaml");
  ASSERT_EQ(spec.variants.size(), 3u);
  EXPECT_EQ(spec.variants[1].first, "monotone");
  const std::vector<SweepCase> cases = expandSweep(spec);
  ASSERT_EQ(cases.size(), 6u);
  EXPECT_EQ(cases[0].id, "point_mass_drop__impulsive__variant=baseline__seed=1");
  EXPECT_EQ(cases[2].id, "point_mass_drop__impulsive__variant=monotone__seed=1");
  EXPECT_EQ(cases[2].cell(), "point_mass_drop impulsive [monotone]");
  EXPECT_EQ(cases[5].variant, "coarse");
  EXPECT_EQ(cases[0].optimizeArguments("OUT"),
            (std::vector<std::string>{"optimize", "point_mass_drop", "--method", "impulsive", "--seed", "1", "--restarts",
                                      "0", "--ipopt", "max_cpu_time=150", "--out", "OUT"}));
  EXPECT_EQ(cases[3].optimizeArguments("OUT"),
            (std::vector<std::string>{"optimize", "point_mass_drop", "--method", "impulsive", "--seed", "2", "--restarts",
                                      "1", "--ipopt", "max_cpu_time=150", "--ipopt", "mu_strategy=monotone", "--out",
                                      "OUT"}));
  EXPECT_EQ(cases[4].optimizeArguments("OUT"),
            (std::vector<std::string>{"optimize", "point_mass_drop", "--method", "impulsive", "--seed", "1", "--N", "10",
                                      "--restarts", "0", "--ipopt", "max_cpu_time=150", "--out", "OUT"}));
  // Without variants: one unnamed, the ids and cells as before.
  const std::vector<SweepCase> plain =
      expandSweep(parseSweepSpec("problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\n", "spec.yaml"));
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_EQ(plain[0].id, "point_mass_drop__impulsive__seed=1");
  EXPECT_EQ(plain[0].cell(), "point_mass_drop impulsive");

  const std::string base = "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\n";
  EXPECT_NE(errorOf(base + "variants: {fast: {ipopt: {tol: [1, 2]}}}\n")
                .find("spec.yaml:4:32: variants.fast.ipopt.tol: expected a number or a name"),
            std::string::npos)
      << errorOf(base + "variants: {fast: {ipopt: {tol: [1, 2]}}}\n");
  EXPECT_NE(errorOf(base + "variants: {fast: {iterations: 3}}\n").find("spec.yaml:4:19: variants.fast.iterations: unknown key 'iterations'"),
            std::string::npos);
  EXPECT_NE(errorOf(base + "variants: {fast: {N: 0}}\n").find("variants.fast.N: expected an integer ≥ 1"),
            std::string::npos);
  EXPECT_NE(errorOf(base + "variants: {\"a b\": {}}\n").find("expected a variant name (letters, digits, _ and -)"),
            std::string::npos);
  EXPECT_NE(errorOf(base + "variants: [a, b]\n").find("variants:"), std::string::npos);
  // A mesh a problem cannot take, named with its variant: ollie_simple's air condition at [20, 0]
  // is not in a mesh of 10 elements.
  const std::string mesh =
      errorOf("problems: [ollie_simple]\nmethods: [impulsive]\nseeds: [1]\nvariants: {full: {}, tiny: {N: 10}}\n");
  EXPECT_NE(mesh.find("problems[0] (ollie_simple), variant tiny: "), std::string::npos) << mesh;
}

// Every spec the repository ships (bench/sweeps, named by the README's commands) reads and expands:
// its problems load with each parameter combination, its methods take them, its paths resolve.
TEST(SweepSpec, EveryShippedSpecExpands) {
  int specs = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(SALTUS_SOURCE_DIR) / "bench" / "sweeps")) {
    if (entry.path().extension() != ".yaml") continue;
    ++specs;
    try {
      const SweepSpec spec = readSweepSpec(entry.path().string());
      EXPECT_FALSE(expandSweep(spec).empty()) << entry.path();
    } catch (const std::exception& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(specs, 10);
}

// A sweep's problem file (bench/sweeps/problems/), loaded with the overrides.
saltus::collocation::Problem sweepProblem(const std::string& file, const std::map<std::string, double>& overrides) {
  return saltus::collocation::loadProblem((fs::path(SALTUS_SOURCE_DIR) / "bench" / "sweeps" / "problems" / file).string(),
                                          overrides);
}

// A sweep's copy of a problem with a continuation (bench/sweeps/problems/) is that problem but for
// its steps: the same parameters, and the same feasibility-stage NLP (bounds, objective and
// constraints, hints included) at a perturbed point, to the last digit; its `steps` steps, the
// first at `first_g` of gravity. Returns that step's parameters.
std::map<std::string, double> expectTheProblemWithItsSteps(const std::string& name, const std::string& copy_file,
                                                           const std::map<std::string, double>& overrides,
                                                           std::size_t steps = 2, double first_g = 0.5) {
  namespace c = saltus::collocation;
  const c::Problem plain = c::loadProblem(name, overrides);
  const c::Problem copy = sweepProblem(copy_file, overrides);
  EXPECT_TRUE(plain.continuation.empty());
  EXPECT_EQ(copy.continuation.size(), steps);
  if (copy.continuation.empty()) return {};
  EXPECT_DOUBLE_EQ(copy.continuation[0].problem->parameters.at("g"), plain.parameters.at("g") * first_g);
  EXPECT_EQ(copy.parameters, plain.parameters);
  const c::Transcription a(plain, c::Method::Impulsive), b(copy, c::Method::Impulsive);
  EXPECT_EQ(a.variables(), b.variables());
  if (a.variables() != b.variables()) return {};
  const Eigen::VectorXd x = a.perturb(a.nullSeed(), 0.1, 1);
  const auto nlp = [&](const c::Transcription& t) {
    c::Nlp p(t, c::Stage::Feasibility, x);
    Ipopt::Index n = 0, m = 0, nnz_j = 0, nnz_h = 0;
    Ipopt::TNLP::IndexStyleEnum style;
    p.get_nlp_info(n, m, nnz_j, nnz_h, style);
    Eigen::VectorXd values(2 * n + 3 * m + 1);
    p.get_bounds_info(n, values.data(), values.data() + n, m, values.data() + 2 * n, values.data() + 2 * n + m);
    p.eval_g(n, x.data(), true, m, values.data() + 2 * n + 2 * m);
    p.eval_f(n, x.data(), false, values[2 * n + 3 * m]);
    return values;
  };
  const Eigen::VectorXd va = nlp(a), vb = nlp(b);
  EXPECT_EQ(va.size(), vb.size());
  if (va.size() == vb.size()) {
    EXPECT_TRUE(va.cwiseEqual(vb).all()) << name;
  }
  return copy.continuation[0].problem->parameters;
}

TEST(SweepSpec, TheShippedContinuationProblemIsOllieSimpleWithItsSteps) {
  const auto first = expectTheProblemWithItsSteps("ollie_simple", "ollie_simple_continuation.yaml", {});
  EXPECT_DOUBLE_EQ(first.at("force_limit"), 6.0);  // the riders' forces kept in newtons
}

// The full body's copy, with the assist of the point masses' forces (3 weights) that its sweep
// sets: at half gravity the assist is 6 of the lighter weights, the same newtons.
TEST(SweepSpec, TheShippedContinuationProblemIsOllieWithItsSteps) {
  const auto first = expectTheProblemWithItsSteps("ollie", "ollie_continuation.yaml", {{"assist", 3.0}});
  EXPECT_DOUBLE_EQ(first.at("assist"), 6.0);
  EXPECT_DOUBLE_EQ(first.at("assist_z"), 6.0);  // the bounds that follow `assist` follow it in the steps
}

// The deeper continuation's copy: a quarter of gravity first (the assist 12 of those weights, the
// same newtons), then the two steps of ollie_continuation.yaml.
TEST(SweepSpec, TheShippedQuarterContinuationProblemIsOllieWithItsSteps) {
  const auto first = expectTheProblemWithItsSteps("ollie", "ollie_continuation_quarter.yaml", {{"assist", 3.0}}, 3, 0.25);
  EXPECT_DOUBLE_EQ(first.at("assist"), 12.0);
  EXPECT_DOUBLE_EQ(first.at("assist_theta"), 12.0);
  const saltus::collocation::Problem quarter = sweepProblem("ollie_continuation_quarter.yaml", {{"assist", 3.0}});
  const saltus::collocation::Problem half = sweepProblem("ollie_continuation.yaml", {{"assist", 3.0}});
  ASSERT_EQ(quarter.continuation.size(), half.continuation.size() + 1);
  for (std::size_t i = 0; i < half.continuation.size(); ++i) {
    EXPECT_EQ(quarter.continuation[i + 1].problem->parameters, half.continuation[i].problem->parameters) << i;
  }
}

// The stronger rider's copy: at `strength` 1 the quarter continuation's problem, bound for bound
// and step for step; at 3 each joint's torque bounds tripled in every step, the assist's as set.
TEST(SweepSpec, TheShippedStrengthProblemScalesTheJointTorqueLimitsAlone) {
  namespace c = saltus::collocation;
  const c::Problem quarter = sweepProblem("ollie_continuation_quarter.yaml", {{"assist", 3.0}});
  const c::Problem same = sweepProblem("ollie_strength.yaml", {{"assist", 3.0}});
  const c::Problem strong = sweepProblem("ollie_strength.yaml", {{"strength", 3.0}});
  ASSERT_EQ(same.inputs, quarter.inputs);
  EXPECT_TRUE(same.input_lower.cwiseEqual(quarter.input_lower).all());
  EXPECT_TRUE(same.input_upper.cwiseEqual(quarter.input_upper).all());
  ASSERT_EQ(same.continuation.size(), quarter.continuation.size());
  ASSERT_EQ(strong.continuation.size(), quarter.continuation.size());
  const c::Problem plain = c::loadProblem("ollie", {});
  const auto expectTripled = [&](const c::Problem& p, const std::string& where) {
    for (std::size_t i = 0; i < p.inputs.size(); ++i) {
      const std::string& name = p.scene.model.coordinate_name[p.inputs[i]];
      const bool joint = name.rfind("rider_", 0) != 0;  // the assist acts on rider_x, rider_z, rider_theta
      EXPECT_DOUBLE_EQ(p.input_lower[i], (joint ? 3.0 : 1.0) * plain.input_lower[i]) << where << name;
      EXPECT_DOUBLE_EQ(p.input_upper[i], (joint ? 3.0 : 1.0) * plain.input_upper[i]) << where << name;
    }
  };
  expectTripled(strong, "the problem: ");
  for (std::size_t k = 0; k < strong.continuation.size(); ++k) {
    const c::Problem &q = *quarter.continuation[k].problem, &s = *same.continuation[k].problem;
    EXPECT_TRUE(s.input_lower.cwiseEqual(q.input_lower).all()) << "step " << k;
    EXPECT_TRUE(s.input_upper.cwiseEqual(q.input_upper).all()) << "step " << k;
    EXPECT_EQ(s.parameters.at("g"), q.parameters.at("g")) << "step " << k;
    expectTripled(*strong.continuation[k].problem, "step " + std::to_string(k) + ": ");
    EXPECT_EQ(strong.continuation[k].problem->parameters.at("g"), q.parameters.at("g"));
  }
  const c::Transcription a(*quarter.continuation[0].problem, c::Method::Impulsive),
      b(*same.continuation[0].problem, c::Method::Impulsive);
  EXPECT_EQ(a.variables(), b.variables());
}

TEST(SweepSpec, FormatsValuesToReadBackExactly) {
  EXPECT_EQ(formatValue(0.1), "0.1");
  EXPECT_EQ(formatValue(2), "2");
  EXPECT_EQ(std::stod(formatValue(1.0 / 3.0)), 1.0 / 3.0);
}

}  // namespace
}  // namespace saltus::sweep
