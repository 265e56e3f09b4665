// The local runner with a stand-in for `saltus optimize` (a shell script): a solve killed from
// outside gets an error record in a local sweep, but none in a Slurm task (whose scheduler killed
// it: the solve runs again on resume); solves start seed by seed and a resume runs only the cases
// without a record; a second runner in a locked folder is refused.
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

// A stand-in "saltus": a shell script of `body` in `dir`, executable; returns its path.
std::string fakeSaltus(const fs::path& dir, const std::string& body) {
  const fs::path p = dir / "fake_saltus";
  std::ofstream(p) << "#!/bin/sh\n" << body;
  fs::permissions(p, fs::perms::owner_all);
  return p.string();
}

// A "saltus" that says something on standard error and then dies by SIGKILL (as the kernel's
// out-of-memory killer, or Slurm after its grace time, would end a solve).
std::string killedProgram(const fs::path& dir) { return fakeSaltus(dir, "echo 'solving...' >&2\nkill -KILL $$\n"); }

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

// A "saltus" that appends its arguments to a file and ends without a solution (an error record).
std::string loggingProgram(const fs::path& dir) {
  return fakeSaltus(dir, "echo \"$*\" >> '" + (dir / "calls.txt").string() + "'\nexit 1\n");
}

TEST(Runner, SolvesStartSeedBySeedAndAResumeRunsOnlyTheCasesWithoutARecord) {
  const fs::path dir = runnerScratch("order");
  std::vector<SweepCase> cases;
  for (const std::string method : {"first-order", "impulsive"})
    for (unsigned seed : {1u, 2u, 3u}) {
      SweepCase c;
      c.problem = c.problem_name = "point_mass_drop";
      c.method = method;
      c.seed = seed;
      c.id = "point_mass_drop__" + method + "__seed=" + std::to_string(seed);
      cases.push_back(c);
    }
  RunnerOptions o;
  o.saltus = loggingProgram(dir);
  // One case already has its record: a resume leaves it alone.
  fs::create_directories(caseDirectory((dir / "out").string(), cases[1]));
  SweepRecord done;
  done.id = cases[1].id;
  done.problem = done.problem_name = "point_mass_drop";
  done.method = "first-order";
  done.seed = 2;
  done.status = "error";
  std::ofstream(fs::path(caseDirectory((dir / "out").string(), cases[1])) / "record.json") << toJson(done).dump(2);

  const RunResult r = runSweep(oneSolveSpec(), cases, (dir / "out").string(), o, nullptr);
  EXPECT_EQ(r.ran, 5);
  ASSERT_EQ(r.records.size(), 6u);  // the grid's order, whatever the order they ran in
  for (std::size_t i = 0; i < cases.size(); ++i) EXPECT_EQ(r.records[i].id, cases[i].id);
  std::ifstream calls(dir / "calls.txt");
  std::vector<std::string> started;
  for (std::string line; std::getline(calls, line);) {
    const auto method = line.find("--method ") + 9, seed = line.find("--seed ") + 7;
    started.push_back(line.substr(method, line.find(' ', method) - method) + " " +
                      line.substr(seed, line.find(' ', seed) - seed));
  }
  const std::vector<std::string> expected = {"first-order 1", "impulsive 1", "impulsive 2", "first-order 3",
                                             "impulsive 3"};
  EXPECT_EQ(started, expected);
  fs::remove_all(dir);
}

// A record made by another command than its case runs now (the spec changed since) is named; one
// whose folder has moved (another --out) is not.
TEST(Runner, RecordsOfAnotherCommandThanTheSpecGivesAreNamed) {
  const fs::path dir = runnerScratch("another");
  std::vector<SweepCase> cases = oneCase();
  SweepCase second = cases[0];
  second.seed = 2;
  second.id = "point_mass_drop__impulsive__seed=2";
  cases.push_back(second);
  const std::string out = (dir / "out").string();
  EXPECT_TRUE(recordsOfAnotherCommand(out, cases).empty());  // no records yet
  const auto write = [&](const SweepCase& c, const std::string& command) {
    fs::create_directories(caseDirectory(out, c));
    SweepRecord r;
    r.id = c.id;
    r.problem = r.problem_name = c.problem;
    r.method = c.method;
    r.seed = c.seed;
    r.status = "error";
    r.command = command;
    std::ofstream(fs::path(caseDirectory(out, c)) / "record.json") << toJson(r).dump(2);
  };
  const std::string moved = optimizeCommand(cases[0], (dir / "elsewhere/runs" / cases[0].id).string());
  ASSERT_NE(moved, optimizeCommand(cases[0], caseDirectory(out, cases[0])));
  write(cases[0], moved);
  EXPECT_TRUE(recordsOfAnotherCommand(out, cases).empty());

  SweepCase changed = cases[1];
  changed.options.restarts = 3;
  write(cases[1], optimizeCommand(changed, caseDirectory(out, cases[1])));
  const std::vector<std::string> other = recordsOfAnotherCommand(out, cases);
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0].rfind(cases[1].id + ": made by `saltus optimize point_mass_drop", 0), 0u) << other[0];
  EXPECT_NE(other[0].find("--restarts 3"), std::string::npos) << other[0];
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
