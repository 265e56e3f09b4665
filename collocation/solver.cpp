#include "collocation/solver.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstdlib>
#include <dlfcn.h>
#include <malloc.h>
#include <fstream>
#include <unistd.h>
#include <stdexcept>

#include "collocation/nlp.hpp"

namespace saltus::collocation {

std::string ipoptStatusName(int status) {
  switch (status) {
    case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected: return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found: return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed: return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition: return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option: return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception: return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown: return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory: return "Insufficient_Memory";
    case Ipopt::Internal_Error: return "Internal_Error";
    default: return "Unknown_Status_" + std::to_string(status);
  }
}

namespace {

// Three process-wide settings for Ipopt with MUMPS, made once before the first solve:
//
// - MUMPS's dense kernels run in the system BLAS. Debian's OpenBLAS (pthreads) starts a thread
//   per core whose idle loop spins on sched_yield: on the biped (13,322 variables, 60
//   iterations) the spinning doubled the process's CPU time (25.8 core-s against 13.7, 11.6 s
//   of it in the kernel) for no gain in wall time, and under `saltus sweep --jobs 2` or a
//   one-core Slurm task it takes the core of the other solve. These KKT systems' fronts are
//   small: one thread. Looked up at run time, so another BLAS (reference, BLIS, MKL) is left alone.
// - MUMPS allocates its factor workspace (over 32 MB on the biped) at every factorisation. glibc
//   serves blocks that large with mmap and returns them with munmap, so each factorisation
//   faulted its pages in afresh and zeroed them (1.2 of 9.8 s in the kernel on the same 60
//   iterations). Kept in the heap below 512 MB instead (freed memory is trimmed above 1 GB):
//   9.8 s → 8.8 s. The process keeps its peak memory until it exits.
// - Debian's MUMPS orders its matrices with SCOTCH 7, whose nested dissection runs a thread
//   per core (SCOTCH_PTHREAD_NUMBER, its default). The threads' interleaving changes the
//   ordering, so a solve of the monopod or the biped came out different at every run (iterates
//   apart in the eighth digit by the sixth iteration; four runs, four different sequences):
//   with one thread every run is the same, bit for bit, as with MUMPS's AMD or QAMD orderings,
//   which cost the biped 35–45 % more per iteration (README). Unless the user's environment says
//   otherwise. SCOTCH's random generator is also reset before every stage
//   (resetOrderingRandomness): a second solve in the same process otherwise ordered from
//   where the first left the generator, and ended 0.01–0.1 away after 12 iterations.
void tuneProcessForSolves() {
  static const bool done = [] {
    using SetThreads = void (*)(int);
    if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) set(1);
    mallopt(M_MMAP_THRESHOLD, 512 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    ::setenv("SCOTCH_PTHREAD_NUMBER", "1", /*overwrite=*/0);
    return true;
  }();
  (void)done;
}

// SCOTCH_randomReset, looked up at run time as OpenBLAS's call above: a MUMPS without SCOTCH
// is left alone.
void resetOrderingRandomness() {
  using Reset = void (*)();
  static const auto reset = reinterpret_cast<Reset>(dlsym(RTLD_DEFAULT, "SCOTCH_randomReset"));
  if (reset) reset();
}

void setOption(Ipopt::IpoptApplication& app, const std::string& name, const std::string& value) {
  const auto option = app.RegOptions()->GetOption(name);
  if (!IsValid(option)) throw IpoptOptionError("unknown Ipopt option '" + name + "'");
  bool ok = false;
  try {
    switch (option->Type()) {
      case Ipopt::OT_Number: {
        std::size_t used = 0;
        const double x = std::stod(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
        ok = app.Options()->SetNumericValue(name, x);
        break;
      }
      case Ipopt::OT_Integer: {
        std::size_t used = 0;
        const int x = std::stoi(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
        ok = app.Options()->SetIntegerValue(name, x);
        break;
      }
      default: ok = app.Options()->SetStringValue(name, value); break;
    }
  } catch (const std::logic_error&) {
    ok = false;
  }
  if (!ok)
    throw IpoptOptionError("Ipopt option '" + name + "': invalid value '" + value + "' (expected " +
                           (option->Type() == Ipopt::OT_Number    ? "a number"
                            : option->Type() == Ipopt::OT_Integer ? "an integer"
                                                                  : "one of its names") +
                           ")");
}

}  // namespace

void checkIpoptOption(const std::string& name, const std::string& value) {
  static const Ipopt::SmartPtr<Ipopt::IpoptApplication> app = [] {
    Ipopt::SmartPtr<Ipopt::IpoptApplication> a = IpoptApplicationFactory();
    a->Options()->SetIntegerValue("print_level", 0);
    return a;
  }();
  setOption(*app, name, value);
}

namespace {

// The start of every stage's point within its bounds (Ipopt's bound_push and bound_frac), and the
// barrier parameter of a stage that starts near a solution (runStage explains both).
constexpr double kBoundPush = 1e-6;
constexpr double kWarmMuInit = 1e-4;

StageReport runStage(const Transcription& t, Stage stage, const Eigen::VectorXd& x0, const Multipliers& start,
                     const SolveOptions& options, Eigen::VectorXd& x_out, Multipliers& multipliers_out,
                     SolveReport& report, bool stop_when_feasible = false, double step_tolerance = -1) {
  // step_tolerance > 0: a tightening step's tolerance on the products (every ε bounded by 0.9 ×
  // it, a point within it is feasible), in place of the problem's.
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", options.print_level);
  app->Options()->SetStringValue("sb", "yes");  // no banner
  // Defaults (the problem file and the command line override them): the tolerance of the
  // paper group's public code (Shield et al., ICB 2021), and an acceptable level for the
  // complementarity problems, whose multipliers need not converge.
  app->Options()->SetNumericValue("tol", 1e-6);
  // Ipopt's default (1e-4, unscaled) would end a solve with integration residuals of 1e-7–1e-6
  // m or m/s; 1e-8 costs one or two iterations on the built-in problems.
  app->Options()->SetNumericValue("constr_viol_tol", 1e-8);
  app->Options()->SetNumericValue("acceptable_tol", 1e-4);
  app->Options()->SetIntegerValue("acceptable_iter", 10);
  app->Options()->SetIntegerValue("max_iter", 3000);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  const bool exact_hessian =
      stage == Stage::Task ? t.problem().exact_hessian : t.problem().feasibility_exact_hessian;
  app->Options()->SetStringValue("hessian_approximation", exact_hessian ? "exact" : "limited-memory");
  // Ipopt moves the starting point at least bound_push (default 1e-2) inside every bound: large
  // next to gaps of millimetres and impulses of a few N s. 1e-6 took the paper's perturbed seeds
  // from 9 to 16 successes of 40 on the built-in problems (bench/sweeps/perturbed_seeds.yaml).
  app->Options()->SetNumericValue("bound_push", kBoundPush);
  app->Options()->SetNumericValue("bound_frac", kBoundPush);
  const bool first_stage = stage == Stage::Feasibility || stage == Stage::Penalty;
  // A stage that starts near a solution (a tightening step or the task stage from the stage
  // before, or a first stage from a warm seed) starts at a small barrier parameter.
  if (!first_stage || options.warm_seed) app->Options()->SetNumericValue("mu_init", kWarmMuInit);
  // Ipopt's adaptive strategy ignores it (its oracle chooses its own), so the stages that only
  // restore feasibility from near a solution run under the monotone strategy, which keeps it: from
  // a warm seed the adaptive strategy's first barrier parameter was 50 on the drop and walked a
  // saved solution away from itself; on the full-body Ollie from a perturbed solution (S = 1e-4)
  // its tightening steps ran out of their 200 CPU s in 4 of 4 seeds, the monotone ones closed 3.
  // The task stage optimises and keeps the adaptive strategy: on the biped's stop the monotone one
  // converged in 39–220 iterations where the adaptive one ran out its 500, but to longer stopping
  // distances in 4 of 6 solves (measured with `saltus sweep`, README).
  if (stage == Stage::Tighten || (first_stage && options.warm_seed))
    app->Options()->SetStringValue("mu_strategy", "monotone");
  if (!start.empty()) {  // and its multipliers
    app->Options()->SetStringValue("warm_start_init_point", "yes");
    app->Options()->SetNumericValue("warm_start_bound_push", 1e-6);
    app->Options()->SetNumericValue("warm_start_bound_frac", 1e-6);
    app->Options()->SetNumericValue("warm_start_mult_bound_push", 1e-6);
  }
  if (t.problem().derivative_check) {
    app->Options()->SetStringValue("derivative_test", "second-order");
    app->Options()->SetNumericValue("derivative_test_perturbation", 1e-7);
  }
  // Every stage's options: the problem's, then the command line's.
  for (const auto& [name, value] : t.problem().ipopt_options) setOption(*app, name, value);
  for (const auto& [name, value] : options.ipopt) setOption(*app, name, value);
  const bool kept_warm_start = first_stage && options.warm_seed && options.keep_warm_start;
  if (kept_warm_start) {  // the warm start above, again
    app->Options()->SetNumericValue("mu_init", kWarmMuInit);
    app->Options()->SetStringValue("mu_strategy", "monotone");
  }
  // A tightening or task stage starts at the stage before's end, whose gaps and impulses sit
  // within millimetres and fractions of a newton-second of their bounds: a caller's bound_push for
  // a cold first stage (Ipopt's own 0.01) would move that point away before the first step.
  if (kept_warm_start || stage == Stage::Tighten || stage == Stage::Task) {
    app->Options()->SetNumericValue("bound_push", kBoundPush);
    app->Options()->SetNumericValue("bound_frac", kBoundPush);
  }
  if (stage == Stage::Task) {  // the task stage's own last: the problem's, then the command line's
    for (const auto& [name, value] : t.problem().task_ipopt_options) setOption(*app, name, value);
    for (const auto& [name, value] : options.task_ipopt) setOption(*app, name, value);
  }
  if (stage == Stage::Task && options.task_max_iter >= 0) app->Options()->SetIntegerValue("max_iter", options.task_max_iter);
  if (stage == Stage::Penalty) app->Options()->SetIntegerValue("max_iter", t.problem().penalty_iterations);
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw std::runtime_error("Ipopt failed to initialise");
  std::string barrier;  // as the options above and the caller's left it
  app->Options()->GetStringValue("mu_strategy", barrier, "");
  tuneProcessForSolves();
  resetOrderingRandomness();

  Ipopt::SmartPtr<Nlp> nlp = new Nlp(t, stage, x0, start, options.hints);
  nlp->setInterruption(options.interrupted);
  const double tolerance = step_tolerance > 0 ? step_tolerance : t.problem().complementarity_tolerance;
  if (stage == Stage::Tighten) nlp->boundProducts(kPenaltyBoundFraction * tolerance);
  if (stage != Stage::Feasibility) nlp->keepBestFeasible(tolerance, options.violation_tolerance);
  if (stop_when_feasible) nlp->stopWhenFeasible();
  const auto clock_start = std::chrono::steady_clock::now();
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(nlp)));
  StageReport r;
  r.name = toString(stage);
  if (stage == Stage::Tighten) r.product_bound = kPenaltyBoundFraction * tolerance;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  r.status_code = status;
  r.status = nlp->stoppedAtFeasible() ? "Stopped_At_Feasible_Point" : ipoptStatusName(status);
  r.succeeded = status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
  if (status == Ipopt::User_Requested_Stop && !nlp->stoppedAtFeasible()) report.interrupted = true;
  if (IsValid(app->Statistics())) r.iterations = app->Statistics()->IterationCount();
  r.evaluation_seconds = nlp->evaluationSeconds();
  r.exact_hessian = exact_hessian;
  r.barrier = barrier;
  r.hessian_evaluations = nlp->hessianEvaluations();
  x_out = nlp->solution().size() == t.variables() ? nlp->solution() : x0;
  multipliers_out = nlp->multipliers();
  // Evaluated here: Ipopt 3.11 hands finalize_solution an objective of 0 when it stops on its
  // CPU-time limit.
  r.objective = nlp->solution().size() == t.variables() ? nlp->cost(x_out) : 0;
  const auto measure = [&] {
    r.largest_product = t.largestProduct(x_out, &r.largest_product_at);
    const Eigen::VectorXd g = nlp->constraints(x_out);
    const Eigen::VectorXd off = (t.constraintLower() - g).cwiseMax(g - t.constraintUpper());
    Eigen::Index at = 0;
    r.largest_violation = off.size() > 0 ? std::max(0.0, off.maxCoeff(&at)) : 0.0;
    r.largest_violation_at = r.largest_violation > 0 ? t.constraintNames()[static_cast<std::size_t>(at)] : "";
    // Eigen's maxCoeff passes over NaN: a point that is not finite is nowhere near feasible.
    if (!x_out.allFinite() || !g.allFinite()) r.largest_violation = std::numeric_limits<double>::infinity();
    if (!std::isfinite(r.largest_product)) r.largest_product = std::numeric_limits<double>::infinity();
  };
  measure();
  // A stage Ipopt did not solve (iteration or time limit, restoration failure) may end away
  // from the feasible set, or at a feasible point worse than one it passed: its result is then
  // the best feasible point it evaluated (its starting point among them). On the biped's task
  // stage, which wanders 1e-4–1e-2 off the constraints while it lowers x_m, this keeps what it
  // gained (README).
  const bool end_feasible = r.largest_product <= tolerance && r.largest_violation <= options.violation_tolerance;
  if (nlp->hasBestFeasible() && !(r.succeeded && end_feasible) &&
      (!end_feasible || nlp->bestFeasibleObjective() < nlp->cost(x_out))) {
    x_out = nlp->bestFeasible();
    r.objective = nlp->bestFeasibleObjective();
    r.kept_iteration = nlp->bestFeasibleIteration();
    multipliers_out = {};  // the end point's, not this point's
    measure();
  }
  report.jacobian_nonzeros = nlp->jacobianNonzeros();
  report.hessian_nonzeros = nlp->hessianNonzeros();
  return r;
}

}  // namespace

bool tightensAfter(const StageReport& feasibility, double tolerance, double violation_tolerance, double tighten_within) {
  const StageReport& f = feasibility;
  if (f.largest_product <= tolerance && f.largest_violation <= violation_tolerance) return false;  // feasible
  if (!(f.largest_product <= tighten_within * tolerance)) return false;
  if (!std::isfinite(f.largest_product) || !std::isfinite(f.largest_violation)) return false;  // no point to start from
  // A stage stopped by its iteration or time limit is tightened as well: on the biped (μ = 1.6) the
  // feasibility stage reached its 3,000 iterations with products of 1.15e-4, 52 tightening
  // iterations from a solution; from products of 20 another became feasible in 629, from 11.8
  // another failed after 3,000 more. So is one whose restoration phase failed: from a perturbed
  // Ollie solution (scale 0.01, seed 2) the feasibility stage failed so with the constraints met
  // to 1e-9 and products of 0.015, a point to start from like any other (README).
  return f.succeeded || f.status_code == Ipopt::Maximum_Iterations_Exceeded ||
         f.status_code == Ipopt::Maximum_CpuTime_Exceeded || f.status_code == Ipopt::Restoration_Failed;
}

SolveReport solve(const Transcription& t, const Eigen::VectorXd& x0, const SolveOptions& options) {
  SolveReport report;
  report.variables = t.variables();
  report.constraints = t.constraints();
  const double tolerance = t.problem().complementarity_tolerance;
  // A stage's end point is feasible when every product is within the tolerance and every
  // constraint within options.violation_tolerance of its bounds, whatever Ipopt's status.
  const auto feasibleEnd = [&](const StageReport& s) {
    return s.largest_product <= tolerance && s.largest_violation <= options.violation_tolerance;
  };
  // The note tells how the result was reached, stage by stage: each stage's remark is added to it.
  const auto addNote = [&](const std::string& text) { report.note += (report.note.empty() ? "" : "; ") + text; };
  const auto keptNote = [](const StageReport& s) {
    return "the " + s.name + " stage ended " + s.status + "; kept the best feasible point it evaluated (a trial of iteration " +
           std::to_string(s.kept_iteration) + ")";
  };
  // Of two end points that are not feasible, whether a is nearer a trajectory than b: one that
  // meets the constraints before one that does not, then the smaller products, or the smaller
  // violation. A task stage stopped at its start, pushed inside its bounds (products 6.4,
  // constraints 10.7 off on ollie_simple), is not kept in place of a local minimum of the penalty
  // with the constraints met (products 1.8).
  const auto nearer = [&](const StageReport& a, const StageReport& b) {
    const bool a_met = a.largest_violation <= options.violation_tolerance;
    const bool b_met = b.largest_violation <= options.violation_tolerance;
    if (a_met != b_met) return a_met;
    return a_met ? a.largest_product < b.largest_product : a.largest_violation < b.largest_violation;
  };
  Eigen::VectorXd x = x0;
  Multipliers multipliers;
  std::size_t kept = 0;  // the stage whose point is the result
  // The task stage runs when there is a task cost, and also when hints shaped the feasibility
  // stage: they are a seeding aid, not part of the problem.
  const bool has_task = t.problem().task_stage && t.problem().cost.hasTask();
  const bool task_follows = !options.feasibility_only && (has_task || (options.hints && !t.problem().hints.empty()));
  // A feasibility stage (or the penalty stage) from `from`, then, for a feasibility stage, the
  // tightening stage when tightensAfter says so. x is the point reached; returns whether it is
  // feasible.
  StageReport first;
  const auto reachFeasible = [&](Stage stage, const Eigen::VectorXd& from) {
    // The penalty stage stops at its first feasible point when a task stage follows, as the
    // tightening stage does: Ipopt does not converge on it (its multipliers wander: the
    // complementarity problem's need not exist), but it reaches such a point fast.
    report.stages.push_back(
        runStage(t, stage, from, {}, options, x, multipliers, report, stage == Stage::Penalty && task_follows));
    first = report.stages.back();  // a copy: later push_backs reallocate
    kept = report.stages.size() - 1;
    if (feasibleEnd(first)) return true;
    // A local minimum of the penalty above the tolerance that Ipopt solved to its tolerance: the
    // stage again from its end, warm (a fresh, small barrier) and under the caller's bound push
    // (SolveOptions::feasibility_repeats). Not one that Ipopt ended at its acceptable level: on
    // the full-body Ollie's quarter-gravity sweep (assist 3) repeating those as well rescued seed 4
    // and lost seeds 2 and 3, 4 of seeds 1-7 feasible against 5, the feasible ones slower (a
    // median of 1,704 s against 974; README).
    SolveOptions again = options;
    again.warm_seed = true;
    again.keep_warm_start = false;
    for (int i = 0; stage == Stage::Feasibility && i < options.feasibility_repeats &&
                    first.status_code == Ipopt::Solve_Succeeded && !report.interrupted;
         ++i) {
      const Eigen::VectorXd before = x;
      const Multipliers multipliers_before = multipliers;
      // From its end made consistent, as a seed from a saved solution is: the gaps, the free points,
      // the slips and restitution pairs from the kinematics, every ε at its product.
      Eigen::VectorXd start = before;
      t.makeConsistent(start);
      report.stages.push_back(runStage(t, Stage::Feasibility, start, {}, again, x, multipliers, report));
      const StageReport repeat = report.stages.back();
      // Kept when Ipopt solved it (to its tolerance or its acceptable level) to lower products: the
      // penalty is what the stage minimises. Its constraints need not be within the feasibility
      // tolerance yet: on the full-body Ollie (seed 1) the repeat that the tightening closed ended
      // at products of 0.069 with them 1.9e-4 off, Solved_To_Acceptable_Level.
      if (!report.interrupted &&
          (feasibleEnd(repeat) || (repeat.succeeded && repeat.largest_product < first.largest_product))) {
        first = repeat;
        kept = report.stages.size() - 1;
        if (feasibleEnd(first)) return true;
      } else {  // the point before it
        x = before;
        multipliers = multipliers_before;
        if (!report.interrupted)
          addNote("the feasibility stage's repeat ended " + repeat.status + " at products of " +
                  std::to_string(repeat.largest_product) +
                  (repeat.largest_product < first.largest_product ? ", lower but not solved" : ", no lower") +
                  "; kept the point before it");
        break;
      }
    }
    if (stage == Stage::Penalty || report.interrupted || options.feasibility_only ||
        !tightensAfter(first, tolerance, options.violation_tolerance, options.tighten_within))
      return false;
    // A local minimum of the penalty with products above the tolerance (often just above: on a
    // resting mass, a staircase of small impulses at later boundaries), or a stage stopped on its
    // way down. The bounded products of the tightening stage, from this point, pull them under it
    // or fail; a failure keeps this point.
    // When a task stage follows (it polishes the point), the tightening stage stops at its first
    // feasible point: on ollie_simple (air goal 0.05 m) it evaluated one at iteration 15 and then
    // ran 2,100 more iterations to its time limit (README). Without one it converges: the result.
    // From products far above the tolerance the bound is lowered in steps (SolveOptions::
    // tighten_factor), each step stopping at its first point within its own bound.
    const Eigen::VectorXd x1 = x;
    Eigen::VectorXd from_step = x1;
    for (double bound = first.largest_product / options.tighten_factor;
         options.tighten_factor > 1 && bound > tolerance && !report.interrupted;) {
      report.stages.push_back(runStage(t, Stage::Tighten, from_step, {}, options, x, multipliers, report, true, bound));
      const StageReport& step = report.stages.back();
      if (!(step.largest_product <= bound && step.largest_violation <= options.violation_tolerance)) break;
      from_step = x;
      if (feasibleEnd(step)) break;  // the last step starts at a solution
      bound = std::min(bound, step.largest_product) / options.tighten_factor;
    }
    if (report.interrupted) {
      x = x1;
      return false;
    }
    report.stages.push_back(runStage(t, Stage::Tighten, from_step, {}, options, x, multipliers, report, task_follows));
    const StageReport& tight = report.stages.back();
    if (feasibleEnd(tight)) {
      kept = report.stages.size() - 1;
      if (tight.kept_iteration >= 0) addNote(keptNote(tight));
      return true;
    }
    x = x1;
    addNote("the tightening stage ended " + tight.status + "; kept the feasibility stage's point");
    return false;
  };
  // The penalty stage (Problem::penalty_iterations) first; when it ends without a feasible point,
  // the feasibility stage starts afresh from the seed. From the biped's penalty-stage points that
  // were not feasible, neither the tightening nor the feasibility stage got far (README).
  bool feasible = false;  // the point x
  if (t.problem().penalty_iterations > 0) {
    feasible = reachFeasible(Stage::Penalty, x0);
    if (!feasible && !report.interrupted) feasible = reachFeasible(Stage::Feasibility, x0);
  } else {
    feasible = reachFeasible(Stage::Feasibility, x0);
  }
  const bool task = task_follows && !report.interrupted;
  if (task && (first.succeeded || feasible)) {
    // x_m is not in the feasibility stage's cost, and the barriers of q ≤ x_m push it up (to 1e5 m
    // on the drop): the task stage starts from the largest coordinate instead.
    t.tightenMaxVariable(x);
    const Eigen::VectorXd x1 = x;
    // The multipliers help only near a solution: the earlier stage's are those of a point of the
    // real problem when its products are within the tolerance.
    const Multipliers start = options.warm_start_multipliers && feasible ? multipliers : Multipliers{};
    report.stages.push_back(runStage(t, Stage::Task, x1, start, options, x, multipliers, report));
    const StageReport& second = report.stages.back();
    if (feasibleEnd(second) || report.interrupted || (!feasible && nearer(second, report.stages[kept]))) {
      kept = report.stages.size() - 1;
      if (second.kept_iteration >= 0) {
        t.tightenMaxVariable(x);
        addNote(keptNote(second));
      }
    } else if (!feasible) {
      // Neither point is feasible: the earlier one is the nearer (a seed to continue from).
      x = x1;
      addNote("the task stage ended " + second.status + " no nearer a feasible point; kept the " +
              report.stages[kept].name + " stage's point");
    } else {
      // The earlier stage's point satisfies every constraint of the problem (hints only add
      // bounds): a valid trajectory, whose task cost the failed stage did not minimise.
      x = x1;
      addNote("the task stage ended " + second.status + " at an infeasible point; kept the " +
              report.stages[kept].name + " stage's solution");
    }
  }
  report.x = x;
  report.kept_stage = static_cast<int>(kept);
  const StageReport& end = report.stages[kept];
  report.largest_product = t.largestProduct(x, &report.largest_product_at);
  report.largest_violation = end.largest_violation;
  report.largest_violation_at = end.largest_violation_at;
  report.objective = end.objective;
  // A kept feasibility-stage point of a task problem: its task-stage objective (the task cost and
  // the weighted penalty), comparable with a task stage's.
  const bool task_kept = report.stages[kept].name == "task";
  if ((!task_kept || end.kept_iteration >= 0) && has_task) report.objective = Nlp(t, Stage::Task, x).cost(x);
  for (const StageReport& s : report.stages) {
    report.wall_seconds += s.wall_seconds;
    report.evaluation_seconds += s.evaluation_seconds;
    report.iterations += s.iterations;
  }
  report.feasible = !report.interrupted && feasibleEnd(end);
  // Converged: Ipopt solved the stage whose point is kept, and that stage minimised the task
  // cost when there is one (a tightening stage only pulls products under the tolerance).
  report.converged = report.feasible && end.succeeded && end.kept_iteration < 0 && (!has_task || task_kept);
  report.attempts.push_back({0, 0, report.feasible, report.largest_product, report.iterations, report.wall_seconds});
  return report;
}

SolveReport solve(const Transcription& t, const SeedFunction& seed, const SolveOptions& options) {
  SolveReport total;
  std::vector<AttemptReport> attempts;
  double wall = 0, eval = 0;
  int iterations = 0;
  const auto attempt = [&](const Seed& start, int k, int r) {
    SolveOptions o = options;
    o.warm_seed = options.warm_seed || start.warm;
    o.keep_warm_start = options.keep_warm_start || (start.warm && start.keep_warm_start);
    o.hints = options.hints && start.hinted;
    total = solve(t, start.x, o);
    wall += total.wall_seconds;
    eval += total.evaluation_seconds;
    iterations += total.iterations;
    AttemptReport a = total.attempts.front();
    a.attempt = k;
    a.resimulation = r;
    attempts.push_back(a);
    return total.feasible || total.interrupted;
  };
  for (int k = 0; k <= std::max(0, options.restarts); ++k) {
    if (attempt(seed(k), k, 0)) break;
    bool done = false;
    for (int r = 0; r < options.resimulations && options.resimulate && !done; ++r) {
      const std::optional<Seed> next = options.resimulate(total.x);
      if (!next) break;
      done = attempt(*next, k, r + 1);
    }
    if (done) break;
  }
  total.attempts = attempts;
  total.wall_seconds = wall;
  total.evaluation_seconds = eval;
  total.iterations = iterations;
  return total;
}

DerivativeCheckReport checkDerivatives(const Transcription& t, Stage stage, const Eigen::VectorXd& x,
                                       bool second_order, double tolerance) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  char path[] = "/tmp/saltus-derivative-check-XXXXXX";
  const int fd = ::mkstemp(path);
  if (fd < 0) throw std::runtime_error("derivative check: cannot create a temporary file");
  ::close(fd);
  auto& o = *app->Options();
  o.SetIntegerValue("print_level", 0);
  o.SetStringValue("sb", "yes");
  o.SetStringValue("output_file", path);
  o.SetIntegerValue("file_print_level", 5);
  o.SetStringValue("derivative_test", second_order ? "second-order" : "first-order");
  o.SetNumericValue("derivative_test_tol", tolerance);
  o.SetNumericValue("derivative_test_perturbation", 1e-7);
  o.SetIntegerValue("max_iter", 0);
  o.SetStringValue("hessian_approximation", "exact");
  // The check runs at the starting point: keep x where it is.
  o.SetNumericValue("bound_push", 1e-12);
  o.SetNumericValue("bound_frac", 1e-12);
  DerivativeCheckReport r;
  if (app->Initialize() == Ipopt::Solve_Succeeded) {
    Ipopt::SmartPtr<Nlp> nlp = new Nlp(t, stage, x);
    app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(nlp)));
  }
  app = nullptr;  // closes the output file
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("No errors detected by derivative checker") != std::string::npos) r.ran = true;
    const auto k = line.find("Derivative checker detected");
    if (k != std::string::npos) {
      r.ran = true;
      r.errors = std::atoi(line.c_str() + k + std::string("Derivative checker detected").size());
    }
    if (line.find('*') != std::string::npos && (line.find("Grad") != std::string::npos ||
                                                line.find("jac_g") != std::string::npos ||
                                                line.find("obj_hess") != std::string::npos ||
                                                line.find("hess") != std::string::npos))
      r.log += line + "\n";
  }
  std::remove(path);
  return r;
}

}  // namespace saltus::collocation
