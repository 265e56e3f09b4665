// The options of `saltus optimize` and their checks, shared with `saltus run`, which checks its
// optimize step's options before it creates anything.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "saltus/saltus.hpp"

namespace saltus::cli {

struct OptimizeCliOptions {
  std::string problem;
  std::string method = "impulsive";
  std::optional<int> P, N;
  std::optional<unsigned> seed;
  std::string seed_kind;
  std::string seed_from;
  std::string seed_method;  // --seed-method: a first solve with this method seeds this one
  std::string seed_inputs;
  std::optional<double> seed_scale;
  std::optional<int> restarts;
  std::optional<int> resimulations;
  std::optional<double> resimulation_tracking;
  std::optional<double> tighten_within;
  std::optional<double> tighten_factor;
  std::optional<int> feasibility_repeats;
  std::optional<int> task_max_iter;
  std::optional<int> penalty_iterations;
  std::string task_penalty;  // --task-penalty on|off; empty: the problem's
  std::vector<std::string> set, ipopt, task_ipopt;
  std::string hessian;              // every stage's: exact or limited-memory
  std::string feasibility_hessian;  // the feasibility and tightening stages'
  int print_level = 0;
  bool derivative_check = false;
  bool no_hints = false;  // --no-hints
  bool no_continuation = false;  // --no-continuation
  std::string out;
};

struct OptimizeCall {
  collocation::Problem problem;
  OptimizeOptions options;
};

// The problem loaded and the options checked (adjustedProblem included), as the solve will use
// them; throws UsageError naming the option, or the loaders' errors naming file and line.
OptimizeCall prepareOptimize(const OptimizeCliOptions& options);

}  // namespace saltus::cli
