// `saltus sweep --slurm` against a real Slurm: a one-node cluster of Debian's slurmctld, slurmd and
// munged, started for each test program in a temporary folder (scripts/slurm/local_cluster.sh)
// and stopped at its end. A sweep started locally and finished on the cluster gives the local
// sweep's records and summary (timings apart); a task cancelled mid-solve leaves no record and is
// redone on resume, counted once; a bad partition is reported with Slurm's own message. Where
// Slurm cannot start (not root), every test is skipped with the reason, which ctest lists.
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "saltus/build_paths.hpp"
#include "tests/support/run_saltus.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;
using saltus::testing::shellQuote;

class SlurmSweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    cluster_ = saltus::testing::scratchPath("slurm", "cluster");
    const std::string script = std::string(SALTUS_SOURCE_DIR) + "/scripts/slurm/local_cluster.sh";
    const fs::path log = cluster_.string() + ".log";
    const int status =
        std::system(("bash " + shellQuote(script) + " start " + shellQuote(cluster_.string()) + " 2 >" +
                     shellQuote(log.string()) + " 2>&1")
                        .c_str());
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    why_not_ = code == 0 ? "" : "the local Slurm cluster did not start (status " + std::to_string(code) + "): " + readFile(log);
    skip_ = code == 2;  // cannot run here at all (not root, Slurm not installed)
    fs::remove(log);
    if (code == 0) ::setenv("SLURM_CONF", (cluster_ / "slurm.conf").c_str(), 1);
  }
  static void TearDownTestSuite() {
    const std::string script = std::string(SALTUS_SOURCE_DIR) + "/scripts/slurm/local_cluster.sh";
    std::system(("bash " + shellQuote(script) + " stop " + shellQuote(cluster_.string()) + " >/dev/null 2>&1").c_str());
    ::unsetenv("SLURM_CONF");
    fs::remove_all(cluster_);
  }
  void SetUp() override {
    if (skip_) GTEST_SKIP() << "Slurm cannot run here: " << why_not_;
    ASSERT_TRUE(why_not_.empty()) << why_not_;
  }

  static fs::path cluster_;
  static std::string why_not_;
  static bool skip_;
};
fs::path SlurmSweep::cluster_;
std::string SlurmSweep::why_not_;
bool SlurmSweep::skip_ = false;

void writeSlurmSpec(const fs::path& path, int seeds, const std::string& options = "{restarts: 0}") {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << "problems: [point_mass_drop]\nmethods: [impulsive]\nseeds: {from: 1, count: " << seeds
                      << "}\noptions: " << options << "\n";
}

nlohmann::json sweepStatus(const fs::path& out) {
  const auto r = runSaltus({"sweep", "status", out.string(), "--json"});
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

// Waits until no task of the sweep is pending or running; returns the last status.
nlohmann::json waitForTasks(const fs::path& out, int seconds = 600) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  nlohmann::json s;
  do {
    s = sweepStatus(out);
    if (!s["tasks"].contains("pending") && !s["tasks"].contains("running")) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  } while (std::chrono::steady_clock::now() < deadline);
  ADD_FAILURE() << "the sweep's tasks did not end within " << seconds << " s: " << s.dump();
  return s;
}

// A record without what depends on when and where it ran: its timings and the folder in its command.
nlohmann::json withoutTimings(nlohmann::json record, const std::string& out) {
  record.erase("wall_seconds");
  record.erase("evaluation_seconds");
  std::string command = record["command"];
  command.replace(command.find(out), out.size(), "OUT");
  record["command"] = command;
  return record;
}

// summary.json without its timing statistics.
nlohmann::json summaryWithoutTimings(const fs::path& out) {
  nlohmann::json s = nlohmann::json::parse(readFile(out / "summary.json"));
  s.erase("records");
  for (nlohmann::json& cell : s["cells"]) {
    cell.erase("wall_seconds");
    cell.erase("wall_all");
  }
  return s;
}

std::string reportWithoutWallTimes(const fs::path& out) {
  std::istringstream in(readFile(out / "report.md"));
  std::string line, kept;
  auto split = [](const std::string& l) {
    std::vector<std::string> cells;
    std::stringstream row(l);
    for (std::string c; std::getline(row, c, '|');) cells.push_back(c);
    return cells;
  };
  std::size_t wall = 0;  // the wall-time column, found in the table's header
  while (std::getline(in, line)) {
    if (line.rfind("| problem |", 0) == 0) {
      const std::vector<std::string> header = split(line);
      wall = std::find(header.begin(), header.end(), " wall s ") - header.begin();
      EXPECT_LT(wall, header.size()) << "no wall-time column in " << line;
    }
    if (line.rfind("| point_mass_drop", 0) == 0 && wall > 0) {  // a cell's row: the wall-time column goes
      std::vector<std::string> cells = split(line);
      if (wall < cells.size()) cells.erase(cells.begin() + static_cast<long>(wall));
      line.clear();
      for (const std::string& c : cells) line += c + "|";
    }
    kept += line + "\n";
  }
  return kept;
}

std::set<std::string> recordIds(const fs::path& out) {
  std::set<std::string> ids;
  if (fs::exists(out / "runs"))
    for (const auto& d : fs::directory_iterator(out / "runs"))
      if (fs::exists(d.path() / "record.json")) ids.insert(d.path().filename().string());
  return ids;
}

TEST_F(SlurmSweep, StartedLocallyFinishedOnTheClusterEqualsALocalSweep) {
  const fs::path dir = saltus::testing::scratchPath("slurm", "equal");
  const fs::path spec = dir / "spec.yaml", out = dir / "out", local = dir / "local";
  // Two seeds on this machine, then the spec grows to four and the cluster runs the other two.
  writeSlurmSpec(spec, 2);
  ASSERT_EQ(runSaltus({"sweep", spec.string(), "--out", out.string(), "--jobs", "2"}).status, 0);
  std::map<std::string, std::string> local_records;
  for (const std::string& id : recordIds(out)) local_records[id] = readFile(out / "runs" / id / "record.json");
  ASSERT_EQ(local_records.size(), 2u);

  writeSlurmSpec(spec, 4);
  const auto submitted = runSaltus({"sweep", spec.string(), "--out", out.string(), "--slurm"});
  ASSERT_EQ(submitted.status, 0) << submitted.err;
  const std::string job = submitted.out.substr(0, submitted.out.find('\n'));
  EXPECT_FALSE(job.empty());
  EXPECT_EQ(job.find_first_not_of("0123456789"), std::string::npos) << submitted.out;  // just the job id
  EXPECT_NE(submitted.err.find("2 solves in 2 array tasks (1 per task)"), std::string::npos) << submitted.err;
  const std::string script = readFile(out / "slurm/sweep.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=0-1\n"), std::string::npos) << script;

  const nlohmann::json status = waitForTasks(out);
  EXPECT_EQ(status["records"], 4) << status.dump();
  EXPECT_EQ(status["tasks"]["completed"], 2) << status.dump();
  EXPECT_EQ(status["jobs"], nlohmann::json::array({job}));
  for (const auto& [id, text] : local_records) EXPECT_EQ(readFile(out / "runs" / id / "record.json"), text) << id << " was redone";
  EXPECT_TRUE(fs::exists(out / "slurm/logs" / (job + "_1.log")));

  const auto collected = runSaltus({"sweep", "collect", out.string()});
  ASSERT_EQ(collected.status, 0) << collected.err;
  EXPECT_NE(collected.err.find("4 of 4 solves have a record, 4 succeeded"), std::string::npos) << collected.err;

  // The same grid run locally from scratch: the same records apart from timings, the same summary.
  ASSERT_EQ(runSaltus({"sweep", spec.string(), "--out", local.string(), "--jobs", "2"}).status, 0);
  ASSERT_EQ(recordIds(local), recordIds(out));
  for (const std::string& id : recordIds(out))
    EXPECT_EQ(withoutTimings(nlohmann::json::parse(readFile(out / "runs" / id / "record.json")), out.string()),
              withoutTimings(nlohmann::json::parse(readFile(local / "runs" / id / "record.json")), local.string()))
        << id;
  EXPECT_EQ(summaryWithoutTimings(out), summaryWithoutTimings(local));
  EXPECT_EQ(reportWithoutWallTimes(out), reportWithoutWallTimes(local));

  // Everything has a record: submitting again submits nothing and rebuilds the summary.
  const auto again = runSaltus({"sweep", spec.string(), "--out", out.string(), "--slurm"});
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_TRUE(again.out.empty()) << again.out;
  EXPECT_NE(again.err.find("nothing to submit"), std::string::npos) << again.err;
  fs::remove_all(dir);
}

TEST_F(SlurmSweep, CancelledTaskLeavesNoRecordAndIsRedoneOnResume) {
  const fs::path dir = saltus::testing::scratchPath("slurm", "cancel");
  const fs::path spec = dir / "spec.yaml", out = dir / "out";
  // Solves of a few seconds each (N = 120), one task at a time.
  writeSlurmSpec(spec, 2, "{N: 120, restarts: 0}");
  const auto submitted =
      runSaltus({"sweep", spec.string(), "--out", out.string(), "--slurm", "--max-parallel", "1"});
  ASSERT_EQ(submitted.status, 0) << submitted.err;
  const std::string job = submitted.out.substr(0, submitted.out.find('\n'));
  EXPECT_NE(readFile(out / "slurm/sweep.sbatch").find("#SBATCH --array=0-1%1\n"), std::string::npos);

  // While the array runs, neither a second submission nor a local sweep may run the same solves.
  const auto second = runSaltus({"sweep", spec.string(), "--out", out.string(), "--slurm"});
  EXPECT_EQ(second.status, 1);
  EXPECT_NE(second.err.find("still has Slurm tasks pending or running: job " + job), std::string::npos) << second.err;
  const auto local = runSaltus({"sweep", spec.string(), "--out", out.string()});
  EXPECT_EQ(local.status, 1);
  EXPECT_NE(local.err.find("still has Slurm tasks pending or running"), std::string::npos) << local.err;

  // Cancel task 0 once its solve has started.
  const fs::path first_log = out / "runs/point_mass_drop__impulsive__seed=1/optimize.log";
  const fs::path first = first_log.parent_path();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(300);
  while (!fs::exists(first_log) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(first_log)) << "task 0 did not start its solve";
  ASSERT_FALSE(fs::exists(first / "record.json")) << "the solve ended before it could be cancelled";
  ASSERT_EQ(std::system(("scancel " + job + "_0").c_str()), 0);

  nlohmann::json status = waitForTasks(out);
  EXPECT_EQ(status["records"], 1) << status.dump();
  EXPECT_FALSE(fs::exists(first / "record.json"));
  EXPECT_EQ(status["tasks"]["cancelled"], 1) << status.dump();
  EXPECT_EQ(status["tasks"]["completed"], 1) << status.dump();
  ASSERT_EQ(status["unfinished"].size(), 1u) << status.dump();
  EXPECT_EQ(status["unfinished"][0]["task"], 0);
  EXPECT_EQ(status["unfinished"][0]["state"], "CANCELLED");
  EXPECT_EQ(status["unfinished"][0]["solves"], nlohmann::json::array({first.filename().string()}));
  EXPECT_FALSE(status["unfinished"][0]["log"].empty());  // the last lines of the task's log
  const auto text = runSaltus({"sweep", "status", out.string()});
  EXPECT_NE(text.out.find("task " + job + "_0 CANCELLED, no record for: " + first.filename().string()), std::string::npos)
      << text.out;

  // Resume: only the cancelled solve goes to Slurm, and nothing is counted twice.
  const std::string kept = readFile(out / "runs/point_mass_drop__impulsive__seed=2/record.json");
  const auto resumed = runSaltus({"sweep", spec.string(), "--out", out.string(), "--slurm"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("1 solves in 1 array task"), std::string::npos) << resumed.err;
  status = waitForTasks(out);
  EXPECT_EQ(status["records"], 2) << status.dump();
  EXPECT_EQ(status["without_record"], 0) << status.dump();
  EXPECT_TRUE(status["unfinished"].empty()) << status.dump();  // task 0 of the first array is redone
  EXPECT_EQ(readFile(out / "runs/point_mass_drop__impulsive__seed=2/record.json"), kept);
  ASSERT_EQ(runSaltus({"sweep", "collect", out.string()}).status, 0);
  const nlohmann::json summary = nlohmann::json::parse(readFile(out / "summary.json"));
  EXPECT_EQ(summary["cells"][0]["solves"], 2);
  EXPECT_EQ(summary["cells"][0]["successes"], 2);
  fs::remove_all(dir);
}

TEST_F(SlurmSweep, BadPartitionIsReportedWithSlurmsOwnMessage) {
  const fs::path dir = saltus::testing::scratchPath("slurm", "partition");
  const fs::path spec = dir / "spec.yaml", out = dir / "out";
  writeSlurmSpec(spec, 1);
  const auto r = runSaltus({"sweep", spec.string(), "--out", out.string(), "--slurm", "--partition", "no_such_partition"});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(r.out.empty()) << r.out;
  // sbatch's words, as Slurm 22.05 prints them.
  EXPECT_NE(r.err.find("sbatch refused the job array: sbatch: error: invalid partition specified: no_such_partition"),
            std::string::npos)
      << r.err;
  // Nothing half-written: no script, no list of solves, no submission.
  EXPECT_FALSE(fs::exists(out / "slurm/sweep.sbatch"));
  EXPECT_FALSE(fs::exists(out / "slurm/cases-1.txt"));
  EXPECT_FALSE(fs::exists(out / "slurm/jobs.json"));
  for (const auto& e : fs::directory_iterator(out / "slurm")) EXPECT_TRUE(e.is_directory()) << e.path();
  fs::remove_all(dir);
}

}  // namespace
