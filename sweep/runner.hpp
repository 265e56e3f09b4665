// Running a sweep (spec.hpp) on local processes. Each solve is a child process
// `saltus optimize ... --out DIR/runs/<id>/solution` (single-threaded: OMP_NUM_THREADS and
// OPENBLAS_NUM_THREADS are 1), its standard error in DIR/runs/<id>/optimize.log. When it ends,
// the runner reads its summary.json, replays a feasible solution in Saltus' time-stepper (the
// physical check, spec.hpp's ReplayCheck) and writes DIR/runs/<id>/record.json atomically
// (temporary file, then rename): a solve has a record exactly when it finished.
//
// Solves start seed by seed (the first seed of every cell, then the second, ...). Resumable:
// solves that have a record are skipped; a solve without one (it was running when the
// sweep was killed) starts again from an empty folder. Interrupted (SIGINT, SIGTERM), the runner
// stops its children, writes no record for them and returns; DIR/.lock (flock) keeps a second
// sweep out of the same folder while one runs.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "sweep/record.hpp"
#include "sweep/spec.hpp"

namespace saltus::sweep {

struct RunnerOptions {
  std::string saltus;  // the saltus program the solves run
  int jobs = 1;        // solves at once
  // Holds DIR/.lock while running (a local sweep). The tasks of a Slurm array share the folder and
  // run disjoint slices of it instead (slurm.hpp).
  bool lock = true;
  // A solve that ends by a signal, or by a saltus child's own interrupt status (130, 137, 143),
  // was stopped from outside (a Slurm time limit, memory limit, scancel, preemption): no record,
  // so that a resume runs it again, and the runner stops as if interrupted. Otherwise such a solve
  // gets an error record.
  bool stopped_solve_leaves_no_record = false;
};

struct Progress {
  int total = 0, done = 0, failed = 0, skipped = 0;  // skipped: had a record before this run
  double elapsed_seconds = 0;
  double eta_seconds = -1;  // −1 until a solve of this run has finished
  const SweepRecord* last = nullptr;  // the record just written (null: the call before the first solve)
};

struct RunResult {
  std::vector<SweepRecord> records;  // every case with a record, in the grid's order
  bool interrupted = false;
  int signal = 0;  // the signal that interrupted it (SIGINT, SIGTERM)
  int ran = 0;  // solves run by this call
  std::string stopped;  // the solve stopped from outside (stopped_solve_leaves_no_record), if any
};

// flock on DIR/.lock for the lifetime of the object: one local sweep or submission per folder.
// Throws std::runtime_error when another process holds it.
class DirectoryLock {
 public:
  explicit DirectoryLock(const std::string& dir);
  ~DirectoryLock();
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

 private:
  int fd_ = -1;
};

// The folder of a case, and its record.
std::string caseDirectory(const std::string& out, const SweepCase& c);
// Reads DIR/runs/*/record.json of the given cases (missing ones are skipped; a record that
// cannot be read throws std::runtime_error naming the file).
std::vector<SweepRecord> readRecords(const std::string& out, const std::vector<SweepCase>& cases);

// The `saltus optimize` command line a case's solve runs (its folder: case_dir), as a record shows it.
std::string optimizeCommand(const SweepCase& c, const std::string& case_dir);
// The cases whose record (in DIR) was made by another command than the case runs now, compared as
// text without their --out (the folder may have moved since): the spec changed since. Paths are
// compared as written, so a spec given by another path (absolute, or from another folder) flags
// every record. A resume keeps those records as they are, so a sweep that mixes them is no longer
// one grid; one line each: "ID: made by `...`, the spec now runs `...`".
std::vector<std::string> recordsOfAnotherCommand(const std::string& out, const std::vector<SweepCase>& cases);

// Builds the record of a finished solve from its folder (summary.json, optimize.log) and runs
// the replay check. `command` is the reproducing command line.
SweepRecord makeRecord(const SweepCase& c, const std::string& case_dir, int exit_code, const std::string& command,
                       const ReplayCheck& check);

// The order a run starts the solves in: seed by seed, the first seeds of every cell before the
// next seeds of any (the grid's order within a seed), so that a sweep stopped part-way (a
// session's end, a time limit) has a look at each cell, and a resume goes on from there.
// `saltus sweep --list` prints this order; records and reports keep the grid's.
std::vector<const SweepCase*> startOrder(const std::vector<SweepCase>& cases);

// Runs every case without a record (in startOrder); `progress` is called once before the first solve and after
// each solve. Throws std::runtime_error when DIR is locked by another sweep or a child cannot start.
RunResult runSweep(const SweepSpec& spec, const std::vector<SweepCase>& cases, const std::string& out,
                   const RunnerOptions& options, const std::function<void(const Progress&)>& progress);

// The command line as a shell would take it back (arguments quoted where needed).
std::string shellCommand(const std::vector<std::string>& arguments);

}  // namespace saltus::sweep
