// A sweep on a Slurm cluster: the grid's solves without a record submitted as one job array,
// each array task running a fixed slice of them through the local runner (runner.hpp, one solve
// at a time), and what Slurm says about the tasks afterwards. Saltus schedules nothing itself:
// Slurm decides where and when, the records in DIR/runs decide what is done.
//
// The sweep folder on the shared file system:
//   DIR/sweep.json                  the spec and the folder as the user wrote them, and the working
//                                   directory they are relative to (written by every sweep)
//   DIR/slurm/sweep.sbatch          the batch script of the last submission (readable, commented)
//   DIR/slurm/cases-<k>.txt         the ids of submission k's solves, one per line: task i runs
//                                   lines i·B … i·B + B − 1 (B solves per task)
//   DIR/slurm/jobs.json             the submissions: job id, tasks, solves per task, cases file
//   DIR/slurm/logs/<job>_<task>.log each task's standard output and error
//
// The commands are Slurm's own (sbatch, squeue, sacct, scontrol), found in PATH; SLURM_CONF and
// the rest of the environment pass through to them.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "sweep/spec.hpp"

namespace saltus::sweep::slurm {

// Slurm refused or failed: the message is Slurm's own, prefixed with the command.
class SlurmError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a program printed and how it ended (exit code, or 128 + signal; −1: it could not start).
struct ProgramResult {
  int status = -1;
  std::string out, err;
};
// Runs `argv` (argv[0] looked up in PATH) to its end, standard input from /dev/null.
ProgramResult runProgram(const std::vector<std::string>& argv);

// How the array is sized: one task per solve while the solves fit in Slurm's MaxArraySize (task
// ids 0 … MaxArraySize − 1), else the smallest fixed batch of solves per task that fits.
struct ArrayPlan {
  int solves = 0;
  int tasks = 0;
  int solves_per_task = 1;
};
// `solves_per_task` > 0 fixes the batch (the array must still fit); throws std::invalid_argument
// naming --solves-per-task when it cannot.
ArrayPlan planArray(int solves, int max_array_size, int solves_per_task = 0);

// MaxArraySize from `scontrol show config`; Slurm's default (1001) when it cannot be read.
int maxArraySize();

// The user's choices for the job array (`saltus sweep --slurm` options).
struct SubmitOptions {
  std::string partition, time, mem;  // empty: the cluster's defaults
  int max_parallel = 0;              // the array's %K (0: no limit of our own)
  int solves_per_task = 0;           // 0: planArray decides
  std::vector<std::string> sbatch_args;  // further sbatch options, one per #SBATCH line
};

// Everything the batch script names. Paths in it are absolute, except spec and out, which are
// passed as the user wrote them and read from `working_directory` (the task's --chdir), so a
// record's command is the same as a local sweep's.
struct ScriptInputs {
  std::string saltus;             // the saltus program every task runs (absolute)
  std::string spec, out;          // as given on the command line
  std::string working_directory;  // where the sweep was submitted from
  std::string out_absolute;       // DIR, absolute
  std::string cases_file;         // absolute
  std::string job_name;
  std::string submitted_by;       // the submitting command line, for the script's header
  ArrayPlan plan;
  SubmitOptions options;
};
// The batch script (#!/bin/bash, commented, #SBATCH lines, then one `exec saltus sweep task`).
// Throws std::invalid_argument when a path cannot go on an #SBATCH line (white space, %).
std::string sbatchScript(const ScriptInputs& in);

// `sbatch --parsable SCRIPT`: the job id. Throws SlurmError with sbatch's message when refused.
std::string submit(const std::string& script_path);

// One array task as Slurm sees it.
struct TaskState {
  std::string job_id;  // the array's job id
  int task = -1;       // its index
  std::string state;   // PENDING, RUNNING, COMPLETED, FAILED, TIMEOUT, CANCELLED, OUT_OF_MEMORY, ...
  std::string reason;  // squeue's reason for a pending task
};
// The tasks of the given arrays: pending and running ones from squeue, finished ones from sacct,
// or from `scontrol show job` when the cluster keeps no accounting (a finished task stays there
// for MinJobAge). Tasks Slurm no longer knows are absent. `source` (when given) says where the
// finished states came from ("sacct", "scontrol" or "" when neither answered).
std::vector<TaskState> queryTasks(const std::vector<std::string>& job_ids, std::string* source = nullptr);

// Slurm's states grouped as `saltus sweep status` counts them: pending, running, completed,
// failed, timed out, cancelled, out of memory, node failure, preempted, or the state itself.
std::string stateGroup(const std::string& state);
bool isActive(const std::string& state);  // pending or running (or about to be)

// ---- the sweep folder ----

// DIR/sweep.json: the spec and the folder as written, and the directory they are relative to.
struct SweepFolder {
  std::string spec, out, working_directory;
  std::string specPath() const;  // the spec, readable from anywhere
};
void writeSweepFolder(const std::string& out, const SweepFolder& folder);
// Throws std::runtime_error naming DIR when DIR/sweep.json is missing or unreadable.
SweepFolder readSweepFolder(const std::string& out);

struct Submission {
  std::string job_id;
  std::string cases_file;  // absolute
  ArrayPlan plan;
  std::string submitted;   // local time, ISO 8601
};
std::vector<Submission> readSubmissions(const std::string& out);  // empty when none
void addSubmission(const std::string& out, const Submission& submission);
// The cases file name for the next submission (DIR/slurm/cases-<k>.txt, k one more than the last).
std::string nextCasesFile(const std::string& out);

// Task `index`'s slice of a cases file: the cases named on its lines, in the file's order.
// Throws std::runtime_error naming the file and line of an id the grid does not have.
std::vector<SweepCase> taskCases(const std::vector<SweepCase>& cases, const std::string& cases_file,
                                 int solves_per_task, int index);

// The ids of the given cases, one per line.
std::string casesFileText(const std::vector<const SweepCase*>& cases);

// The array tasks of this folder's submissions still pending or running; throws SlurmError when
// there are some ("job 12 of this sweep has 3 tasks pending or running: ..."), so that a second
// submission or a local run cannot run the same solves twice. Nothing when squeue cannot answer.
void refuseWhileActive(const std::string& out);

}  // namespace saltus::sweep::slurm
