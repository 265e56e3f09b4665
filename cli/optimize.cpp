// saltus optimize PROBLEM: contact-implicit trajectory optimisation (collocation/) of a problem
// file or built-in problem with one of three methods, solved in two stages with Ipopt. Writes
// DIR/trajectory.csv (collocation/solution.hpp), DIR/variables.csv (the decision variables, from
// which collocation/saved_solution.hpp rebuilds the solution for replay, rendering or seeding) and
// DIR/summary.json; they appear only when the solve ran (a failed or infeasible solve still
// writes them, with Ipopt's status, and exits 1).
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

#include "cli/optimize.hpp"

#include <memory>

#include "cli/common.hpp"
#include "scene/cleanup.hpp"
#include "cli/simulation.hpp"
#include "saltus/saltus.hpp"

namespace saltus::cli {

namespace {

using namespace saltus::collocation;
namespace fs = std::filesystem;


}  // namespace

OptimizeCall prepareOptimize(const OptimizeCliOptions& opt) {
  Method method;
  try {
    method = parseMethod(opt.method);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--method: ") + e.what());
  }
  // --ipopt and --task-ipopt: name=value, the name an Ipopt option this command does not own.
  const auto ipoptOptions = [](const std::string& flag, const std::vector<std::string>& given) {
    std::map<std::string, std::string> ipopt;
    for (const std::string& a : given) {
      const auto eq = a.find('=');
      if (eq == std::string::npos || eq == 0)
        throw UsageError(flag + " '" + a + "': expected name=value, e.g. " + flag + " max_iter=500");
      const std::string name = a.substr(0, eq), value = a.substr(eq + 1);
      if (name == "hessian_approximation") throw UsageError(flag + " " + a + ": set this through --hessian instead");
      if (name == "derivative_test") throw UsageError(flag + " " + a + ": set this through --derivative-check instead");
      try {
        checkIpoptOption(name, value);
      } catch (const IpoptOptionError& e) {
        throw UsageError(flag + " " + a + ": " + e.what());
      }
      ipopt[name] = value;
    }
    return ipopt;
  };
  const std::map<std::string, std::string> ipopt = ipoptOptions("--ipopt", opt.ipopt);
  const std::map<std::string, std::string> task_ipopt = ipoptOptions("--task-ipopt", opt.task_ipopt);
  OptimizeCall call{loadProblem(opt.problem, parseSetOptions(opt.set)), {}};
  const Problem& problem = call.problem;
  OptimizeOptions& options = call.options;
  options.method = method;
  options.N = opt.N;
  options.P = opt.P;
  options.random_seed = opt.seed;
  if (!opt.seed_kind.empty()) {
    try {
      options.seed_kind = parseSeedKind(opt.seed_kind);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--seed-kind: ") + e.what());
    }
  }
  options.seed_from = opt.seed_from;
  if (!opt.seed_method.empty()) {
    try {
      options.seed_method = parseMethod(opt.seed_method);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--seed-method: ") + e.what());
    }
  }
  options.seed_inputs = opt.seed_inputs;
  options.seed_scale = opt.seed_scale;
  options.restarts = opt.restarts;
  options.resimulations = opt.resimulations;
  options.resimulation_tracking = opt.resimulation_tracking;
  const auto hessian = [](const std::string& flag, const std::string& kind, std::optional<bool>& exact) {
    if (kind.empty()) return;
    if (kind != "exact" && kind != "limited-memory")
      throw UsageError(flag + ": expected exact or limited-memory, got '" + kind + "'");
    exact = kind == "exact";
  };
  hessian("--hessian", opt.hessian, options.exact_hessian);
  hessian("--feasibility-hessian", opt.feasibility_hessian, options.feasibility_exact_hessian);
  options.derivative_check = opt.derivative_check;
  options.hints = !opt.no_hints;
  options.continuation = !opt.no_continuation;
  options.solve.print_level = opt.print_level;
  options.solve.ipopt = ipopt;
  options.solve.task_ipopt = task_ipopt;
  if (opt.tighten_within) {
    if (!(*opt.tighten_within >= 0) || !std::isfinite(*opt.tighten_within))
      throw UsageError("--tighten-within: expected a finite non-negative ratio (0: never tighten)");
    options.solve.tighten_within = *opt.tighten_within;
  }
  if (opt.tighten_factor) {
    if (!(*opt.tighten_factor >= 0) || !std::isfinite(*opt.tighten_factor))
      throw UsageError("--tighten-factor: expected a finite non-negative factor (at most 1: one step)");
    options.solve.tighten_factor = *opt.tighten_factor;
  }
  if (opt.feasibility_repeats) {
    if (*opt.feasibility_repeats < 0) throw UsageError("--feasibility-repeats: expected a non-negative integer");
    options.solve.feasibility_repeats = *opt.feasibility_repeats;
  }
  options.penalty_iterations = opt.penalty_iterations;  // checked by adjustedProblem, below
  if (!opt.task_penalty.empty()) {
    if (opt.task_penalty != "on" && opt.task_penalty != "off")
      throw UsageError("--task-penalty: expected on or off, got '" + opt.task_penalty + "'");
    options.task_penalty = opt.task_penalty == "on";
  }
  if (opt.task_max_iter) {
    if (*opt.task_max_iter < 0) throw UsageError("--task-max-iter: expected a non-negative iteration count");
    options.solve.task_max_iter = *opt.task_max_iter;
  }
  if (fs::exists(opt.out) && !fs::is_directory(opt.out))
    throw UsageError("--out " + opt.out + ": exists and is not a directory");
  try {
    adjustedProblem(problem, options);  // the options' own errors are usage errors
  } catch (const std::invalid_argument& e) {
    throw optionError(e);
  }
  return call;
}

namespace {

int optimizeCommand(const OptimizeCliOptions& opt) {
  const OptimizeCall call = prepareOptimize(opt);
  const Problem& problem = call.problem;
  const OptimizeOptions& options = call.options;
  const Method method = options.method;
  // The folder is checked writable before the solve (a probe file), not after minutes of it. A
  // new folder is written as a temporary one beside it and renamed when the solution is saved, so
  // that neither an interrupt nor a SIGKILL leaves an empty or partial folder under its name.
  std::error_code error;
  const fs::path out = fs::absolute(opt.out).lexically_normal();
  const fs::path target = out.has_filename() ? out : out.parent_path();
  std::unique_ptr<scene::ScopedTemporary> made_parents, work;
  const bool fresh = !fs::exists(target, error);
  if (fresh) {
    scene::removeStaleTemporaries(target.parent_path().string());  // a killed solve's folder
    fs::path missing;
    for (fs::path p = target.parent_path(); !p.empty() && !fs::exists(p, error) && p != p.parent_path(); p = p.parent_path())
      missing = p;
    if (!missing.empty()) made_parents = std::make_unique<scene::ScopedTemporary>(missing.string());
    work = std::make_unique<scene::ScopedTemporary>(scene::temporaryName(target.string()));
    fs::create_directories(work->path(), error);
    if (error) throw UsageError("--out " + opt.out + ": cannot create the folder (" + error.message() + ")");
  }
  const std::string folder = fresh ? work->path() : opt.out;
  try {
    scene::AtomicFile probe((fs::path(folder) / "summary.json").string());
  } catch (const std::exception& e) {
    throw UsageError("--out " + opt.out + ": cannot write into it (" + e.what() + ")");
  }
  const OptimizeResult o = saltus::optimize(problem, options);  // refuses what the method cannot represent
  saveSolution(folder, o);
  if (fresh) {
    fs::rename(work->path(), target, error);
    if (error) throw std::runtime_error(opt.out + ": cannot move the solution into place (" + error.message() + ")");
    work->keep();
    if (made_parents) made_parents->keep();
  }

  const SolveReport& r = o.report;
  std::cerr << "saltus optimize: " << problem.name << ", " << toString(method) << ": "
            << (r.converged ? "feasible" : r.feasible ? "feasible, not converged" : "NOT feasible") << " ("
            << r.keptStage().status << ", largest product "
            << r.largest_product << (r.largest_product_at.empty() ? "" : " at " + r.largest_product_at) << "), " << r.iterations << " iterations, " << r.wall_seconds << " s ("
            << r.evaluation_seconds << " s evaluating"
            << (r.attempts.size() > 1 ? ", " + std::to_string(r.attempts.size()) + " attempts" : std::string()) << ") -> "
            << opt.out << "\n";
  if (!r.note.empty()) std::cerr << "saltus optimize: " << r.note << "\n";
  if (!o.seed_fallback.empty()) std::cerr << "saltus optimize: " << o.seed_fallback << "\n";
  if (o.seed_solve) {
    const SolveReport& s = o.seed_solve->report;
    std::cerr << "saltus optimize: started from the " << toString(o.seed_solve->transcription->method()) << " solve ("
              << (s.feasible ? "feasible" : "NOT feasible") << ", largest product " << s.largest_product << ", "
              << s.iterations << " iterations, " << s.wall_seconds << " s, counted above)\n";
  }
  for (const HintReach& h : o.hints) {
    if (h.reachable) continue;
    const std::string closes = h.closes < 0 ? std::string("never within the horizon") : "first at " + std::to_string(h.closes) + " s";
    std::cerr << "saltus optimize: the hint at " << h.origin << " (" << h.contact << " closed at [" << h.element + 1 << ","
              << h.point << "]) ";
    if (h.actuated)  // the inputs may close it where the unactuated motion does not
      std::cerr << "is not met by the motion without inputs: that point lies between " << h.earliest << " and "
                << h.latest << " s, and without inputs " << h.contact << " closes " << closes
                << "; the inputs have to close it there\n";
    else
      std::cerr << "cannot be met: that point lies between " << h.earliest << " and " << h.latest << " s, and the motion closes "
                << h.contact << " " << closes << "\n";
  }
  return r.feasible ? 0 : 1;
}

}  // namespace

Command addOptimizeCommand(CLI::App& saltus) {
  auto opt = std::make_shared<OptimizeCliOptions>();
  CLI::App* app = saltus.add_subcommand("optimize", "Trajectory optimisation through contact (direct collocation, Ipopt)");
  app->add_option("problem", opt->problem, "built-in problem name or problem file (.yaml)")->required();
  app->add_option("--method", opt->method, "impulsive (default), continuous or first-order");
  app->add_option("--P", opt->P, "collocation points per element (overrides the file)");
  app->add_option("--N", opt->N, "finite elements (overrides the file)");
  app->add_option("--seed", opt->seed, "random seed of the perturbation of the initial guess");
  app->add_option("--seed-kind", opt->seed_kind,
                  "initial guess: null, perturbed (the null guess plus random values), simulation (the time-stepper's "
                  "motion, mesh on its impacts) or perturbed-simulation (plus random values)");
  app->add_option("--seed-from", opt->seed_from, "start from an earlier solution (its --out directory), perturbed by the seed scale");
  app->add_option("--seed-method", opt->seed_method,
                  "solve first with this method (from the seed the other options describe), then start this solve "
                  "from its solution: e.g. --method impulsive --seed-method first-order");
  app->add_option("--seed-inputs", opt->seed_inputs,
                  "an input schedule (CSV: t and a u.<input> column per input, held from each row to the next; the "
                  "last row's time is the horizon) that drives the simulation seed in place of zero inputs");
  app->add_option("--seed-scale", opt->seed_scale, "size of the random perturbation of the initial guess (0: none)");
  app->add_option("--restarts", opt->restarts, "further attempts from new perturbations when a solve ends infeasible");
  app->add_option("--resimulations", opt->resimulations,
                  "after an attempt that ends infeasible, up to this many further attempts, each from the "
                  "time-stepper's motion under the previous attempt's inputs (problems with inputs)");
  app->add_option("--resimulation-tracking", opt->resimulation_tracking,
                  "in a re-simulation the inputs also track the previous attempt's motion of their coordinates, "
                  "critically damped at this natural frequency [rad/s] (default 30; 0: the inputs alone)");
  app->add_option("--tighten-within", opt->tighten_within,
                  "tighten (every product bounded by 0.9 x the tolerance) a solve ending infeasible with products "
                  "within this many times the tolerance (default: always; 0: never)");
  app->add_option("--tighten-factor", opt->tighten_factor,
                  "from products far above the tolerance, tighten in steps: the bound from 1/F of the products down "
                  "by F a step to the tolerance (default 10; at most 1: one step)");
  app->add_option("--feasibility-repeats", opt->feasibility_repeats,
                  "a feasibility stage that Ipopt solved at a local minimum above the tolerance runs again from its "
                  "end, up to this many times, with a fresh barrier and the --ipopt bound_push (default 0)");
  app->add_option("--task-max-iter", opt->task_max_iter,
                  "iteration limit of the task stage (default: Ipopt's max_iter); a task stage stopped by it at a "
                  "feasible point gives a feasible, not converged, solution");
  app->add_option("--penalty-iterations", opt->penalty_iterations,
                  "iteration cap of the penalty stage, which starts the solve with the complementarity products in "
                  "the cost and stops at its first feasible point (default: the problem's; 0: none)");
  app->add_option("--task-penalty", opt->task_penalty,
                  "on: the task stage weighs the complementarity products in its cost instead of bounding them "
                  "(its result is still its best point with every product within the tolerance); off: bounded "
                  "(default: the problem's)");
  app->add_option("--set", opt->set, "override a parameter: name=value (repeatable)");
  app->add_option("--ipopt", opt->ipopt, "Ipopt option: name=value (repeatable), e.g. max_iter=500");
  app->add_option("--task-ipopt", opt->task_ipopt,
                  "Ipopt option of the task stage only (after --ipopt): name=value (repeatable), e.g. "
                  "obj_scaling_factor=10");
  app->add_option("--hessian", opt->hessian, "every stage's Hessian: exact or limited-memory (quasi-Newton)");
  app->add_option("--feasibility-hessian", opt->feasibility_hessian,
                  "the feasibility and tightening stages' Hessian (after --hessian): exact or limited-memory");
  app->add_flag("--derivative-check", opt->derivative_check, "run Ipopt's second-order derivative checker");
  app->add_flag("--no-hints", opt->no_hints, "solve without the problem file's hints (its feasibility-stage aids)");
  app->add_flag("--no-continuation", opt->no_continuation,
                "solve without the problem file's continuation in its parameters (solve.continuation)");
  app->add_option("--print-level", opt->print_level, "Ipopt's print_level (0 = quiet)");
  app->add_option("--out", opt->out, "output directory (trajectory.csv, variables.csv, summary.json)")->required();
  return {app, [opt] { return optimizeCommand(*opt); }};
}

}  // namespace saltus::cli
