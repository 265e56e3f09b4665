// A sweep: the grid of solves problems × methods × parameter values × variants × seeds that `saltus sweep`
// runs (the protocol of the paper's §V.C: many seeded solves, statistics per case). Read from a
// YAML spec (format in the README, "saltus sweep"):
//
//   problems: [point_mass_drop, drops/drop.yaml]   # built-in names or files (relative to the spec)
//   methods: [impulsive, first-order, impulsive from first-order]  # the last a two-step solve
//   set: {restitution: [0, 0.5], height: [0.05, 0.3]}  # every combination, for every problem
//   seeds: {from: 1, count: 10}                         # or a list [1, 2, 7]
//   options: {N: 20, restarts: 0}                        # passed to every solve
//   options: {seed_from: solutions/ollie, seed_scale: 1e-4}  # an earlier solution, perturbed
//   variants: {baseline: {}, monotone: {ipopt: {mu_strategy: monotone}}}  # each over the grid
//   success: physical                                    # or feasible (below)
//
// A problem may carry a grid of its own, combined with the top-level one:
//   problems: [{problem: pendulum_conveyor, set: {friction: [0.2, 4]}}]
// Every error is a scene::ScenarioError naming the file, line, column and key; expandSweep also
// loads every problem with each of its parameter combinations, so a parameter the problem lacks
// or a value it refuses is reported before any solve starts.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "verify/replay.hpp"

namespace saltus::sweep {

// Options of `saltus optimize` passed to every solve.
struct SolveSettings {
  std::optional<int> N, P, restarts, resimulations;
  std::optional<double> seed_scale;
  std::optional<double> resimulation_tracking;  // --resimulation-tracking
  std::optional<double> tighten_within;  // --tighten-within
  std::optional<double> tighten_factor;  // --tighten-factor
  std::optional<int> feasibility_repeats;  // --feasibility-repeats
  std::optional<int> task_max_iter;      // --task-max-iter
  std::optional<int> penalty_iterations;  // --penalty-iterations
  std::optional<bool> task_penalty;       // --task-penalty on|off
  std::string seed_kind;  // --seed-kind: null, perturbed or simulation; empty: the problem's
  // --seed-from: an earlier solution's folder (or its trajectory.csv), read relative to the
  // spec, perturbed by seed_scale in every solve (the paper's §VI strategy 4); not with
  // seed_kind or a two-step method, which choose the seed otherwise.
  std::string seed_from;
  bool hints = true;      // false: --no-hints
  bool continuation = true;  // false: --no-continuation
  std::string hessian;              // --hessian: "", "exact" or "limited-memory"
  std::string feasibility_hessian;  // --feasibility-hessian: the same
  std::map<std::string, std::string> ipopt;  // --ipopt name=value
  std::map<std::string, std::string> task_ipopt;  // --task-ipopt name=value
};

// The physical check of every solution: a replay in Saltus' time-stepper (verify/replay.hpp)
// from the optimised initial state, driven by the optimised inputs; the solution is physically
// right when the replayed positions stay within the tolerance of the optimised ones.
struct ReplayCheck {
  bool enabled = true;
  double dt = 1e-4;
  double tolerance = 0;  // 0: verify::ReplayOptions' default (10 m/s × dt)
  // restart: mesh (or mesh-after-jumps): from the optimised state at every mesh point
  // (verify::Restart), for motions that open loop diverge whatever the solution's accuracy (a
  // biped on one foot).
  verify::Restart restart = verify::Restart::None;
};

struct ProblemEntry {
  std::string problem;  // built-in name or path (resolved against the spec's folder)
  std::map<std::string, std::vector<double>> set;  // this problem's own grid
};

struct SweepSpec {
  std::string file;  // where it was read from ("" when built in C++)
  std::vector<ProblemEntry> problems;
  std::vector<std::string> methods;
  std::map<std::string, std::vector<double>> set;  // for every problem
  std::vector<unsigned> seeds;
  SolveSettings options;
  // Alternatives compared over the whole grid (`variants: {NAME: {options it changes}}`), each
  // with its options in full: `options` with the variant's keys in place of its own (ipopt and
  // task_ipopt entries added). In the spec's order; empty: one, unnamed, `options` itself.
  std::vector<std::pair<std::string, SolveSettings>> variants;
  // The variants, or {"", options} without any.
  std::vector<std::pair<std::string, SolveSettings>> settings() const;
  ReplayCheck replay;
  // What a successful solve is (`success:`): physical (the default) — feasible and, with the
  // replay check, physically right; feasible — feasible alone, the paper's success (§V.C, its
  // authors' code: every complementarity product at most 1e-4), the replay still run and
  // counted under `physical` beside it.
  bool physical_success = true;
};

// A method of the grid as listed: "M" (saltus optimize --method M) or "M from S", a two-step
// solve: S from the sweep's seed, then M from S's solution (--method M --seed-method S). Throws
// std::invalid_argument for anything else, or M and S the same.
struct MethodLabel {
  std::string method, seed_method;  // seed_method empty for a single solve
};
MethodLabel splitMethod(const std::string& label);

// One solve of the grid.
struct SweepCase {
  std::string id;       // directory name under DIR/runs, unique and stable across runs of a spec
  std::string problem;  // as passed to saltus optimize
  std::string problem_name;  // the problem's `name`
  std::string method;  // as listed: "M" or "M from S" (splitMethod)
  std::map<std::string, double> set;  // the grid's values (sorted by name)
  std::string variant;   // the spec's variant (empty: none)
  SolveSettings options;  // the variant's options (SweepSpec::settings)
  unsigned seed = 1;
  bool physical_required = true;  // the spec's success rule (SweepSpec::physical_success)
  // A cell of the summary: problem, method, parameter values and variant (every seed of a cell):
  // "pendulum_conveyor impulsive friction=0.5 [monotone]".
  std::string cell() const;
  // The arguments after `saltus`: optimize PROBLEM --method M --seed S --set ... (options) --out OUT.
  std::vector<std::string> optimizeArguments(const std::string& out) const;
};

SweepSpec readSweepSpec(const std::string& path);
// Parses a spec from text; `file` names it in messages and relative problem paths are resolved
// against its folder.
SweepSpec parseSweepSpec(const std::string& text, const std::string& file);

// A cell of the grid left out because its method cannot represent the problem there
// (collocation::methodCannotTake: restitution for the continuous and first-order methods).
struct SkippedCell {
  std::string problem_name, method;
  std::map<std::string, double> set;
  std::string reason;
};

// The grid, in a fixed order (problem, method, parameter values, seed). Loads every problem with
// each parameter combination (and transcribes it for each method), so that an unknown
// parameter, a refused value or a bad mesh is an error now, naming the spec's key. Cells whose
// method cannot represent the problem are left out (listed in `skipped` when given); a grid
// left with no solve at all is an error naming the first reason.
std::vector<SweepCase> expandSweep(const SweepSpec& spec, std::vector<SkippedCell>* skipped = nullptr);

// A value as it appears in ids and commands: shortest text that reads back to the same double.
std::string formatValue(double x);

}  // namespace saltus::sweep
