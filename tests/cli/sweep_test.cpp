// `saltus sweep`, run as a program: a small sweep end to end (records, summary, report, charts),
// a sweep killed mid-run and resumed (finished solves kept, the rest run), and a bad spec refused
// before any solve starts.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "saltus/build_paths.hpp"
#include "tests/support/run_saltus.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;

fs::path sweepDir(const std::string& name) { return saltus::testing::scratchPath("sweep_test", name); }

void writeSpec(const fs::path& path, int seeds) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: {from: 1, count: " << seeds
                      << "}\noptions: {restarts: 0}\n";
}

std::vector<fs::path> records(const fs::path& out) {
  std::vector<fs::path> found;
  if (!fs::exists(out / "runs")) return found;
  for (const auto& d : fs::directory_iterator(out / "runs"))
    if (fs::exists(d.path() / "record.json")) found.push_back(d.path() / "record.json");
  return found;
}

TEST(CliSweep, SmallSweepWritesRecordsSummaryReportAndCharts) {
  const fs::path dir = sweepDir("small");
  writeSpec(dir / "spec.yaml", 2);
  const auto r = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string(), "--jobs", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  ASSERT_EQ(records(dir / "out").size(), 2u);
  const nlohmann::json rec =
      nlohmann::json::parse(readFile(dir / "out/runs/point_mass_drop__impulsive__seed=2/record.json"));
  EXPECT_EQ(rec["seed"], 2);
  EXPECT_TRUE(rec["feasible"].get<bool>());
  EXPECT_TRUE(rec["physical"].get<bool>());  // the replay follows the bounce-free landing
  EXPECT_LT(rec["replay_deviation"].get<double>(), 1e-3);
  EXPECT_LE(rec["largest_product"].get<double>(), 1e-4);
  EXPECT_NE(rec["command"].get<std::string>().find("saltus optimize point_mass_drop --method impulsive --seed 2"),
            std::string::npos);
  // The record's figures are the solve's own.
  const nlohmann::json solve =
      nlohmann::json::parse(readFile(dir / "out/runs/point_mass_drop__impulsive__seed=2/solution/summary.json"));
  EXPECT_EQ(rec["iterations"], solve["iterations"]);
  EXPECT_EQ(rec["objective"], solve["objective"]);
  EXPECT_EQ(rec["status"], solve["status"]);
  EXPECT_EQ(solve["status"], solve["stages"][solve["kept_stage"].get<int>()]["status"]);

  const nlohmann::json summary = nlohmann::json::parse(readFile(dir / "out/summary.json"));
  ASSERT_EQ(summary["cells"].size(), 1u);
  EXPECT_EQ(summary["cells"][0]["solves"], 2);
  EXPECT_EQ(summary["cells"][0]["successes"], 2);
  const std::string report = readFile(dir / "out/report.md");
  EXPECT_NE(report.find("| point_mass_drop | impulsive | – | 2/2 (100 %) |"), std::string::npos) << report;
  for (const char* chart : {"sweep_time.png", "sweep_error.svg", "sweep_cost.png"})
    EXPECT_GT(fs::file_size(dir / "out/charts" / chart), 1000u) << chart;

  // Run again: nothing to do, the same records.
  const auto again = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string()});
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.err.find("2 of 2 solves have a record (0 run now)"), std::string::npos) << again.err;
  fs::remove_all(dir);
}

// The paper's strategy 4 as a sweep: every seed starts from the same earlier solution, perturbed
// by seed_scale with its own random seed (--seed-from in each solve's command and summary).
// Variants compare settings over the same grid: each solve runs with its variant's options (a
// feasibility stage capped at 3 iterations cannot land the drop), and each variant is a cell of
// the summary and the report.
TEST(CliSweep, VariantsAreCellsOfTheirOwnSolvedWithTheirOwnOptions) {
  const fs::path dir = sweepDir("variants");
  fs::create_directories(dir);
  std::ofstream(dir / "spec.yaml") << "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: [1]\n"
                                      "options: {restarts: 0, tighten_within: 0}\n"
                                      "variants: {baseline: {}, capped: {ipopt: {max_iter: 3}}}\n";
  const auto r = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string(), "--jobs", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(records(dir / "out").size(), 2u);
  const nlohmann::json baseline = nlohmann::json::parse(
      readFile(dir / "out/runs/point_mass_drop__impulsive__variant=baseline__seed=1/record.json"));
  const nlohmann::json capped =
      nlohmann::json::parse(readFile(dir / "out/runs/point_mass_drop__impulsive__variant=capped__seed=1/record.json"));
  EXPECT_EQ(baseline["variant"], "baseline");
  EXPECT_TRUE(baseline["feasible"].get<bool>());
  EXPECT_EQ(baseline["command"].get<std::string>().find("max_iter"), std::string::npos);
  EXPECT_FALSE(capped["feasible"].get<bool>());
  EXPECT_LE(capped["iterations"].get<int>(), 3);
  EXPECT_NE(capped["command"].get<std::string>().find("--ipopt max_iter=3"), std::string::npos) << capped["command"];
  const nlohmann::json summary = nlohmann::json::parse(readFile(dir / "out/summary.json"));
  ASSERT_EQ(summary["cells"].size(), 2u);
  EXPECT_EQ(summary["cells"][1]["variant"], "capped");
  const std::string report = readFile(dir / "out/report.md");
  EXPECT_NE(report.find("| point_mass_drop | impulsive [baseline] | – | 1/1 (100 %) |"), std::string::npos) << report;
  EXPECT_NE(report.find("| point_mass_drop | impulsive [capped] | – | 0/1 (0 %) |"), std::string::npos) << report;
  EXPECT_GT(fs::file_size(dir / "out/charts/sweep_time.png"), 1000u);
}

TEST(CliSweep, AnEarlierSolutionSeedsEverySolve) {
  const fs::path dir = sweepDir("seed_from");
  fs::create_directories(dir);
  const fs::path solution = fs::path(SALTUS_SOURCE_DIR) / "tests/data/solutions/point_mass_drop_inelastic";
  std::ofstream(dir / "spec.yaml") << "problems: [point_mass_drop]\nmethods: [impulsive]\nset: {restitution: [0]}\n"
                                      "seeds: [1, 2]\noptions: {restarts: 0, seed_from: "
                                   << solution.string() << ", seed_scale: 0.01}\n";
  const auto r = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (int seed : {1, 2}) {
    const fs::path run = dir / "out/runs" / ("point_mass_drop__impulsive__restitution=0__seed=" + std::to_string(seed));
    const nlohmann::json rec = nlohmann::json::parse(readFile(run / "record.json"));
    EXPECT_NE(rec["command"].get<std::string>().find("--seed-from " + solution.string()), std::string::npos) << rec["command"];
    EXPECT_TRUE(rec["feasible"].get<bool>()) << seed;
    const nlohmann::json solve = nlohmann::json::parse(readFile(run / "solution/summary.json"));
    EXPECT_EQ(solve["seed"], "solution");
    EXPECT_EQ(fs::path(solve["seed_solution"].get<std::string>()), solution);
    EXPECT_EQ(solve["seed_scale"], 0.01);
    EXPECT_EQ(solve["random_seed"], seed);
  }
  fs::remove_all(dir);
}

// A sweep in which nothing succeeds (one Ipopt iteration a stage) still draws its charts, each
// saying "no success", without a legend of nothing (matplotlib's warning on stderr).
TEST(CliSweep, ASweepWithoutASuccessDrawsItsChartsWithoutWarnings) {
  const fs::path dir = sweepDir("no_success");
  fs::create_directories(dir);
  std::ofstream(dir / "spec.yaml") << "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: {from: 1, count: 1}\n"
                                      "options: {restarts: 0, ipopt: {max_iter: 1}}\n";
  const auto r = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(readFile(dir / "out/summary.json"));
  ASSERT_EQ(summary["cells"].size(), 1u);
  EXPECT_EQ(summary["cells"][0]["successes"], 0);
  for (const char* chart : {"sweep_time.png", "sweep_error.svg", "sweep_cost.png"})
    EXPECT_GT(fs::file_size(dir / "out/charts" / chart), 1000u) << chart;
  EXPECT_EQ(r.err.find("No artists"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(CliSweep, KilledSweepResumesWithTheSolvesLeft) {
  const fs::path dir = sweepDir("resume");
  writeSpec(dir / "spec.yaml", 4);
  const std::string spec = (dir / "spec.yaml").string(), out = (dir / "out").string();
  std::vector<std::string> args = {SALTUS_BINARY, "sweep", spec, "--out", out, "--jobs", "1"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, SALTUS_BINARY, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Kill it once the first solve has its record (the second is then running).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (records(out).empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(pid, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 143);  // 128 + SIGTERM
  const std::vector<fs::path> before = records(out);
  ASSERT_GE(before.size(), 1u);
  ASSERT_LT(before.size(), 4u);
  std::map<fs::path, std::string> kept;
  for (const fs::path& p : before) kept[p] = readFile(p);

  const auto r = runSaltus({"sweep", spec, "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(records(out).size(), 4u);
  for (const auto& [path, text] : kept) EXPECT_EQ(readFile(path), text) << path << " was redone";
  EXPECT_NE(r.err.find("4 of 4 solves have a record (" + std::to_string(4 - before.size()) + " run now)"),
            std::string::npos)
      << r.err;
  const nlohmann::json summary = nlohmann::json::parse(readFile(dir / "out/summary.json"));
  EXPECT_EQ(summary["cells"][0]["solves"], 4);
  fs::remove_all(dir);
}

TEST(CliSweep, BadSpecIsRefusedBeforeAnySolve) {
  const fs::path dir = sweepDir("bad");
  fs::create_directories(dir);
  std::ofstream(dir / "spec.yaml") << "problems: [point_mass_drop]\nmethods: [impulsive]\nset: {heigth: [0.1]}\nseeds: [1]\n";
  const auto r = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("problems[0] (point_mass_drop) with heigth=0.1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("height"), std::string::npos) << r.err;  // the parameters the problem has
  EXPECT_FALSE(fs::exists(dir / "out"));

  const auto list = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", (dir / "out").string(), "--list"});
  EXPECT_EQ(list.status, 1);
  std::ofstream(dir / "spec.yaml") << "problems: [point_mass_drop]\nmethods: [impulsive, first-order]\nseeds: [1, 5]\n";
  const auto listed = runSaltus({"sweep", (dir / "spec.yaml").string(), "--out", "OUT", "--list"});
  ASSERT_EQ(listed.status, 0) << listed.err;
  EXPECT_EQ(std::count(listed.out.begin(), listed.out.end(), '\n'), 4);
  EXPECT_NE(listed.out.find("saltus optimize point_mass_drop --method first-order --seed 5 --out "
                            "OUT/runs/point_mass_drop__first-order__seed=5/solution\n"),
            std::string::npos)
      << listed.out;
  // In the order a run starts them: seed 1 of both methods before seed 5 of either.
  const std::size_t first_order_1 = listed.out.find("--method first-order --seed 1 ");
  const std::size_t impulsive_5 = listed.out.find("--method impulsive --seed 5 ");
  ASSERT_NE(first_order_1, std::string::npos) << listed.out;
  ASSERT_NE(impulsive_5, std::string::npos) << listed.out;
  EXPECT_LT(first_order_1, impulsive_5) << listed.out;
  EXPECT_LT(listed.out.find("--method impulsive --seed 1 "), listed.out.find('\n')) << listed.out;  // the grid's first
  fs::remove_all(dir);
}

TEST(CliSweep, SlurmScriptOnlyWritesTheBatchScriptWithoutACluster) {
  const fs::path dir = sweepDir("script_only");
  writeSpec(dir / "spec.yaml", 3);
  const std::string spec = (dir / "spec.yaml").string(), out = (dir / "out").string();
  // Slurm is not asked: this works on a machine without it (PATH without sbatch).
  const auto r = runSaltus({"sweep", spec, "--out", out, "--slurm-script-only", "--time", "00:10:00", "--mem", "1G",
                            "--max-parallel", "2", "--sbatch-arg=--qos=short"},
                           "PATH=/nonexistent");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, (fs::path(out) / "slurm/sweep.sbatch").string() + "\n");
  const std::string script = readFile(dir / "out/slurm/sweep.sbatch");
  for (const char* line : {"#SBATCH --array=0-2%2\n", "#SBATCH --time=00:10:00\n", "#SBATCH --mem=1G\n",
                           "#SBATCH --qos=short\n", " sweep task "})
    EXPECT_NE(script.find(line), std::string::npos) << line << "\n" << script;
  const std::string cases = readFile(dir / "out/slurm/cases-1.txt");
  EXPECT_EQ(std::count(cases.begin(), cases.end(), '\n'), 3);
  EXPECT_FALSE(fs::exists(dir / "out/slurm/jobs.json"));  // nothing was submitted

  // Task 1 of the script, run by hand as Slurm would: the second solve of the list, and its record.
  const std::string second = cases.substr(cases.find('\n') + 1, cases.find('\n', cases.find('\n') + 1) - cases.find('\n') - 1);
  const auto task = runSaltus({"sweep", "task", spec, "--out", out, "--cases", (dir / "out/slurm/cases-1.txt").string(),
                               "--solves-per-task", "1", "--index", "1"});
  ASSERT_EQ(task.status, 0) << task.err;
  EXPECT_EQ(records(dir / "out").size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "out/runs" / second / "record.json")) << second;

  // status and collect read the folder; collect says what is missing.
  const auto status = runSaltus({"sweep", "status", out, "--json"}, "PATH=/nonexistent");
  ASSERT_EQ(status.status, 0) << status.err;
  const nlohmann::json s = nlohmann::json::parse(status.out);
  EXPECT_EQ(s["solves"], 3);
  EXPECT_EQ(s["records"], 1);
  EXPECT_EQ(s["without_record"], 2);
  const auto collect = runSaltus({"sweep", "collect", out});
  EXPECT_EQ(collect.status, 1);
  EXPECT_NE(collect.err.find("2 solve(s) have no record yet"), std::string::npos) << collect.err;
  EXPECT_TRUE(fs::exists(dir / "out/report.md"));
  fs::remove_all(dir);
}

TEST(CliSweep, SlurmOptionsAndSubcommandsRefuseWhatTheyCannotDo) {
  const fs::path dir = sweepDir("slurm_usage");
  writeSpec(dir / "spec.yaml", 1);
  const std::string spec = (dir / "spec.yaml").string(), out = (dir / "out").string();
  const auto jobs = runSaltus({"sweep", spec, "--out", out, "--slurm", "--jobs", "4"});
  EXPECT_EQ(jobs.status, 2);
  EXPECT_NE(jobs.err.find("--jobs: not with --slurm"), std::string::npos) << jobs.err;
  const auto partition = runSaltus({"sweep", spec, "--out", out, "--partition", "short"});
  EXPECT_EQ(partition.status, 2);
  EXPECT_NE(partition.err.find("go with --slurm"), std::string::npos) << partition.err;
  const auto no_out = runSaltus({"sweep", spec});
  EXPECT_EQ(no_out.status, 2);
  EXPECT_NE(no_out.err.find("--out is required"), std::string::npos) << no_out.err;
  const auto not_sweep = runSaltus({"sweep", "status", (dir / "nowhere").string()});
  EXPECT_EQ(not_sweep.status, 1);
  EXPECT_NE(not_sweep.err.find("not a sweep folder (no sweep.json"), std::string::npos) << not_sweep.err;
  const auto blank = runSaltus({"sweep", spec, "--out", (dir / "with space").string(), "--slurm-script-only"});
  EXPECT_EQ(blank.status, 2);
  EXPECT_NE(blank.err.find("an #SBATCH line cannot carry"), std::string::npos) << blank.err;
  EXPECT_FALSE(fs::exists(dir / "with space"));
  // Without Slurm installed, a submission says so.
  const auto none = runSaltus({"sweep", spec, "--out", out, "--slurm"}, "PATH=/nonexistent");
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find("is Slurm installed (sbatch in PATH)?"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(dir / "out/slurm/sweep.sbatch"));
  EXPECT_FALSE(fs::exists(dir / "out/slurm/cases-1.txt"));
  fs::remove_all(dir);
}

}  // namespace
