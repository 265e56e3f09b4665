// saltus run: the main job on the fast point-mass drop (restitution 0.5, seed 2) at a small video
// size. The report exists, every file it links or shows exists and is not empty, each of the four
// steps has a status, and the exit status agrees with them: 0 only when every step (replay
// included, where this build has it) succeeded. An infeasible solve still gets its chart and
// video, is marked in the report, and the run exits 1; a step that exits 0 without its files
// fails. The trajectory chart comes as PNG and SVG.
#include <unistd.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/run_saltus.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;

fs::path runScratch(const std::string& name) { return saltus::testing::scratchPath("run_test", name); }

// Every Markdown link or image target of the report, e.g. "charts/trajectory.png".
std::set<std::string> reportTargets(const std::string& report) {
  std::set<std::string> targets;
  const std::regex link(R"(\]\(([^)\s]+)\))");
  for (auto it = std::sregex_iterator(report.begin(), report.end(), link); it != std::sregex_iterator(); ++it)
    targets.insert((*it)[1].str());
  return targets;
}

// The status cell of a step's row in the Steps table ("ok", "failed (exit 2): ...", "skipped ...").
std::string stepStatus(const std::string& report, const std::string& step) {
  const std::regex row("\\n\\| " + step + " \\| ([^|]*) \\|");
  std::smatch m;
  return std::regex_search(report, m, row) ? m[1].str() : std::string();
}

void expectLinkedFilesExist(const fs::path& dir, const std::string& report) {
  for (const std::string& target : reportTargets(report)) {
    EXPECT_EQ(target.find("://"), std::string::npos) << target;
    const fs::path file = dir / target;
    ASSERT_TRUE(fs::exists(file)) << "report.md names " << target << ", which does not exist";
    EXPECT_GT(fs::file_size(file), 0u) << target;
  }
}

TEST(CliRun, PointMassDropReportNamesOnlyFilesThatExist) {
  const fs::path dir = runScratch("drop");
  const auto r = runSaltus({"run", "point_mass_drop", "--set", "restitution=0.5", "--seed", "2", "--out", dir.string(),
                            "--fps", "8", "--width", "96", "--height", "64"});
  ASSERT_TRUE(fs::exists(dir / "report.md")) << r.err;
  const std::string report = readFile(dir / "report.md");
  expectLinkedFilesExist(dir, report);
  const std::set<std::string> targets = reportTargets(report);
  for (const char* expected : {"charts/trajectory.png", "charts/trajectory.svg", "render/video.mp4", "render/still.png",
                               "optimize/summary.json", "logs/optimize.log"})
    EXPECT_TRUE(targets.count(expected)) << expected << " not in report.md:\n" << report;

  // Each step has a status; optimize, render and charts succeed here.
  for (const char* step : {"optimize", "render", "charts"}) EXPECT_EQ(stepStatus(report, step), "ok") << step;
  const std::string replay = stepStatus(report, "replay");
  ASSERT_FALSE(replay.empty()) << report;
  EXPECT_NE(report.find("| status | feasible"), std::string::npos) << report;
  EXPECT_NE(report.find("point_mass_drop"), std::string::npos);
  EXPECT_NE(report.find("restitution = 0.5"), std::string::npos) << report;
  if (replay == "ok") {
    // With the replay command: its results per engine and the charts replay.json lists.
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(targets.count("replay/replay.json")) << report;
    EXPECT_NE(report.find("| saltus |"), std::string::npos) << report;
    EXPECT_NE(report.find("| bullet |"), std::string::npos) << report;
    EXPECT_NE(report.find("Result: **ok**"), std::string::npos) << report;
  } else {
    // Without it (or when it fails): reported as failed, and the run fails; without a
    // replay.json no results are shown.
    EXPECT_EQ(replay.rfind("failed", 0), 0u) << replay;
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(report.find("Result: **FAILED** (step replay failed)"), std::string::npos) << report;
    if (!fs::exists(dir / "replay" / "replay.json")) {
      EXPECT_EQ(report.find("| bullet |"), std::string::npos) << report;
      EXPECT_NE(report.find("No replay results: the replay step failed"), std::string::npos) << report;
    }
  }

  // The trajectory chart: a real PNG and SVG, with content.
  const std::string png = readFile(dir / "charts" / "trajectory.png"), svg = readFile(dir / "charts" / "trajectory.svg");
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(png.size(), 20000u);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_GT(svg.size(), 20000u);
  EXPECT_EQ(readFile(dir / "render" / "still.png").substr(1, 3), "PNG");
  EXPECT_FALSE(fs::exists(dir / "render" / "frames"));  // only the still frame is kept
  fs::remove_all(dir);
}

TEST(CliRun, InfeasibleSolveIsMarkedAndTheRunFails) {
  const fs::path dir = runScratch("infeasible");
  // Two Ipopt iterations per stage cannot land the ball (three can: the tightening stage, under
  // the monotone barrier, closes the feasibility stage's near miss): optimize exits 1 but writes
  // its files. The chart interpreter is /bin/true: it exits 0 without drawing, which is a failed
  // step too.
  const auto r = runSaltus({"run", "point_mass_drop", "--ipopt", "max_iter=2", "--out", dir.string(), "--fps", "4",
                            "--width", "64", "--height", "48", "--engine", "saltus"},
                           "SALTUS_PYTHON=/bin/true");
  EXPECT_EQ(r.status, 1) << r.err;
  const std::string report = readFile(dir / "report.md");
  expectLinkedFilesExist(dir, report);
  EXPECT_NE(report.find("| status | **NOT feasible**"), std::string::npos) << report;
  EXPECT_NE(report.find("Result: **FAILED** (the solve is infeasible"), std::string::npos) << report;
  EXPECT_EQ(stepStatus(report, "optimize").rfind("failed (exit 1): the solve ended infeasible", 0), 0u) << report;
  EXPECT_EQ(stepStatus(report, "render"), "ok") << report;
  EXPECT_EQ(stepStatus(report, "charts"), "failed (exit 0): exited 0 but did not write charts/trajectory.png; exited 0 "
                                          "but did not write charts/trajectory.svg")
      << report;
  EXPECT_NE(report.find("No trajectory chart: the charts step failed."), std::string::npos) << report;
  fs::remove_all(dir);
}

TEST(CliRun, BadOptionsAreUsageErrorsAndWriteNothing) {
  const fs::path dir = runScratch("bad");
  auto r = runSaltus({"run", "point_mass_drop", "--width", "101", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--width/--height"), std::string::npos) << r.err;
  r = runSaltus({"run", "point_mass_drop", "--set", "restitution", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--set 'restitution'"), std::string::npos) << r.err;
  r = runSaltus({"run", "point_mass_drop", "--engine", "ode", "--out", dir.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
