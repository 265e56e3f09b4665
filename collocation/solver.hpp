// The two-stage solve of paper §V.C with Ipopt: first the feasibility stage (minimise the
// complementarity penalty Σ ε from the seed, hints applied), then, when the problem has a task
// cost or hints, the task stage (minimise the task cost and the weighted penalty with every
// ε ≤ the complementarity tolerance and without the hints, warm-started from the first stage:
// its point, and (by default) its multipliers with Ipopt's warm_start_init_point). A feasibility
// stage that ends just short of the tolerance is tightened in between (SolveOptions::tighten_within).
//
// A solution is feasible when, at its point, every product A·B is at most the tolerance (1e-4)
// and every constraint is within SolveOptions::violation_tolerance of its bounds, whatever
// Ipopt's status; it is converged when, in addition, Ipopt solved the stage it comes from and
// that stage minimised the task cost (when the problem has one). A task stage stopped by its
// iteration limit at a feasible point gives a feasible, not converged, solution (a valid
// trajectory whose cost is not proven locally minimal); one that ends at an infeasible point
// leaves the best feasible point it evaluated (or the feasibility stage's point) as the result,
// also not converged.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "collocation/nlp.hpp"
#include "collocation/transcription.hpp"

namespace saltus::collocation {

struct StageReport {
  std::string name;           // "feasibility" or "task"
  std::string status;         // Ipopt's status name, e.g. "Solve_Succeeded"
  int status_code = 0;        // Ipopt's ApplicationReturnStatus
  bool succeeded = false;     // Solve_Succeeded or Solved_To_Acceptable_Level
  int iterations = 0;
  double objective = 0;
  double largest_product = 0;
  std::string largest_product_at;  // the product's constraint name
  double largest_violation = 0;   // of a constraint's bounds (before the products' ε), at its end
  std::string largest_violation_at;  // that constraint's name (empty when every bound holds)
  double wall_seconds = 0;
  double evaluation_seconds = 0;  // in our function and derivative callbacks
  bool exact_hessian = true;      // false: Ipopt's limited-memory quasi-Newton (Problem)
  int hessian_evaluations = 0;    // of the Lagrangian's exact Hessian (none with quasi-Newton)
  std::string barrier;            // Ipopt's mu_strategy in the stage: "monotone" or "adaptive"
  // ≥ 0: the stage's result is not its end point but the best feasible point it evaluated, a
  // trial of this iteration (0: its starting point); the task and tightening stages only.
  int kept_iteration = -1;
  // A tightening stage's bound on every ε (0.9 × the tolerance for the last; a step of the
  // continuation, SolveOptions::tighten_factor, has its own); 0 for the other stages.
  double product_bound = 0;
};

// One attempt of a solve with restarts.
struct AttemptReport {
  int attempt = 0;       // k: the seed function's point for this attempt (random_seed + k)
  int resimulation = 0;  // r ≥ 1: the r-th re-simulation after it (SolveOptions::resimulate); 0: the seed
  bool feasible = false;
  double largest_product = 0;
  int iterations = 0;
  double wall_seconds = 0;
};

struct SolveReport {
  std::vector<StageReport> stages;  // of the last attempt
  // The stage of `stages` whose point is x: the last, or an earlier one when the note says so.
  // Its status is the solve's (a task stage of no iterations after an infeasible feasibility
  // stage ends Maximum_Iterations_Exceeded, and the feasibility stage's point is the result).
  int kept_stage = -1;
  const StageReport& keptStage() const { return stages.at(kept_stage < 0 ? stages.size() - 1 : kept_stage); }
  std::vector<AttemptReport> attempts;
  // Set when the task (or tightening) stage ended at an infeasible point and the feasibility
  // stage's point was kept.
  std::string note;
  Eigen::VectorXd x;      // the solution: the last stage's end point, or the note's
  bool feasible = false;   // products ≤ tolerance and constraints within violation_tolerance at x
  bool converged = false;  // feasible, and Ipopt solved the (task) stage x comes from
  bool interrupted = false;  // SolveOptions::interrupted stopped it (not feasible)
  double largest_product = 0;
  std::string largest_product_at;  // the product's constraint name (e.g. "impact.ball[10,0]")
  double largest_violation = 0;    // of a constraint's bounds at x
  std::string largest_violation_at;  // that constraint's name (e.g. "defect.q.board_z[12,1]"; empty: none)
  double objective = 0;   // the objective of the stage x comes from
  double wall_seconds = 0, evaluation_seconds = 0;
  int iterations = 0;
  int variables = 0, constraints = 0, jacobian_nonzeros = 0, hessian_nonzeros = 0;
};

// The starting point of attempt k = 0, 1, …, and whether it is close to a solution (an earlier
// solution, a simulation): then Ipopt starts with a small barrier parameter and keeps the point
// close to its bounds, as with SolveOptions::warm_seed.
struct Seed {
  Eigen::VectorXd x;
  bool warm = false;
  // The problem's hints bound its first stage. A re-simulated seed has none: it carries the
  // motion the inputs found, and a hint chosen for a cold seed would pull it off that motion.
  bool hinted = true;
  // A warm seed whose start (SolveOptions::warm_seed) holds over the Ipopt options given for the
  // solve: a re-simulated seed's, whose solve's options were chosen for the cold seeds before it.
  bool keep_warm_start = false;
};

struct SolveOptions {
  int print_level = 0;  // Ipopt's print_level (0 … 12)
  std::map<std::string, std::string> ipopt;  // extra options (the problem's, then the command line's)
  // The task stage's extra options, after `ipopt` (the problem's task_ipopt, then these).
  std::map<std::string, std::string> task_ipopt;
  // The task stage starts from the feasibility stage's multipliers as well as its point.
  bool warm_start_multipliers = true;
  // The seed is close to a solution (an earlier solution): the feasibility stage starts with a
  // small barrier parameter (Ipopt's monotone strategy from mu_init 1e-4) and keeps the seed close
  // to its bounds, as the tightening stages do.
  bool warm_seed = false;
  // The warm start above (mu_init, the monotone barrier, bound_push and bound_frac 1e-6) over the
  // problem's and the caller's Ipopt options in the first stage (Seed::keep_warm_start).
  bool keep_warm_start = false;
  // The problem's hints bound the first stage (Seed::hinted).
  bool hints = true;
  // Largest violation of a constraint's bounds at a feasible point, in the constraints' own SI
  // units (metres, m/s, N·s). Ipopt's constr_viol_tol (1e-8 here) applies to its scaled problem:
  // a biped's feasibility stage that Ipopt solved ended 1.05e-6 off in SI units.
  double violation_tolerance = 1e-5;
  // Iteration limit of the task stage (its max_iter, over the problem's and the command line's;
  // −1: the same as the feasibility stage). A task stage that reaches it at a feasible point
  // leaves a feasible, not converged, solution.
  int task_max_iter = -1;
  int restarts = 0;  // further attempts after an infeasible end (solve with a SeedFunction)
  // A feasibility stage that Ipopt solved (Solve_Succeeded, not Solved_To_Acceptable_Level) at a
  // local minimum of the penalty above the tolerance is run again from its end, up to this many
  // times, before any tightening: the same stage from that end made consistent
  // (Transcription::makeConsistent: the gaps, free points, slips and ε from the kinematics, as a
  // seed from a saved solution is) as a warm seed (the monotone barrier from μ₀ = 1e-4, where the
  // stage before ended at Ipopt's smallest, unless the caller's Ipopt options set them), with the
  // caller's bound_push and bound_frac, which move the point off the bounds it sat on. A repeat is
  // kept when it is feasible, or when Ipopt solved it (Solve_Succeeded or
  // Solved_To_Acceptable_Level) to lower products; the repeats go on while Ipopt ends them
  // Solve_Succeeded above the tolerance. One that is not kept ends them, its start the point (the
  // note says so). A restart (above) would start from a new perturbation and lose the stage's
  // work. On the full-body Ollie (quarter-gravity continuation, assist 3, seed 1; bound_push 0.01)
  // the feasibility stage solved at products of 1.25 and the tightening from there lost the
  // constraints; the same stage from its saved end (a second solve) ended at 0.069 and the
  // tightening from there was feasible (README).
  int feasibility_repeats = 0;
  // The feasibility (or penalty) stage alone, with its repeats: no tightening and no task stage (a step of a
  // continuation in the problem's parameters, whose end only seeds the next step).
  bool feasibility_only = false;
  // After an attempt that ends infeasible, up to this many further attempts, each from
  // `resimulate` of the previous attempt's end point (a chain, before the next restart's seed):
  // the time-stepper's motion under that point's inputs (seedFromResimulation). Empty
  // `resimulate` or a std::nullopt from it (the simulation failed) ends the chain.
  int resimulations = 0;
  std::function<std::optional<Seed>(const Eigen::VectorXd& end)> resimulate;
  // A feasibility stage that ends (Ipopt succeeded, stopped by its iteration or time limit, or its
  // restoration phase failed; tightensAfter) with its largest product above the tolerance, but
  // within this many times it, is tightened:
  // a stage minimising Σ ε with every ε bounded by 0.9 × the tolerance (the paper's bounded form
  // of eq. 8), from that point, before any task stage; when it fails the feasibility stage's
  // point is kept. Default: always; 0: never. On the perturbed simulation seeds of
  // bench/sweeps/seeds.yaml it turned 58 of 107 failed impulsive solves into successes, 43 of
  // them with products within 10 times the tolerance; the biped's (μ = 1.6, seed 1) feasibility
  // stage stopped at its 3,000 iterations with products of 1.15e-4 and tightened in 52 (README).
  double tighten_within = std::numeric_limits<double>::infinity();
  // From a feasibility stage whose products are far above the tolerance, the tightening stage's
  // bound is lowered in steps, a continuation in the manner of Scholtes's regularisation
  // (S. Scholtes, "Convergence properties of a regularization scheme for mathematical programs
  // with complementarity constraints", SIAM J. Optim. 11(4):918–936, 2001): every ε bounded by
  // 0.9 × P / F (P the feasibility stage's largest product), then by F less (from the lower of
  // the bound and the products reached) each step, each stopping at its first point within its
  // bound, until the bound reaches the tolerance; the last step is the tightening stage above.
  // A step that fails leaves the last step from the point before it. ≤ 1: one step. On the
  // biped (μ = 1.6, perturbed seeds), from feasibility stages that ended at products of 0.22–200,
  // one step was feasible on 6 of 16 (the others out of their 3,000 iterations 0.0025–13 off the
  // constraints), the steps on 11 of 15 (the first step 341–2,162 iterations, each later one
  // 4–151) (README).
  double tighten_factor = 10;
  // Called at every Ipopt iteration (its intermediate callback); true stops the solve there
  // (Ipopt's User_Requested_Stop) with no further stage or attempt: a user's Ctrl-C.
  std::function<bool()> interrupted;
};

using SeedFunction = std::function<Seed(int attempt)>;

// Thrown for an Ipopt option that does not exist or has a value of the wrong type.
class IpoptOptionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Checks an Ipopt option against Ipopt's registered options before any solve: the name exists and
// the value has its type (and, for a name-valued option, is one of its names). Throws
// IpoptOptionError.
void checkIpoptOption(const std::string& name, const std::string& value);

// Whether the tightening stage follows a feasibility stage that ended as `feasibility` reports: its
// point is not feasible (products within `tolerance`, constraints within `violation_tolerance`),
// its products are within tighten_within × tolerance (SolveOptions::tighten_within), and Ipopt
// ended the stage at a (local) solution, at its iteration or time limit, or after its restoration
// phase failed; not after an error in its step or an interruption.
bool tightensAfter(const StageReport& feasibility, double tolerance, double violation_tolerance, double tighten_within);

// One attempt from x0 (options.restarts is ignored).
SolveReport solve(const Transcription& t, const Eigen::VectorXd& x0, const SolveOptions& options);
// Up to 1 + options.restarts attempts, from seed(0), seed(1), …, each followed, while it ends
// infeasible, by up to options.resimulations attempts from options.resimulate of the previous
// end, until one is feasible; the
// report is the feasible attempt's (or the last one's), with every attempt listed and the
// times and iterations summed over them.
SolveReport solve(const Transcription& t, const SeedFunction& seed, const SolveOptions& options);

// Ipopt's derivative checker (derivative_test = second-order) at x: the gradient of the cost, the
// Jacobian of the constraints and the Hessian of the Lagrangian of one stage against Ipopt's own
// finite differences, without iterating. Ipopt writes its findings to a temporary file, parsed
// here; `log` keeps the lines about the entries it flagged.
struct DerivativeCheckReport {
  bool ran = false;  // Ipopt ran the checker (its summary line was found)
  int errors = 0;    // entries whose relative error exceeds derivative_test_tol
  std::string log;
};
// Ipopt 3.11's checker costs about n·m·nnz: seconds for a few hundred variables, minutes for a
// thousand; `second_order` = false checks the gradient and the Jacobian only.
DerivativeCheckReport checkDerivatives(const Transcription& t, Stage stage, const Eigen::VectorXd& x,
                                       bool second_order = true, double tolerance = 1e-4);

// Ipopt's name of an ApplicationReturnStatus, e.g. "Infeasible_Problem_Detected".
std::string ipoptStatusName(int status);

}  // namespace saltus::collocation
