// Input schedules for the simulation seed (collocation/input_schedule.hpp): a file read back
// row by row and held from each row's time to the next, the columns other than u. ignored, and
// every way a schedule can be wrong refused with the file, the row and the column.
#include "collocation/input_schedule.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/errors.hpp"
#include "tests/support/files.hpp"
#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace input_schedule_test {

// The drop of Fig. 3 with its one coordinate, z, actuated within ±30 N.
Problem actuatedDrop() {
  Problem p = testing::pointMassDrop(0.0);
  p.inputs = {0};
  p.input_lower = Eigen::VectorXd::Constant(1, -30);
  p.input_upper = Eigen::VectorXd::Constant(1, 30);
  return p;
}

// Writes DIR/NAME/schedule.csv.
std::string write(const testing::ScratchDir& dir, const std::string& name, const std::string& text) {
  std::filesystem::create_directories(dir / name);
  const std::string path = (dir / name / "schedule.csv").string();
  std::ofstream(path) << text;
  return path;
}

TEST(InputSchedule, ReadsTheInputColumnsAndHoldsEachRowUntilTheNext) {
  // A trajectory file's other columns are ignored.
  const testing::ScratchDir dir("input_schedule", "good");
  const std::string path = write(dir, "good", "t,q.z,v.z,u.z\n0,0.1,0,19.62\n0.1,0.149,0.981,0\n0.5,0,0,0\n");
  const InputSchedule s = readInputSchedule(path, actuatedDrop());
  ASSERT_EQ(s.times.size(), 3u);
  EXPECT_DOUBLE_EQ(s.horizon(), 0.5);
  EXPECT_DOUBLE_EQ(s.at(0)[0], 19.62);
  EXPECT_DOUBLE_EQ(s.at(0.0999)[0], 19.62);
  EXPECT_DOUBLE_EQ(s.at(0.1)[0], 0);  // a row holds from its own time
  EXPECT_DOUBLE_EQ(s.at(-1)[0], 19.62);
  EXPECT_DOUBLE_EQ(s.at(2)[0], 0);  // the last row holds beyond the horizon
}

TEST(InputSchedule, RefusesWhatIsNotASchedule) {
  const Problem p = actuatedDrop();
  const testing::ScratchDir dir("input_schedule", "bad");
  auto message = [&](const std::string& name, const std::string& text) {
    const std::string path = write(dir, name, text);
    return testing::expectedMessageOf<InputScheduleError>([&] { readInputSchedule(path, p); });
  };
  std::string m = message("missing", "t,q.z\n0,0\n1,0\n");
  EXPECT_NE(m.find("schedule.csv:1: no column 'u.z'"), std::string::npos) << m;
  m = message("extra", "t,u.z,u.x\n0,0,0\n1,0,0\n");
  EXPECT_NE(m.find("column 'u.x' is not an input of 'point_mass_drop'; expected u.z"), std::string::npos) << m;
  m = message("start", "t,u.z\n0.1,0\n1,0\n");
  EXPECT_NE(m.find("row 1 (t = 0.1): the first row must be at t = 0"), std::string::npos) << m;
  m = message("order", "t,u.z\n0,0\n0.5,1\n0.5,2\n");
  EXPECT_NE(m.find("row 3 (t = 0.5): times must increase strictly (the previous row's is 0.5)"), std::string::npos)
      << m;
  m = message("bounds", "t,u.z\n0,0\n0.2,31\n1,0\n");
  EXPECT_NE(m.find("row 2 (t = 0.2): column 'u.z': 31 is outside the input's bounds [-30, 30]"), std::string::npos)
      << m;
  m = message("short", "t,u.z\n0,0\n");
  EXPECT_NE(m.find("1 rows; a schedule needs at least two"), std::string::npos) << m;
  m = message("nan", "t,u.z\n0,nan\n1,0\n");
  EXPECT_NE(m.find("schedule.csv:2: column 'u.z': expected a finite number"), std::string::npos) << m;
  const std::string path = write(dir, "unactuated", "t,u.z\n0,0\n1,0\n");
  m = testing::expectedMessageOf<InputScheduleError>([&] { readInputSchedule(path, testing::pointMassDrop(0.0)); });
  EXPECT_NE(m.find("problem 'point_mass_drop' has none"), std::string::npos) << m;
}

// A tracking reference is linear between its samples; at a velocity jump (two samples at one
// time) it is the one after from that time on; before the first and after the last it holds.
TEST(InputSchedule, TrackingReferenceInterpolatesAndJumps) {
  Tracking tr;
  tr.times = {0, 0.1, 0.1, 0.2};
  for (const auto& [q, v] : {std::pair{0.0, 0.0}, {1.0, 2.0}, {1.0, -2.0}, {3.0, 0.0}}) {
    tr.q.push_back(Eigen::VectorXd::Constant(1, q));
    tr.v.push_back(Eigen::VectorXd::Constant(1, v));
  }
  Eigen::VectorXd q, v;
  const auto at = [&](double t) {
    tr.reference(t, q, v);
    return std::pair{q[0], v[0]};
  };
  EXPECT_NEAR(at(0.05).first, 0.5, 1e-15);
  EXPECT_NEAR(at(0.05).second, 1.0, 1e-15);
  EXPECT_EQ(at(0.1), (std::pair{1.0, -2.0}));
  EXPECT_NEAR(at(0.15).first, 2.0, 1e-15);
  EXPECT_NEAR(at(0.15).second, -1.0, 1e-15);
  EXPECT_EQ(at(-1), (std::pair{0.0, 0.0}));
  EXPECT_EQ(at(0.2), (std::pair{3.0, 0.0}));
  EXPECT_EQ(at(1), (std::pair{3.0, 0.0}));
}

}  // namespace input_schedule_test
}  // namespace saltus::collocation
