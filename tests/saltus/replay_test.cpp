// saltus/replay.cpp: a saved solution (tests/data/solutions/point_mass_drop_inelastic) replayed
// through the library API in the Saltus stepper, and its files: replay.csv with a row per
// recorded sample, replay.json saying what the result says, no charts when none are asked for.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "saltus/build_paths.hpp"
#include "saltus/saltus.hpp"

namespace {

namespace fs = std::filesystem;

TEST(ApiReplay, TheInelasticDropReplaysWithinToleranceAndWritesItsReport) {
  const std::string solution = (fs::path(SALTUS_SOURCE_DIR) / "tests/data/solutions/point_mass_drop_inelastic").string();
  saltus::verify::ReplayOptions options;
  options.dt = 1e-4;
  const saltus::verify::ReplayResult r = saltus::replay(solution, options);
  ASSERT_EQ(r.engines.size(), 1u);
  EXPECT_TRUE(r.engines.front().completed) << r.engines.front().message;
  EXPECT_TRUE(r.withinTolerance());
  EXPECT_LE(r.engines.front().max_position_deviation, options.resolvedTolerance());
  EXPECT_EQ(r.problem, "point_mass_drop");

  const fs::path out = fs::temp_directory_path() / ("saltus_api_replay_" + std::to_string(::getpid()));
  fs::remove_all(out);
  EXPECT_EQ(saltus::writeReplay(out.string(), r, solution, /*charts=*/false), "");
  std::ifstream json_in(out / "replay.json");
  const nlohmann::json j = nlohmann::json::parse(json_in);
  EXPECT_EQ(j.at("within_tolerance").get<bool>(), r.withinTolerance());
  EXPECT_EQ(j.at("steps").get<long>(), r.steps);
  EXPECT_EQ(j.at("engines").at("saltus").at("max_position_deviation").get<double>(),
            r.engines.front().max_position_deviation);
  EXPECT_TRUE(j.at("charts").empty());
  EXPECT_FALSE(fs::exists(out / "replay_deviation.png"));

  std::ifstream csv(out / "replay.csv");
  long rows = 0;
  for (std::string line; std::getline(csv, line);)
    if (!line.empty() && line[0] != '#') ++rows;
  EXPECT_EQ(rows, static_cast<long>(r.t.size()) + 1);  // the header and one row per sample
  fs::remove_all(out);
}

TEST(ApiReplay, AMissingSolutionIsRefusedNamingTheFile) {
  try {
    saltus::replay("/nonexistent/solution", saltus::verify::ReplayOptions{});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/solution"), std::string::npos) << e.what();
  }
}

}  // namespace
