// Reading trajectory CSVs: interpolation, jumps (two rows at one t), forces and impulses of both
// writers (collocation rows with rn/pn, time-stepper rows with step impulses), bad files.
#include "render/csv_trajectory.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/files.hpp"
#include "tests/support/scenes.hpp"

namespace {

using saltus::render::CsvTrajectory;

// Files of this program's tests, removed when it exits.
std::string writeCsvFile(const std::string& name, const std::string& text) {
  static const saltus::testing::ScratchDir dir("render", "csv_trajectory");
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

// Collocation-style rows: force samples at some rows (0 where there is no force variable), a
// velocity jump at t = 0.5 (before, then after with the impulse).
const char* kCollocationCsv =
    "t,q.z,v.z,contact.ball.gap,contact.ball.vn,contact.ball.vt,contact.ball.rn,contact.ball.rt,contact.ball.pn,contact.ball.pt\n"
    "0,1,0,1,0,0,0,0,0,0\n"
    "0.25,0.75,-2,0.75,-2,0,2,0,0,0\n"
    "0.5,0.5,-3,0.5,-3,0,0,0,0,0\n"
    "0.5,0.5,1.5,0.5,1.5,0,0,0,4.5,0\n"
    "1.0,0.5,0,0.5,0,0,10,0,0,0\n";

TEST(CsvTrajectory, InterpolatesPositionsLinearlyAndClampsOutsideTheRange) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.5);
  const CsvTrajectory tr(writeCsvFile("interp.csv", kCollocationCsv), scene);
  EXPECT_EQ(tr.rows(), 5);
  EXPECT_DOUBLE_EQ(tr.startTime(), 0);
  EXPECT_DOUBLE_EQ(tr.endTime(), 1);
  EXPECT_NEAR(tr.q(0.125)[0], 0.875, 1e-12);
  EXPECT_NEAR(tr.q(0.5)[0], 0.5, 1e-12);   // the jump instant
  EXPECT_NEAR(tr.q(0.75)[0], 0.5, 1e-12);  // after the jump: rows 4 and 5
  EXPECT_NEAR(tr.q(-1)[0], 1.0, 1e-12);
  EXPECT_NEAR(tr.q(2)[0], 0.5, 1e-12);
}

TEST(CsvTrajectory, ForceColumnsGiveForcesBetweenSamplesAndImpulsesAtJumps) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.5);
  const CsvTrajectory tr(writeCsvFile("forces.csv", kCollocationCsv), scene);
  EXPECT_TRUE(tr.hasForceColumns());
  ASSERT_EQ(tr.impulses().size(), 1u);
  EXPECT_DOUBLE_EQ(tr.impulses()[0].t, 0.5);
  EXPECT_EQ(tr.impulses()[0].contact, 0);
  EXPECT_DOUBLE_EQ(tr.impulses()[0].p.normal, 4.5);
  // samples (0.25, 2) and (1, 10); rows with all-zero forces carry no sample
  EXPECT_NEAR(tr.contactForces(0.75)[0].normal, 2 + 8 * (0.5 / 0.75), 1e-12);
  EXPECT_NEAR(tr.contactForces(0.25)[0].normal, 2, 1e-12);
  EXPECT_NEAR(tr.contactForces(0.1)[0].normal, 2, 1e-12);
}

TEST(CsvTrajectory, TimeStepperRowsSplitImpactsFromMeanForces) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.0);
  // dt = 0.01: falling at 2 m/s, an impact stops it (pn = 2 N s at t = 0.02), then resting
  // contact with pn = m g dt each step: a mean force of m g.
  const char* csv =
      "t,q.z,v.z,contact.ball.gap,contact.ball.vn,contact.ball.vt,contact.ball.pn,contact.ball.pt\n"
      "0,0.04,-2,0.04,-2,0,0,0\n"
      "0.01,0.02,-2,0.02,-2,0,0,0\n"
      "0.02,0,0,0,0,0,2,0\n"
      "0.03,0,0,0,0,0,0.0981,0\n"
      "0.04,0,0,0,0,0,0.0981,0\n";
  const CsvTrajectory tr(writeCsvFile("stepper.csv", csv), scene);
  EXPECT_FALSE(tr.hasForceColumns());
  ASSERT_EQ(tr.impulses().size(), 1u);
  EXPECT_DOUBLE_EQ(tr.impulses()[0].t, 0.02);
  EXPECT_DOUBLE_EQ(tr.impulses()[0].p.normal, 2);
  EXPECT_NEAR(tr.contactForces(0.035)[0].normal, 9.81, 1e-9);  // held over the step (0.03, 0.04]
  EXPECT_NEAR(tr.contactForces(0.015)[0].normal, 0, 1e-12);    // free flight
  EXPECT_NEAR(tr.contactForces(0.02)[0].normal, 0, 1e-12);     // the impact is not a force
}

TEST(CsvTrajectory, BadFilesGiveErrorsNamingFileLineAndColumn) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.5);
  auto message = [&](const std::string& path) {
    try {
      CsvTrajectory tr(path, scene);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("/nonexistent/trajectory.csv").find("/nonexistent/trajectory.csv: cannot read"), std::string::npos);
  const std::string no_q = writeCsvFile("noq.csv", "t,q.x,v.x\n0,1,0\n");
  EXPECT_NE(message(no_q).find(no_q + ":1: no column 'q.z'"), std::string::npos);
  const std::string bad = writeCsvFile("bad.csv", "t,q.z\n0,1\n0.1,abc\n");
  EXPECT_NE(message(bad).find(bad + ":3: column 'q.z': expected a finite number, got 'abc'"), std::string::npos);
  // A pose that is not finite would draw nothing: refused where it is.
  const std::string nan = writeCsvFile("nan.csv", "t,q.z\n0,1\n0.1,nan\n");
  EXPECT_NE(message(nan).find(nan + ":3: column 'q.z': expected a finite number, got 'nan'"), std::string::npos);
  const std::string twice = writeCsvFile("twice.csv", "t,q.z,q.z\n0,1,2\n");
  EXPECT_NE(message(twice).find(twice + ":1: column 'q.z' appears twice"), std::string::npos);
  const std::string back = writeCsvFile("back.csv", "t,q.z\n0,1\n0.2,1\n0.1,1\n");
  EXPECT_NE(message(back).find(back + ":4: t = 0.1 is before the previous row's"), std::string::npos);
  const std::string still = writeCsvFile("still.csv", "t,q.z\n0,1\n0,1\n0,1\n");
  EXPECT_NE(message(still).find(still + ": every row is at t = 0"), std::string::npos) << message(still);
  const std::string empty = writeCsvFile("empty.csv", "t,q.z\n");
  EXPECT_NE(message(empty).find("no data rows"), std::string::npos);
}

}  // namespace
