// saltus::optimize (saltus/saltus.hpp): transcribe, seed, solve in two stages, evaluate; and the
// files of a solve (trajectory.csv, variables.csv, summary.json).
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "collocation/saved_solution.hpp"
#include "saltus/format.hpp"
#include "saltus/saltus.hpp"
#include "scene/atomic_file.hpp"

namespace saltus {

namespace fs = std::filesystem;
using namespace saltus::collocation;

Problem adjustedProblem(Problem problem, const OptimizeOptions& options) {
  // The method's own penalty keys (a problem file's solve.<method>), then the options.
  if (const auto m = problem.method_solve.find(options.method); m != problem.method_solve.end()) {
    if (m->second.penalty_iterations) problem.penalty_iterations = *m->second.penalty_iterations;
    if (m->second.task_penalty) problem.task_penalty = *m->second.task_penalty;
    if (m->second.penalty_weight) problem.cost.penalty_weight = *m->second.penalty_weight;
  }
  problem.method_solve.clear();  // applied: the problem as solved
  if (options.P && (*options.P < 1 || *options.P > 9))
    throw std::invalid_argument("P: expected an order from 1 to 9, got " + std::to_string(*options.P));
  if (options.N && (*options.N < 1 || *options.N > collocation::kMaxElements))
    throw std::invalid_argument("N: expected from 1 to " + std::to_string(collocation::kMaxElements) +
                                " elements, got " + std::to_string(*options.N));
  if (options.P || options.N) {
    try {
      remesh(problem, options.N.value_or(problem.N), options.P.value_or(problem.P));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("N: ") + e.what());
    }
  }
  if (options.random_seed) problem.random_seed = *options.random_seed;
  if (options.seed_kind) {
    if (*options.seed_kind == SeedKind::Solution)
      throw std::invalid_argument("seed_kind: a solution seed is given by seed_from (its folder)");
    if (!options.seed_from.empty())
      throw std::invalid_argument("seed_kind: not with seed_from (which starts from a solution)");
    problem.seed_kind = *options.seed_kind;
  }
  if (options.seed_method) {
    if (*options.seed_method == options.method)
      throw std::invalid_argument(std::string("seed_method: expected another method than the solve's own (") +
                                  toString(options.method) + ")");
    if (!options.seed_from.empty())
      throw std::invalid_argument("seed_method: not with seed_from (which names the solution to start from)");
    if (const std::string why = methodCannotTake(problem, *options.seed_method); !why.empty())
      throw std::invalid_argument("seed_method: " + why);
  }
  if (!options.seed_from.empty()) {
    problem.seed_kind = SeedKind::Solution;
    problem.seed_solution = options.seed_from;
    problem.seed_solution_origin = "--seed-from";
  }
  if (!options.seed_inputs.empty()) {
    problem.seed_inputs = options.seed_inputs;
    problem.seed_inputs_origin = "--seed-inputs";
  }
  if (options.seed_scale) {
    if (!(*options.seed_scale >= 0) || !std::isfinite(*options.seed_scale))
      throw std::invalid_argument("seed_scale: expected a non-negative number");
    problem.seed_scale = *options.seed_scale;
  }
  if (options.restarts) {
    if (*options.restarts < 0) throw std::invalid_argument("restarts: expected a non-negative integer");
    problem.restarts = *options.restarts;
  }
  if (options.resimulations) {
    if (*options.resimulations < 0) throw std::invalid_argument("resimulations: expected a non-negative integer");
    problem.resimulations = *options.resimulations;
  }
  if (options.resimulation_tracking) {
    if (!(*options.resimulation_tracking >= 0))
      throw std::invalid_argument("resimulation_tracking: expected a natural frequency >= 0 rad/s (0: open loop)");
    problem.resimulation_tracking = *options.resimulation_tracking;
  }
  if (options.exact_hessian) problem.exact_hessian = problem.feasibility_exact_hessian = *options.exact_hessian;
  if (options.feasibility_exact_hessian) problem.feasibility_exact_hessian = *options.feasibility_exact_hessian;
  problem.derivative_check = problem.derivative_check || options.derivative_check;
  if (options.penalty_iterations) {
    if (*options.penalty_iterations < 0)
      throw std::invalid_argument("penalty_iterations: expected a non-negative iteration count (0: no penalty stage)");
    problem.penalty_iterations = *options.penalty_iterations;
  }
  if (options.task_penalty) problem.task_penalty = *options.task_penalty;
  if (!options.hints) problem.hints.clear();
  if (options.solve.print_level < 0 || options.solve.print_level > 12)
    throw std::invalid_argument("print_level: expected Ipopt's print level, 0 … 12, got " +
                                std::to_string(options.solve.print_level));
  if (!(options.solve.tighten_within >= 0))
    throw std::invalid_argument("tighten_within: expected a non-negative ratio (0: never tighten)");
  if (options.solve.feasibility_repeats < 0)
    throw std::invalid_argument("feasibility_repeats: expected a non-negative integer, got " +
                                std::to_string(options.solve.feasibility_repeats));
  if (!(options.solve.tighten_factor >= 0) || !std::isfinite(options.solve.tighten_factor))
    throw std::invalid_argument("tighten_factor: expected a finite non-negative factor (at most 1: one step)");
  return problem;
}

namespace {

// A continuation step's problem, adjusted as the problem is, and its transcription.
struct StepTranscription {
  std::shared_ptr<const Problem> problem;
  std::shared_ptr<const Transcription> transcription;  // refers to *problem
};
// The problem's continuation steps; none when the options turn it off or the seed is an earlier
// solution (already a point of the problem).
std::vector<StepTranscription> continuationSteps(const Problem& adjusted, const OptimizeOptions& options,
                                                 const Transcription& t) {
  std::vector<StepTranscription> steps;
  if (!options.continuation || adjusted.seed_kind == SeedKind::Solution) return steps;
  for (std::size_t i = 0; i < adjusted.continuation.size(); ++i) {
    const ContinuationStep& step = adjusted.continuation[i];
    std::string values;
    for (const auto& [name, value] : step.parameters) values += (values.empty() ? "" : ", ") + name + " = " + formatNumber(value);
    const std::string at = "continuation[" + std::to_string(i) + "] (" + values + ")";
    if (!step.problem) throw std::invalid_argument(at + ": the step's problem was not read (loadProblem reads it)");
    Problem p = adjustedProblem(*step.problem, options);
    p.continuation.clear();
    auto problem = std::make_shared<const Problem>(std::move(p));
    auto ts = std::make_shared<const Transcription>(*problem, options.method);
    if (ts->variables() != t.variables() || ts->constraints() != t.constraints())
      throw std::invalid_argument(at + ": its transcription has " + std::to_string(ts->variables()) + " variables and " +
                                  std::to_string(ts->constraints()) + " constraints against the problem's " +
                                  std::to_string(t.variables()) + " and " + std::to_string(t.constraints()) +
                                  "; a step may change values (gravity, bounds, goals), not the mesh, contacts, "
                                  "inputs or conditions");
    steps.push_back({std::move(problem), std::move(ts)});
  }
  return steps;
}

}  // namespace

OptimizeResult optimize(const Problem& problem, const OptimizeOptions& options) {
  // Every Ipopt option checked before any stage runs: a bad task-stage option would otherwise
  // surface after the feasibility stage.
  for (const auto& [key, given] : {std::pair{"ipopt", &options.solve.ipopt}, {"task_ipopt", &options.solve.task_ipopt}})
    for (const auto& [name, value] : *given) {
      try {
        collocation::checkIpoptOption(name, value);
      } catch (const collocation::IpoptOptionError& e) {
        throw collocation::IpoptOptionError(std::string(key) + ": " + e.what());
      }
    }
  OptimizeResult o;
  o.problem_ptr = std::make_shared<const Problem>(adjustedProblem(problem, options));
  const auto transcription = std::make_shared<const Transcription>(*o.problem_ptr, options.method);
  o.transcription = transcription;
  const Transcription& t = *transcription;
  const Problem& adjusted = *o.problem_ptr;
  SolveOptions solve = options.solve;
  if (options.seed_method) {
    OptimizeOptions first = options;
    first.method = *options.seed_method;
    first.seed_method.reset();
    try {
      o.seed_solve = std::make_shared<const OptimizeResult>(optimize(problem, first));
    } catch (const std::invalid_argument& e) {  // what the seed method cannot represent
      throw std::invalid_argument(std::string("seed_method: ") + e.what());
    }
    if (o.seed_solve->report.interrupted) return *o.seed_solve;
    const Eigen::VectorXd x0 = seedFromSolution(t, *o.seed_solve->transcription, o.seed_solve->report.x,
                                                std::string("the ") + toString(*options.seed_method) + " solve");
    solve.restarts = 0;  // the earlier solution, unperturbed: every attempt would be the same
    solve.warm_seed = true;
    o.report = collocation::solve(t, x0, solve);
    o.report.iterations += o.seed_solve->report.iterations;
    o.report.wall_seconds += o.seed_solve->report.wall_seconds;
    o.report.evaluation_seconds += o.seed_solve->report.evaluation_seconds;
  } else {
    const Seeding seeding = makeSeeding(t);
    o.simulation_seed = seeding.simulation;
    o.seed_fallback = seeding.fallback;
    solve.restarts = seeding.restarts;
    SeedFunction seed = seeding.seed;
    const auto steps = continuationSteps(adjusted, options, t);
    std::vector<std::string> step_notes;  // each step's remarks, for the solve's note
    if (!steps.empty()) {
      // Each attempt's seed through the steps: a feasibility stage on each from the previous
      // end, the first with the hints (when the seed takes them), then the problem's own solve
      // from the last end, warm and with the seed's hints, as from an earlier solution.
      seed = [&o, &steps, &adjusted, &step_notes, base = seeding.seed, options = solve](int k) {
        collocation::Seed s = base(k);
        const bool hinted = s.hinted;
        for (std::size_t i = 0; i < steps.size(); ++i) {
          SolveOptions step = options;
          step.feasibility_only = true;
          step.restarts = step.resimulations = 0;
          // A step's feasibility stage that Ipopt solves at a local minimum above the tolerance is
          // repeated as the problem's own is (SolveOptions::feasibility_repeats): on the full-body
          // Ollie (quarter-gravity continuation, assist 3, seed 5) the first step's repeat went
          // from products of 1.16 to 0.67 at the tail's strike, and the solve took 974 s where it
          // had taken 1,970 (README).
          step.resimulate = nullptr;
          step.warm_seed = options.warm_seed || s.warm;
          step.keep_warm_start = i > 0 || (s.warm && s.keep_warm_start);
          step.hints = options.hints && s.hinted;
          const SolveReport r = collocation::solve(*steps[i].transcription, s.x, step);
          for (std::size_t j = 0; j < r.stages.size(); ++j)  // the stage whose end seeds the next is kept
            o.continuation.push_back({k, static_cast<int>(i), adjusted.continuation[i].parameters, r.stages[j],
                                      static_cast<int>(j) == r.kept_stage});
          if (!r.note.empty())
            step_notes.push_back("continuation[" + std::to_string(i) + "] of attempt " + std::to_string(k) + ": " + r.note);
          s = collocation::Seed{r.x, true, false, true};
        }
        s.hinted = hinted;
        return s;
      };
    }
    if (adjusted.resimulations > 0 && !adjusted.inputs.empty()) {
      solve.resimulations = adjusted.resimulations;
      solve.resimulate = [&t, tracking = adjusted.resimulation_tracking](const Eigen::VectorXd& end)
          -> std::optional<collocation::Seed> {
        try {
          // warm, without the hints, in the warm start's own barrier and bound push
          return collocation::Seed{collocation::seedFromResimulation(t, end, nullptr, tracking), true, false, true};
        } catch (const std::runtime_error&) {  // the time-stepper failed: no such attempt
          return std::nullopt;
        }
      };
    }
    o.report = collocation::solve(t, seed, solve);
    // The steps' remarks come first in the note, as their stages ran first.
    std::string notes;
    for (const std::string& n : step_notes) notes += (notes.empty() ? "" : "; ") + n;
    if (!notes.empty()) o.report.note = notes + (o.report.note.empty() ? "" : "; " + o.report.note);
    for (const ContinuationStepReport& c : o.continuation) {
      o.report.iterations += c.stage.iterations;
      o.report.wall_seconds += c.stage.wall_seconds;
      o.report.evaluation_seconds += c.stage.evaluation_seconds;
    }
  }
  o.tighten_within = solve.tighten_within;
  o.tighten_factor = solve.tighten_factor;
  o.feasibility_repeats = solve.feasibility_repeats;
  o.samples = trajectory(t, o.report.x);
  o.mean_local_error = meanLocalError(t, o.report.x);
  if (!o.report.feasible && !o.report.interrupted && !adjusted.hints.empty()) {
    try {
      o.hints = checkHints(t);
    } catch (const std::runtime_error& e) {  // a diagnostic: the solve's result stands regardless
      o.hints_not_checked = e.what();
    }
  }
  return o;
}

std::string summaryJson(const OptimizeResult& o) {
  const Problem& problem = o.problem();
  const Transcription& t = *o.transcription;
  const SolveReport& r = o.report;
  const Method method = t.method();
  nlohmann::ordered_json j;
  j["problem"] = problem.name;
  // files by absolute path: replay and render may run from another directory
  j["source"] = problem.source.rfind("builtin:", 0) == 0 ? problem.source
                                                          : fs::absolute(problem.source).lexically_normal().string();
  j["method"] = toString(method);
  j["N"] = problem.N;
  j["P"] = method == Method::FirstOrder ? 1 : problem.P;
  j["elements"] = t.elements();
  j["seed"] = toString(problem.seed_kind);
  if (problem.seed_kind == SeedKind::Solution) j["seed_solution"] = problem.seed_solution;
  if (!problem.seed_inputs.empty()) j["seed_inputs"] = fs::absolute(problem.seed_inputs).lexically_normal().string();
  if ((problem.seed_kind == SeedKind::Simulation || problem.seed_kind == SeedKind::PerturbedSimulation) &&
      o.seed_fallback.empty())
    j["simulation_seed"] = {{"dt", o.simulation_seed.dt},
                            {"events", o.simulation_seed.events},
                            {"passes", o.simulation_seed.iterations}};
  if (!o.seed_fallback.empty()) j["seed_fallback"] = o.seed_fallback;
  if (o.seed_solve) {  // a two-step solve: the first solve's figures (counted in the totals below)
    const SolveReport& s = o.seed_solve->report;
    j["seed_method"] = toString(o.seed_solve->transcription->method());
    j["seed_solve"] = {{"feasible", s.feasible},
                       {"status", s.stages.empty() ? std::string() : s.keptStage().status},
                       {"largest_product", s.largest_product},
                       {"objective", s.objective},
                       {"iterations", s.iterations},
                       {"wall_seconds", s.wall_seconds},
                       {"evaluation_seconds", s.evaluation_seconds},
                       {"mean_local_error", o.seed_solve->mean_local_error}};
  }
  for (const ContinuationStepReport& c : o.continuation)  // counted in the totals below
    j["continuation"].push_back({{"attempt", c.attempt},
                                 {"step", c.step},
                                 {"parameters", c.parameters},
                                 {"stage", c.stage.name},
                                 {"kept", c.kept},
                                 {"status", c.stage.status},
                                 {"largest_product", c.stage.largest_product},
                                 {"largest_product_at", c.stage.largest_product_at},
                                 {"largest_violation", c.stage.largest_violation},
                                 {"iterations", c.stage.iterations},
                                 {"wall_seconds", c.stage.wall_seconds},
                                 {"evaluation_seconds", c.stage.evaluation_seconds}});
  j["seed_scale"] = problem.seed_scale;
  j["random_seed"] = problem.random_seed;
  j["restarts"] = problem.restarts;
  j["resimulations"] = problem.resimulations;
  j["resimulation_tracking"] = problem.resimulation_tracking;
  j["penalty_iterations"] = problem.penalty_iterations;  // as solved: the method's own, or the options'
  j["task_penalty"] = problem.task_penalty;
  j["penalty_weight"] = problem.cost.penalty_weight;
  j["hints_used"] = problem.hints.size();  // the hints imposed (--no-hints: 0)
  if (std::isfinite(o.tighten_within)) j["tighten_within"] = o.tighten_within;
  j["tighten_factor"] = o.tighten_factor;
  j["feasibility_repeats"] = o.feasibility_repeats;
  j["feasible"] = r.feasible;
  j["converged"] = r.converged;
  // Ipopt's status of the stage whose point is the solution (stages[kept_stage]).
  j["status"] = r.keptStage().status;
  j["kept_stage"] = r.kept_stage;
  j["objective"] = r.objective;
  j["largest_product"] = r.largest_product;
  j["largest_product_at"] = r.largest_product_at;
  j["largest_violation"] = r.largest_violation;
  j["largest_violation_at"] = r.largest_violation_at;
  j["complementarity_tolerance"] = problem.complementarity_tolerance;
  j["iterations"] = r.iterations;
  j["wall_seconds"] = r.wall_seconds;
  j["evaluation_seconds"] = r.evaluation_seconds;
  j["ipopt_seconds"] = r.wall_seconds - r.evaluation_seconds;
  j["evaluation_fraction"] = r.wall_seconds > 0 ? r.evaluation_seconds / r.wall_seconds : 0.0;
  j["variables"] = r.variables;
  j["constraints"] = r.constraints;
  j["jacobian_nonzeros"] = r.jacobian_nonzeros;
  j["hessian_nonzeros"] = r.hessian_nonzeros;
  j["total_time"] = o.samples.empty() ? 0.0 : o.samples.back().t;
  j["mean_local_error"] = o.mean_local_error;
  for (const StageReport& s : r.stages)
    j["stages"].push_back({{"name", s.name},
                           {"status", s.status},
                           {"succeeded", s.succeeded},
                           {"iterations", s.iterations},
                           {"objective", s.objective},
                           {"largest_product", s.largest_product},
                           {"largest_violation", s.largest_violation},
                           {"largest_violation_at", s.largest_violation_at},
                           {"wall_seconds", s.wall_seconds},
                           {"evaluation_seconds", s.evaluation_seconds},
                           {"hessian", s.exact_hessian ? "exact" : "limited-memory"},
                           {"hessian_evaluations", s.hessian_evaluations},
                           {"barrier", s.barrier},
                           {"kept_iteration", s.kept_iteration},
                           {"product_bound", s.product_bound}});
  for (const AttemptReport& a : r.attempts)
    j["attempts"].push_back({{"attempt", a.attempt},
                             {"resimulation", a.resimulation},
                             {"random_seed", problem.random_seed + a.attempt},
                             {"feasible", a.feasible},
                             {"largest_product", a.largest_product},
                             {"iterations", a.iterations},
                             {"wall_seconds", a.wall_seconds}});
  if (!r.note.empty()) j["note"] = r.note;
  if (!o.hints_not_checked.empty()) j["hints_not_checked"] = o.hints_not_checked;
  for (const HintReach& h : o.hints)
    j["hints"].push_back({{"origin", h.origin},
                          {"contact", h.contact},
                          {"at", {h.element + 1, h.point}},
                          {"earliest", h.earliest},
                          {"latest", h.latest},
                          {"simulated_closing", h.closes},
                          {"reachable", h.reachable},
                          {"actuated", h.actuated}});
  j["parameters"] = problem.parameters;
  return j.dump(2) + "\n";
}

void saveSolution(const std::string& dir, const OptimizeResult& o) {
  fs::create_directories(dir);
  writeTrajectoryCsv((fs::path(dir) / "trajectory.csv").string(), *o.transcription, o.samples);
  writeSolution(dir, *o.transcription, o.report.x);
  scene::writeFileAtomically((fs::path(dir) / "summary.json").string(), summaryJson(o));
}

}  // namespace saltus
