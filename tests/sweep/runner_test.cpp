// The local runner with a stand-in for `saltus optimize` (a shell script): a solve killed from
// outside gets an error record in a local sweep, but none in a Slurm task (whose scheduler killed
// it: the solve runs again on resume); a second runner in a locked folder is refused.
#include "sweep/runner.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/files.hpp"

namespace {

namespace fs = std::filesystem;
using namespace saltus::sweep;

fs::path runnerScratch(const std::string& name) {
  const fs::path d = saltus::testing::scratchPath("runner", name);
  fs::create_directories(d);
  return d;
}

// A "saltus" that says something on standard error and then dies by SIGKILL (as the kernel's
// out-of-memory killer, or Slurm after its grace time, would end a solve).
std::string killedProgram(const fs::path& dir) {
  const fs::path p = dir / "fake_saltus";
  std::ofstream(p) << "#!/bin/sh\necho 'solving...' >&2\nkill -KILL $$\n";
  fs::permissions(p, fs::perms::owner_all);
  return p.string();
}

SweepSpec oneSolveSpec() {
  SweepSpec spec;
  spec.methods = {"impulsive"};
  spec.seeds = {1};
  spec.replay.enabled = false;
  return spec;
}

std::vector<SweepCase> oneCase() {
  SweepCase c;
  c.id = "point_mass_drop__impulsive__seed=1";
  c.problem = c.problem_name = "point_mass_drop";
  c.method = "impulsive";
  return {c};
}

TEST(Runner, ASolveKilledFromOutsideHasAnErrorRecordLocallyAndNoneInASlurmTask) {
  const fs::path dir = runnerScratch("killed");
  RunnerOptions local;
  local.saltus = killedProgram(dir);
  const RunResult l = runSweep(oneSolveSpec(), oneCase(), (dir / "local").string(), local, nullptr);
  ASSERT_EQ(l.records.size(), 1u);
  EXPECT_EQ(l.records[0].status, "error");
  EXPECT_EQ(l.records[0].error, "saltus optimize was killed by signal 9");
  EXPECT_TRUE(l.stopped.empty());

  RunnerOptions task = local;
  task.lock = false;
  task.stopped_solve_leaves_no_record = true;
  const RunResult t = runSweep(oneSolveSpec(), oneCase(), (dir / "task").string(), task, nullptr);
  EXPECT_TRUE(t.records.empty());
  EXPECT_EQ(t.stopped, "point_mass_drop__impulsive__seed=1");
  EXPECT_EQ(t.ran, 0);
  EXPECT_FALSE(fs::exists(dir / "task/runs/point_mass_drop__impulsive__seed=1/record.json"));
  EXPECT_FALSE(fs::exists(dir / "task/.lock"));  // tasks share the folder without its lock
  fs::remove_all(dir);
}

TEST(Runner, ASecondSweepInALockedFolderIsRefused) {
  const fs::path dir = runnerScratch("locked");
  DirectoryLock held(dir.string());
  RunnerOptions o;
  o.saltus = killedProgram(dir);
  try {
    runSweep(oneSolveSpec(), oneCase(), dir.string(), o, nullptr);
    FAIL() << "the folder is locked";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another saltus sweep is running in this folder"), std::string::npos) << e.what();
  }
  o.lock = false;  // a Slurm task does not take the lock
  EXPECT_NO_THROW(runSweep(oneSolveSpec(), oneCase(), dir.string(), o, nullptr));
  fs::remove_all(dir);
}

}  // namespace

TEST(Runner, TheSpecInForceDecidesWhatSucceededNotTheRecordsFile) {
  const fs::path dir = runnerScratch("rule");
  std::vector<SweepCase> cases = oneCase();
  SweepRecord r;
  r.id = cases[0].id;
  r.problem = r.problem_name = "point_mass_drop";
  r.method = "impulsive";
  r.status = "Solve_Succeeded";
  r.feasible = r.converged = true;
  r.physical = false;  // written under the physical rule: failed
  fs::create_directories(caseDirectory(dir.string(), cases[0]));
  std::ofstream(fs::path(caseDirectory(dir.string(), cases[0])) / "record.json") << toJson(r).dump(2);
  EXPECT_FALSE(readRecords(dir.string(), cases).at(0).success());
  cases[0].physical_required = false;  // the spec now says success: feasible
  const SweepRecord now = readRecords(dir.string(), cases).at(0);
  EXPECT_TRUE(now.success());
  EXPECT_EQ(now.physical, std::optional<bool>(false));
  fs::remove_all(dir);
}
