// The results of a sweep: one record per solve (DIR/runs/<id>/record.json, written when the
// solve ends) and the statistics per cell (problem, method, parameter values; every seed) that
// DIR/summary.csv and DIR/summary.json hold.
//
// A solve succeeds when it is feasible (Ipopt succeeded in every stage and every
// complementarity product is at most the problem's tolerance, paper §III: ε ≤ 1e-4) and, unless
// the spec says `success: feasible`, physically right (its replay in the time-stepper stays
// within tolerance, spec.hpp's ReplayCheck; without a replay check, feasible alone). The
// statistics of time, iterations, mean local error and cost are over the successful solves of a
// cell, as the paper's Figs. 6–8 show its solutions; the wall time over all solves is given too
// (the time to an answer).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace saltus::sweep {

struct SweepRecord {
  std::string id, problem, problem_name, method;
  std::map<std::string, double> set;
  std::string variant;  // the spec's variant (empty: none)
  unsigned seed = 0;
  std::string command;  // the saltus optimize command that reproduces the solve
  int exit_code = 0;    // of saltus optimize (0 feasible, 1 not feasible or an error)
  std::string status;   // Ipopt's status of the last stage, or "error" when no solution was written
  std::string error;    // the command's last line of standard error when it wrote no solution
  bool feasible = false;
  bool converged = false;  // feasible, and Ipopt solved the stage of the solution (solver.hpp)
  std::optional<bool> physical;     // replay within tolerance (absent: no replay check)
  // The spec's success rule (SweepSpec::physical_success): physical as well as feasible. Written
  // for the reader; readRecords sets it from the spec in force, not from the file.
  bool physical_required = true;
  double replay_deviation = -1;     // largest position deviation of the replay [m or rad]; −1: none
  std::string replay_message;       // why the replay did not complete
  int iterations = 0;
  double wall_seconds = 0, evaluation_seconds = 0;
  double largest_product = 0, mean_local_error = 0, objective = 0;
  int variables = 0, constraints = 0;
  int attempts = 0;

  bool success() const { return feasible && (!physical_required || physical.value_or(true)); }
};

nlohmann::ordered_json toJson(const SweepRecord& r);
// Throws std::runtime_error naming the missing or mistyped key.
SweepRecord recordFromJson(const nlohmann::json& j);

// Median, quartiles (linear interpolation between order statistics, as numpy's default) and range.
struct Quartiles {
  int count = 0;
  double min = 0, q1 = 0, median = 0, q3 = 0, max = 0;
};
Quartiles quartiles(std::vector<double> values);

struct CellSummary {
  std::string problem_name, method;
  std::map<std::string, double> set;
  std::string variant;
  int solves = 0, feasible = 0, converged = 0, physical = 0, successes = 0;
  double success_rate = 0;
  Quartiles wall_all;  // wall seconds over every solve
  Quartiles wall_seconds, iterations, mean_local_error, objective;  // over the successful solves
};

// One cell per (problem, method, parameter values, variant), in the order of their first record.
std::vector<CellSummary> summarise(const std::vector<SweepRecord>& records);

std::string summaryCsv(const std::vector<CellSummary>& cells);
// {"cells": [...], "records": [...]}: what the charts are drawn from.
nlohmann::ordered_json summaryJson(const std::vector<CellSummary>& cells, const std::vector<SweepRecord>& records);

}  // namespace saltus::sweep
