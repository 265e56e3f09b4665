// saltus/simulate.cpp: the library API's simulation, in memory and streamed. Newton's rebound
// apex e² h (ball_drop), the arrays' shapes against the step count, the streamed samples and the
// arrays against each other (one file, byte for byte), and refusals naming the option.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "saltus/saltus.hpp"
#include "tests/support/files.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;

// The message of the std::invalid_argument `f` throws ("" when it throws none).
template <class F>
std::string invalidArgument(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ApiSimulate, BallReboundsToNewtonsApexWithArraysOfOneRowPerSample) {
  // h = 1 m, e = 0.5: the first apex after the bounce is e² h = 0.25 m (Newton's restitution).
  const saltus::scene::Scene scene = saltus::loadScene("ball_drop", {{"restitution", 0.5}});
  saltus::SimulateOptions options;
  options.dt = 1e-4;
  options.duration = 0.8;  // one bounce: the ball lands at 0.45 s and again at 0.90 s
  options.theta = 0.5;
  const saltus::Simulation run = saltus::simulate(scene, options);
  const long steps = saltus::stepCount(0.8, 1e-4);
  ASSERT_EQ(steps, 8000);
  ASSERT_EQ(run.t.size(), steps + 1);
  ASSERT_EQ(run.q.rows(), steps + 1);
  ASSERT_EQ(run.q.cols(), scene.model.nq());
  ASSERT_EQ(run.v.rows(), steps + 1);
  ASSERT_EQ(run.contacts.size(), run.layout.contacts.size());
  ASSERT_FALSE(run.contacts.empty());
  EXPECT_EQ(run.summary.stats.steps, steps);
  EXPECT_DOUBLE_EQ(run.t[0], 0.0);
  EXPECT_NEAR(run.t[steps], 0.8, 1e-9);
  EXPECT_NEAR(run.summary.end_time, 0.8, 1e-9);

  // The apex after the bounce (t > 0.5 s: the ball reaches the ground at sqrt(2/g) = 0.45 s).
  double apex = 0;
  for (Eigen::Index k = 0; k < run.t.size(); ++k)
    if (run.t[k] > 0.5) apex = std::max(apex, run.q(k, 0));
  EXPECT_NEAR(apex, 0.25, 2e-3);
  // One impact: the contact's normal impulse is m (1 + e) sqrt(2 g h) summed over the impact.
  const saltus::ContactHistory& ground = run.contacts.front();
  const double g = 9.81, impulse = ground.pn.head(static_cast<Eigen::Index>(0.6 / 1e-4)).sum();
  EXPECT_NEAR(impulse, scene.model.totalMass() * 1.5 * std::sqrt(2 * g * 1.0), 2e-2);
  // Energy: e² of it is left after the bounce.
  EXPECT_NEAR(run.summary.energy_end / run.summary.energy_start, 0.25, 1e-2);
  EXPECT_FALSE(run.summary.driven);
}

TEST(ApiSimulate, StreamedSamplesAreTheArraysAndWriteTheSameFile) {
  const saltus::scene::Scene scene = saltus::loadScene("block_slide", {});
  saltus::SimulateOptions options;
  options.dt = 2e-3;
  const saltus::Simulation run = saltus::simulate(scene, options);

  const fs::path dir = fs::temp_directory_path() / ("saltus_api_simulate_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  long k = 0;
  bool same = true;
  {
    saltus::scene::TrajectoryCsvWriter writer((dir / "streamed.csv").string(), saltus::scene::trajectoryLayout(scene));
    saltus::simulate(scene, options, [&](const saltus::SimulationSample& s) {
      same = same && s.t == run.t[k] && s.q == run.q.row(k).transpose() && s.v == run.v.row(k).transpose() &&
             s.contacts.front().pt1 == run.contacts.front().pt1[k];
      ++k;
      saltus::writeSample(writer, s);
    });
    writer.commit();
  }
  EXPECT_TRUE(same);
  EXPECT_EQ(k, run.t.size());
  saltus::writeTrajectoryCsv((dir / "arrays.csv").string(), run);
  const std::string streamed = readFile(dir / "streamed.csv");
  EXPECT_GT(streamed.size(), 1000u);
  EXPECT_EQ(readFile(dir / "arrays.csv"), streamed);
  fs::remove_all(dir);
}

TEST(ApiSimulate, BadOptionsAreRefusedNamingTheField) {
  const saltus::scene::Scene scene = saltus::loadScene("ball_drop", {});
  saltus::SimulateOptions options;
  options.dt = 0;
  EXPECT_EQ(invalidArgument([&] { saltus::simulate(scene, options); }).rfind("dt: ", 0), 0u);
  options.dt = 1e-3;
  options.theta = 0.3;
  EXPECT_EQ(invalidArgument([&] { saltus::simulate(scene, options); }).rfind("theta: ", 0), 0u);
  options.theta = 1;
  options.duration = std::nan("");
  EXPECT_EQ(invalidArgument([&] { saltus::simulate(scene, options); }).rfind("duration: ", 0), 0u);
  // A step count that would overflow is refused, not run as one step.
  options.duration = 1e300;
  EXPECT_NE(invalidArgument([&] { saltus::simulate(scene, options); }).find("too many steps"), std::string::npos);
  options.duration = 1;
  options.dt = 1e-300;
  EXPECT_NE(invalidArgument([&] { saltus::simulate(scene, options); }).find("too many steps"), std::string::npos);
}

TEST(ApiSimulate, TheSizeIsKnownBeforeTheRun) {
  const saltus::scene::Scene scene = saltus::loadScene("pendulum_conveyor", {});
  saltus::SimulateOptions options;
  options.duration = 2;
  options.every = 7;
  const saltus::Simulation run = saltus::simulate(scene, options);
  EXPECT_EQ(run.t.size(), saltus::sampleCount(scene, options));
  EXPECT_EQ(run.t.size(), 1 + 286);  // t = 0, steps 7, 14, … 1995, and 2000
  EXPECT_NEAR(run.t[1], 7e-3, 1e-12);
  EXPECT_NEAR(run.t[run.t.size() - 1], 2.0, 1e-9);
  // the estimate is within 25 % of the file written
  const fs::path csv = fs::temp_directory_path() / ("saltus_api_size_" + std::to_string(::getpid()) + ".csv");
  saltus::writeTrajectoryCsv(csv.string(), run);
  const double ratio = static_cast<double>(fs::file_size(csv)) / saltus::csvBytesEstimate(scene, options);
  fs::remove(csv);
  EXPECT_GT(ratio, 0.75);
  EXPECT_LT(ratio, 1.25);
  // a step longer than the run, and arrays beyond the memory limit, are refused before running
  options.dt = 3;
  EXPECT_NE(invalidArgument([&] { saltus::simulate(scene, options); }).find("longer than the duration"), std::string::npos);
  options.dt = 1e-3;
  options.every = 1;
  options.duration = 1e7;
  EXPECT_NE(invalidArgument([&] { saltus::simulate(scene, options); }).find("GB of memory"), std::string::npos);
}

TEST(ApiSimulate, StepCountCoversTheDuration) {
  EXPECT_EQ(saltus::stepCount(1.0, 1e-3), 1000);  // 1/1e-3 is 1000 up to round-off
  EXPECT_EQ(saltus::stepCount(1.0005, 1e-3), 1001);
  EXPECT_EQ(saltus::stepCount(1e-9, 1e-3), 1);
  EXPECT_EQ(saltus::stepCount(0.3, 0.1), 3);
}

TEST(ApiSimulate, ABeltOrAnInputDrivesTheScene) {
  EXPECT_TRUE(saltus::isDriven(saltus::loadScene("pendulum_conveyor", {})));
  EXPECT_FALSE(saltus::isDriven(saltus::loadScene("painleve_rod", {})));
}

}  // namespace
