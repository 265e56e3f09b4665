// `saltus replay`, run as a program on solutions that `saltus optimize` writes once per test
// program (point_mass_drop with e = 0.5, ~0.5 s; tests/data/problems/push_block.yaml, an
// actuated point mass, ~0.4 s): the report's contents (replay.json, replay.csv, charts), a
// deliberately wrong input caught by the tolerance (exit 1), usage errors (exit 2), a directory
// without variables.csv and a failing chart step (exit 1, CSV and JSON kept).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "saltus/build_paths.hpp"
#include "tests/support/run_saltus.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;

fs::path replayTestDir(const std::string& name) { return saltus::testing::scratchPath("replay_test", name); }

// A solution solved once per program, removed when the program ends.
struct SolvedDir {
  fs::path path;
  SolvedDir(const std::string& name, const std::vector<std::string>& optimize_args) : path(replayTestDir(name)) {
    std::vector<std::string> args = optimize_args;
    args.insert(args.end(), {"--out", path.string()});
    const auto r = runSaltus(args);
    EXPECT_EQ(r.status, 0) << r.err;
  }
  ~SolvedDir() { fs::remove_all(path); }
};

const fs::path& dropDir() {
  static const SolvedDir d("drop_solution", {"optimize", "point_mass_drop", "--set", "restitution=0.5", "--seed", "2"});
  return d.path;
}
const fs::path& pushDir() {
  static const SolvedDir d("push_solution",
                           {"optimize", std::string(SALTUS_SOURCE_DIR) + "/tests/data/problems/push_block.yaml"});
  return d.path;
}

TEST(ReplayCommand, BothEnginesOnTheBounceWriteTheReport) {
  const fs::path out = replayTestDir("drop_report");
  const auto r = runSaltus({"replay", dropDir().string(), "--engine", "both", "--out", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const nlohmann::json j = nlohmann::json::parse(readFile(out / "replay.json"));
  EXPECT_EQ(j["problem"], "point_mass_drop");
  EXPECT_DOUBLE_EQ(j["tolerance"].get<double>(), 1e-3);  // 10 m/s × dt, dt 1e-4
  EXPECT_TRUE(j["within_tolerance"].get<bool>());
  EXPECT_EQ(j["optimised_events"].size(), 3u);
  for (const char* name : {"saltus", "bullet"}) {
    SCOPED_TRACE(name);
    const nlohmann::json& e = j["engines"][name];
    ASSERT_TRUE(e.is_object());
    const double max_dev = e["max_position_deviation"].get<double>();
    EXPECT_TRUE(std::isfinite(max_dev));
    EXPECT_GT(max_dev, 0.0);
    EXPECT_LT(max_dev, 1e-3);
    EXPECT_GT(e["rms_position_deviation"].get<double>(), 0.0);
    EXPECT_LE(e["rms_position_deviation"].get<double>(), max_dev);
    EXPECT_LE(e["final_position_deviation"].get<double>(), max_dev);
    EXPECT_TRUE(e["within_tolerance"].get<bool>());
    EXPECT_GE(e["max_penetration"].get<double>(), 0.0);
    EXPECT_EQ(e["events_matched"], 3);
    ASSERT_EQ(e["event_matches"].size(), 3u);
    for (const auto& m : e["event_matches"]) EXPECT_LE(std::abs(m["dt"].get<double>()), 2e-4);
    ASSERT_EQ(e["coordinates"].size(), 1u);
    EXPECT_EQ(e["coordinates"][0]["coordinate"], "z");
  }
  const nlohmann::json& b = j["engines"]["bullet"];
  EXPECT_GE(b["approximations"].size(), 1u);
  EXPECT_EQ(b["mlcp_fallbacks"], 0);
  EXPECT_GT(b["max_penetration"].get<double>(), 0.0);  // Bullet keeps a penetration (erp2 = 0)

  ASSERT_EQ(j["charts"].size(), 4u);
  for (const auto& c : j["charts"]) EXPECT_GT(fs::file_size(out / c.get<std::string>()), 1000u) << c;
  std::stringstream csv(readFile(out / "replay.csv"));
  std::string line, header;
  long rows = 0;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty())
      header = line;
    else
      ++rows;
  }
  EXPECT_EQ(header.rfind("t,opt.q.z,opt.v.z,opt.energy,saltus.q.z,saltus.dq.z,saltus.dv.z,saltus.energy,", 0), 0u) << header;
  EXPECT_NE(header.find("bullet.penetration"), std::string::npos);
  EXPECT_EQ(rows, j["steps"].get<long>() + 1);  // under 4000 steps: every one, and t = 0
  fs::remove_all(out);
}

// MuJoCo as the third engine: the same bounce, its events matched, its soft contact's deviation
// above saltus' (a spring, not Newton's impact) and its approximations in the report.
TEST(ReplayCommand, MujocoReplaysTheBounceWithItsApproximations) {
  const fs::path out = replayTestDir("drop_mujoco");
  const auto r = runSaltus({"replay", dropDir().string(), "--engine", "all", "--tolerance", "0.01", "--out", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(readFile(out / "replay.json"));
  const nlohmann::json& m = j["engines"]["mujoco"];
  ASSERT_TRUE(m.is_object()) << j.dump();
  EXPECT_TRUE(m["within_tolerance"].get<bool>());
  EXPECT_EQ(m["events_matched"], 3);
  EXPECT_EQ(m["warnings"], 0);
  EXPECT_GE(m["approximations"].size(), 3u);
  EXPECT_GT(m["max_position_deviation"].get<double>(), j["engines"]["saltus"]["max_position_deviation"].get<double>());
  EXPECT_NE(readFile(out / "replay.csv").find("mujoco.q.z"), std::string::npos);
  const auto refused = runSaltus({"replay", dropDir().string(), "--engine", "ode", "--out", out.string()});
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("expected saltus, bullet, mujoco, a comma-separated list of them, both or all"), std::string::npos) << refused.err;
  fs::remove_all(out);
}

// An input doubled, then a constant 0.05 N added: exit 1 with the reason on standard error and
// within_tolerance false in the report; the optimised input itself stays within.
TEST(ReplayCommand, AWrongInputIsCaughtByTheTolerance) {
  const fs::path ok = replayTestDir("push_ok");
  const auto good = runSaltus({"replay", pushDir().string(), "--out", ok.string()}, "SALTUS_PYTHON=/bin/true");
  ASSERT_EQ(good.status, 0) << good.err;
  const nlohmann::json jg = nlohmann::json::parse(readFile(ok / "replay.json"));
  EXPECT_LT(jg["engines"]["saltus"]["max_position_deviation"].get<double>(), 1e-6);
  EXPECT_EQ(jg["inputs"], nlohmann::json::array({"x"}));

  const fs::path bad = replayTestDir("push_doubled");
  const auto r = runSaltus({"replay", pushDir().string(), "--input-scale", "2", "--out", bad.string()},
                           "SALTUS_PYTHON=/bin/true");  // real charts: the test above
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("saltus exceeds the tolerance"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("coordinate x"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(readFile(bad / "replay.json"));
  EXPECT_FALSE(j["within_tolerance"].get<bool>());
  EXPECT_FALSE(j["engines"]["saltus"]["within_tolerance"].get<bool>());
  EXPECT_GT(j["engines"]["saltus"]["max_position_deviation"].get<double>(), 0.05);
  EXPECT_EQ(j["charts"].size(), 4u);  // the chart step runs all the same

  const fs::path off = replayTestDir("push_offset");
  const auto o = runSaltus({"replay", pushDir().string(), "--input-offset", "0.05", "--out", off.string()},
                           "SALTUS_PYTHON=/bin/true");
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("exceeds the tolerance"), std::string::npos) << o.err;
  for (const fs::path& d : {ok, bad, off}) fs::remove_all(d);
}

TEST(ReplayCommand, RefusesBadArguments) {
  const fs::path out = replayTestDir("refused");
  auto r = runSaltus({"replay", dropDir().string(), "--engine", "ode", "--out", out.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--engine: unknown engine 'ode'"), std::string::npos) << r.err;
  r = runSaltus({"replay", dropDir().string(), "--dt", "0", "--out", out.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--dt"), std::string::npos) << r.err;
  r = runSaltus({"replay", dropDir().string(), "--dt", "-1e-3", "--out", out.string()});
  EXPECT_EQ(r.status, 2);
  r = runSaltus({"replay", dropDir().string(), "--feedback", "pid", "--out", out.string()});
  EXPECT_EQ(r.status, 2);
  r = runSaltus({"replay", dropDir().string(), "--input-offset", "1", "--out", out.string()});  // no inputs
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no inputs"), std::string::npos) << r.err;
  r = runSaltus({"replay", pushDir().string(), "--input-offset", "1,2", "--out", out.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("expected 1 values"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  // A directory without variables.csv (an optimisation from before variables.csv existed).
  const fs::path empty = replayTestDir("no_variables");
  fs::create_directories(empty);
  r = runSaltus({"replay", empty.string(), "--out", out.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(": no variables.csv in this folder; expected the --out folder of saltus optimize"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // A file that is not a solution is named as given (not as a variables.csv beside it).
  const fs::path text = empty / "notes.txt";
  std::ofstream(text) << "not a solution\n";
  r = runSaltus({"replay", text.string(), "--out", out.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(text.string() + ": not a solution; expected the --out folder"), std::string::npos) << r.err;
  r = runSaltus({"replay", (empty / "gone").string(), "--out", out.string()});
  EXPECT_NE(r.err.find((empty / "gone").string() + ": no such solution"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(empty);
}

TEST(ReplayCommand, FailingChartsKeepCsvAndJson) {
  const fs::path out = replayTestDir("no_charts");
  const auto r = runSaltus({"replay", dropDir().string(), "--out", out.string()}, "SALTUS_PYTHON=/bin/false");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("chart step failed"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(readFile(out / "replay.json"));
  EXPECT_TRUE(j["charts"].empty());
  EXPECT_TRUE(j["within_tolerance"].get<bool>());
  EXPECT_TRUE(fs::exists(out / "replay.csv"));
  EXPECT_FALSE(fs::exists(out / "replay_deviation.png"));
  fs::remove_all(out);
}

}  // namespace
