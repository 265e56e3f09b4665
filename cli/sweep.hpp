// What `saltus sweep` shares between its local runner (sweep.cpp) and its Slurm side
// (sweep_slurm.cpp): the options, and the summary, charts and report built from the records.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "sweep/record.hpp"
#include "sweep/runner.hpp"
#include "sweep/slurm.hpp"
#include "sweep/spec.hpp"

namespace saltus::cli {

struct SweepOptions {
  std::string spec;
  std::string out;
  int jobs = 0;
  bool list = false;
  // Slurm
  bool slurm = false;
  bool script_only = false;
  sweep::slurm::SubmitOptions submit;
};

// Writes DIR/summary.csv, DIR/summary.json, DIR/charts/ and DIR/report.md from the records (each
// file atomically); `spec` is named in the report as written. Returns the charts' error message
// ("" when they were drawn or there was nothing to draw).
std::string writeSweepSummary(const std::string& spec, const std::string& out, const std::vector<sweep::SweepCase>& cases,
                              const std::vector<sweep::SkippedCell>& skipped,
                              const std::vector<sweep::SweepRecord>& records);

// One line on standard error: "saltus sweep: 18 of 24 solves have a record (...), 17 succeeded -> DIR/report.md".
void printSweepLine(const std::string& out, std::size_t records, std::size_t cases, int ran,
                    const std::vector<sweep::SweepRecord>& all);

// One solve's outcome in a line ("success (Solve_Succeeded, 12 it, 0.31 s, ...)").
std::string sweepOutcome(const sweep::SweepRecord& r);

// The progress of a runner (one line per finished solve, or a bar on a terminal).
void printSweepProgress(const sweep::Progress& p, bool terminal);

// sweep_slurm.cpp: `saltus sweep SPEC --out DIR --slurm`, and the subcommands that follow it.
int submitSweep(const SweepOptions& opt, const std::vector<sweep::SweepCase>& cases,
                const std::vector<sweep::SkippedCell>& skipped);
// Registers `sweep status`, `sweep collect` and (for the batch script) `sweep task` under `sweep`;
// the returned function runs the one that was given and returns false when none was.
std::function<bool(int&)> addSweepSubcommands(CLI::App& sweep);

}  // namespace saltus::cli
