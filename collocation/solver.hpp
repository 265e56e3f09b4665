// The two-stage solve of paper §V.C with Ipopt: first the feasibility stage (minimise the
// complementarity penalty Σ ε from the seed, hints applied), then, when the problem has a task
// cost or hints, the task stage (minimise the task cost and the weighted penalty with every
// ε ≤ the complementarity tolerance and without the hints, warm-started from the first stage). A solution is feasible when Ipopt succeeded and every product A·B is
// at most the tolerance (1e-4).
#pragma once

#include <map>
#include <string>
#include <vector>

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
  double wall_seconds = 0;
  double evaluation_seconds = 0;  // in our function and derivative callbacks
};

struct SolveReport {
  std::vector<StageReport> stages;
  Eigen::VectorXd x;      // the last stage's solution
  bool feasible = false;  // every stage succeeded and every product ≤ tolerance
  double largest_product = 0;
  double objective = 0;   // the last stage's objective
  double wall_seconds = 0, evaluation_seconds = 0;
  int iterations = 0;
  int variables = 0, constraints = 0, jacobian_nonzeros = 0, hessian_nonzeros = 0;
};

struct SolveOptions {
  int print_level = 0;  // Ipopt's print_level (0 … 12)
  std::map<std::string, std::string> ipopt;  // extra options (the problem's, then the command line's)
};

// Thrown for an Ipopt option that does not exist or has a value of the wrong type.
class IpoptOptionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

SolveReport solve(const Transcription& t, const Eigen::VectorXd& x0, const SolveOptions& options);

// Ipopt's name of an ApplicationReturnStatus, e.g. "Infeasible_Problem_Detected".
std::string ipoptStatusName(int status);

}  // namespace saltus::collocation
