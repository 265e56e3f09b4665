// The Slurm side of a sweep without a cluster: how the array is sized, the batch script, each
// task's slice of the solves, the submissions kept in the folder, and Slurm's states as status
// counts them. (tests/slurm/ runs the same against a real cluster.)
#include "sweep/slurm.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/files.hpp"

namespace {

namespace fs = std::filesystem;
using namespace saltus::sweep;

fs::path slurmScratch(const std::string& name) {
  const fs::path d = saltus::testing::scratchPath("slurm_unit", name);
  fs::create_directories(d);
  return d;
}

TEST(SlurmArrayPlan, OneTaskPerSolveWhileTheyFitThenTheSmallestBatchThatFits) {
  const slurm::ArrayPlan small = slurm::planArray(24, 1001);
  EXPECT_EQ(small.tasks, 24);
  EXPECT_EQ(small.solves_per_task, 1);
  const slurm::ArrayPlan exact = slurm::planArray(1001, 1001);
  EXPECT_EQ(exact.tasks, 1001);
  EXPECT_EQ(exact.solves_per_task, 1);
  // The paper's 1,200 solves on Slurm's default MaxArraySize: two per task, 600 tasks.
  const slurm::ArrayPlan paper = slurm::planArray(1200, 1001);
  EXPECT_EQ(paper.solves_per_task, 2);
  EXPECT_EQ(paper.tasks, 600);
  const slurm::ArrayPlan big = slurm::planArray(10007, 1001);
  EXPECT_EQ(big.solves_per_task, 10);
  EXPECT_EQ(big.tasks, 1001);
  EXPECT_LE(big.tasks * big.solves_per_task - big.solves, big.solves_per_task - 1);  // every solve, once
  // A fixed batch.
  const slurm::ArrayPlan fixed = slurm::planArray(10, 1001, 4);
  EXPECT_EQ(fixed.tasks, 3);
  EXPECT_EQ(fixed.solves_per_task, 4);
  try {
    slurm::planArray(5000, 1001, 2);
    FAIL() << "2 per task cannot fit 5000 solves in 1001 tasks";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--solves-per-task 2: 5000 solves would need 2500 array tasks"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("expected at least 5"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurm::planArray(0, 1001).tasks, 0);
}

slurm::ScriptInputs scriptInputs() {
  slurm::ScriptInputs in;
  in.saltus = "/opt/saltus/bin/saltus";
  in.spec = "specs/paper.yaml";
  in.out = "results/paper";
  in.working_directory = "/home/ana/project";
  in.out_absolute = "/home/ana/project/results/paper";
  in.cases_file = "/home/ana/project/results/paper/slurm/cases-1.txt";
  in.job_name = "saltus-sweep-paper";
  in.submitted_by = "saltus sweep specs/paper.yaml --out results/paper --slurm";
  in.plan = slurm::planArray(1200, 1001);
  in.options.partition = "short";
  in.options.time = "00:30:00";
  in.options.mem = "2G";
  in.options.max_parallel = 100;
  in.options.sbatch_args = {"--qos=normal", "--account=robotics"};
  return in;
}

TEST(SlurmScript, NamesTheArrayItsLimitsAndTheTaskCommand) {
  const std::string s = slurm::sbatchScript(scriptInputs());
  EXPECT_EQ(s.rfind("#!/bin/bash\n", 0), 0u);
  for (const char* line : {"#SBATCH --job-name=saltus-sweep-paper\n", "#SBATCH --array=0-599%100\n",
                           "#SBATCH --chdir=/home/ana/project\n",
                           "#SBATCH --output=/home/ana/project/results/paper/slurm/logs/%A_%a.log\n",
                           "#SBATCH --cpus-per-task=1\n", "#SBATCH --partition=short\n", "#SBATCH --time=00:30:00\n",
                           "#SBATCH --mem=2G\n", "#SBATCH --qos=normal\n", "#SBATCH --account=robotics\n",
                           "export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1\n",
                           "exec /opt/saltus/bin/saltus sweep task specs/paper.yaml --out results/paper --cases "
                           "/home/ana/project/results/paper/slurm/cases-1.txt --solves-per-task 2 --index "
                           "\"$SLURM_ARRAY_TASK_ID\"\n"})
    EXPECT_NE(s.find(line), std::string::npos) << line << "\n" << s;
  // Every #SBATCH line comes before the first command (sbatch stops reading them there).
  EXPECT_LT(s.rfind("#SBATCH"), s.find("export "));
  // Without options: no partition, time or memory lines, no %K.
  slurm::ScriptInputs plain = scriptInputs();
  plain.options = {};
  const std::string p = slurm::sbatchScript(plain);
  EXPECT_NE(p.find("#SBATCH --array=0-599\n"), std::string::npos);
  EXPECT_EQ(p.find("--partition"), std::string::npos);
  EXPECT_EQ(p.find("--time"), std::string::npos);
  EXPECT_EQ(p.find("--mem"), std::string::npos);
}

TEST(SlurmScript, RefusesAFolderAnSbatchLineCannotCarry) {
  slurm::ScriptInputs in = scriptInputs();
  in.out_absolute = "/home/ana/my results";
  EXPECT_THROW(slurm::sbatchScript(in), std::invalid_argument);
  in = scriptInputs();
  in.out_absolute = "/home/ana/100%";
  EXPECT_THROW(slurm::sbatchScript(in), std::invalid_argument);
  in = scriptInputs();
  in.options.sbatch_args = {"--qos=a\n#SBATCH --x"};
  EXPECT_THROW(slurm::sbatchScript(in), std::invalid_argument);
}

std::vector<SweepCase> fiveCases() {
  std::vector<SweepCase> cases;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    SweepCase c;
    c.problem = c.problem_name = "point_mass_drop";
    c.method = "impulsive";
    c.seed = seed;
    c.id = "point_mass_drop__impulsive__seed=" + std::to_string(seed);
    cases.push_back(c);
  }
  return cases;
}

TEST(SlurmTaskCases, EachTaskRunsItsOwnSliceAndTogetherTheyRunEverySolveOnce) {
  const fs::path dir = slurmScratch("slices");
  const std::vector<SweepCase> cases = fiveCases();
  // The cases file lists the solves without a record, in any order.
  const std::vector<const SweepCase*> pending = {&cases[4], &cases[0], &cases[2], &cases[3]};
  const fs::path file = dir / "cases-1.txt";
  std::ofstream(file) << slurm::casesFileText(pending);
  std::vector<std::string> seen;
  for (int index = 0; index < 2; ++index)
    for (const SweepCase& c : slurm::taskCases(cases, file.string(), 3, index)) seen.push_back(c.id);
  EXPECT_EQ(seen, (std::vector<std::string>{cases[4].id, cases[0].id, cases[2].id, cases[3].id}));
  EXPECT_EQ(slurm::taskCases(cases, file.string(), 3, 0).size(), 3u);
  EXPECT_EQ(slurm::taskCases(cases, file.string(), 3, 1).size(), 1u);
  EXPECT_TRUE(slurm::taskCases(cases, file.string(), 3, 2).empty());  // past the end: nothing to do

  // A spec changed after submitting: the unknown id is named with its line.
  std::ofstream(file, std::ios::app) << "point_mass_drop__impulsive__seed=9\n";
  try {
    slurm::taskCases(cases, file.string(), 1, 4);
    FAIL() << "an id the grid does not have";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cases-1.txt:5: solve 'point_mass_drop__impulsive__seed=9' is not in the sweep's grid"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(slurm::taskCases(cases, (dir / "missing.txt").string(), 1, 0), std::runtime_error);
  fs::remove_all(dir);
}

TEST(SlurmFolder, SubmissionsAccumulateAndCasesFilesAreNumbered) {
  const fs::path dir = slurmScratch("folder");
  fs::create_directories(dir / "slurm");
  EXPECT_TRUE(slurm::readSubmissions(dir.string()).empty());
  const std::string first = slurm::nextCasesFile(dir.string());
  EXPECT_EQ(fs::path(first).filename(), "cases-1.txt");
  EXPECT_TRUE(fs::path(first).is_absolute());
  std::ofstream(first) << "a\n";
  slurm::addSubmission(dir.string(), {"101", first, slurm::planArray(1, 1001), ""});
  const std::string second = slurm::nextCasesFile(dir.string());
  EXPECT_EQ(fs::path(second).filename(), "cases-2.txt");
  slurm::addSubmission(dir.string(), {"102", second, slurm::planArray(7, 3), "2026-01-01T00:00:00"});
  const std::vector<slurm::Submission> subs = slurm::readSubmissions(dir.string());
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[0].job_id, "101");
  EXPECT_FALSE(subs[0].submitted.empty());
  EXPECT_EQ(subs[1].job_id, "102");
  EXPECT_EQ(subs[1].plan.tasks, 3);
  EXPECT_EQ(subs[1].plan.solves_per_task, 3);
  EXPECT_EQ(subs[1].submitted, "2026-01-01T00:00:00");

  slurm::writeSweepFolder(dir.string(), {"spec.yaml", "out", "/home/ana"});
  const slurm::SweepFolder f = slurm::readSweepFolder(dir.string());
  EXPECT_EQ(f.spec, "spec.yaml");
  EXPECT_EQ(f.specPath(), "/home/ana/spec.yaml");
  slurm::writeSweepFolder(dir.string(), {"/data/spec.yaml", "out", "/home/ana"});
  EXPECT_EQ(slurm::readSweepFolder(dir.string()).specPath(), "/data/spec.yaml");
  EXPECT_THROW(slurm::readSweepFolder((dir / "nowhere").string()), std::runtime_error);
  std::ofstream(dir / "slurm/jobs.json") << "{\"submissions\": [{\"job_id\": 3}]}";
  EXPECT_THROW(slurm::readSubmissions(dir.string()), std::runtime_error);
  fs::remove_all(dir);
}

TEST(SlurmStates, GroupedAsStatusCountsThem) {
  EXPECT_EQ(slurm::stateGroup("PENDING"), "pending");
  EXPECT_EQ(slurm::stateGroup("RUNNING"), "running");
  EXPECT_EQ(slurm::stateGroup("COMPLETED"), "completed");
  EXPECT_EQ(slurm::stateGroup("TIMEOUT"), "timed out");
  EXPECT_EQ(slurm::stateGroup("OUT_OF_MEMORY"), "out of memory");
  EXPECT_EQ(slurm::stateGroup("NODE_FAIL"), "node failure");
  EXPECT_EQ(slurm::stateGroup("PREEMPTED"), "preempted");
  EXPECT_EQ(slurm::stateGroup("CANCELLED"), "cancelled");
  EXPECT_EQ(slurm::stateGroup("SOMETHING_NEW"), "SOMETHING_NEW");
  EXPECT_TRUE(slurm::isActive("PENDING"));
  EXPECT_TRUE(slurm::isActive("COMPLETING"));
  EXPECT_FALSE(slurm::isActive("TIMEOUT"));
}

TEST(SlurmPrograms, OutputAndStatusOfAProgramAndOneThatIsNotThere) {
  const slurm::ProgramResult ok = slurm::runProgram({"sh", "-c", "echo out; echo err >&2; exit 3"});
  EXPECT_EQ(ok.status, 3);
  EXPECT_EQ(ok.out, "out\n");
  EXPECT_EQ(ok.err, "err\n");
  const slurm::ProgramResult missing = slurm::runProgram({"saltus-no-such-program"});
  EXPECT_EQ(missing.status, -1);
  EXPECT_NE(missing.err.find("saltus-no-such-program: cannot start"), std::string::npos);
}

}  // namespace
