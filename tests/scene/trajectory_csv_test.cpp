// scene/trajectory_csv.hpp: the header names every column the readers look up, each row holds
// what it was given, and an unfinished file leaves nothing behind (read with a plain split, not
// the reader under test); readTrajectoryCsv gives back what the writer wrote, and refuses a bad
// file naming its line and column.
#include "scene/trajectory_csv.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "scene/scenario.hpp"

namespace saltus::scene {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> splitLine(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream s(line);
  for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
  return fields;
}

std::vector<std::vector<std::string>> readLines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(splitLine(line));
  return lines;
}

TrajectoryLayout twoContacts(bool forces) {
  TrajectoryLayout layout;
  layout.coordinates = {"x", "z"};
  layout.inputs = {"x"};
  layout.contacts = {{"foot", true}, {"stop", false}};
  layout.forces = forces;
  return layout;
}

class TrajectoryCsvTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("saltus_trajectory_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(TrajectoryCsvTest, HeaderAndRowsOfAnOptimisersFile) {
  const fs::path path = dir_ / "trajectory.csv";
  TrajectoryCsvWriter writer(path.string(), twoContacts(true));
  ContactRow foot;
  foot.gap = 0.25;
  foot.vn = -1.5;
  foot.vt = {0.5, -0.125};
  foot.rn = 9.81;
  foot.rt = {1, 2};
  foot.pn = 0.75;
  foot.pt = {3, 4};
  ContactRow stop;
  stop.gap = 0.1;
  stop.vn = 0.2;
  stop.vt = {7, 8};  // a planar group writes the first of each pair only
  stop.pn = 0.3;
  writer.beginRow(0.001, Eigen::Vector2d(1, 2), Eigen::Vector2d(3, 4), Eigen::VectorXd::Constant(1, 5));
  writer.contact(foot);
  writer.contact(stop);
  writer.endRow();
  writer.commit();
  const auto lines = readLines(path);
  ASSERT_EQ(lines.size(), 2u);
  const std::vector<std::string> header = {
      "t", "q.x", "q.z", "v.x", "v.z", "u.x",
      "contact.foot.gap", "contact.foot.vn", "contact.foot.vt1", "contact.foot.vt2", "contact.foot.rn",
      "contact.foot.rt1", "contact.foot.rt2", "contact.foot.pn", "contact.foot.pt1", "contact.foot.pt2",
      "contact.stop.gap", "contact.stop.vn", "contact.stop.vt", "contact.stop.rn", "contact.stop.rt",
      "contact.stop.pn", "contact.stop.pt"};
  EXPECT_EQ(lines[0], header);
  const std::vector<double> row = {0.001, 1, 2, 3, 4, 5, 0.25, -1.5, 0.5, -0.125, 9.81, 1, 2, 0.75, 3, 4,
                                   0.1, 0.2, 7, 0, 0, 0.3, 0};
  ASSERT_EQ(lines[1].size(), row.size());
  for (std::size_t i = 0; i < row.size(); ++i) EXPECT_EQ(std::stod(lines[1][i]), row[i]) << header[i];
}

// A contact on a plane fixed in a body has the point's plane coordinates: .s on the skateboard's
// planar feet (free along the deck), nothing on its wheels (on the world's ground).
TEST_F(TrajectoryCsvTest, APointOnABodysPlaneHasItsPlaneCoordinates) {
  const Scene board = loadScene("skateboard");
  const TrajectoryLayout layout = trajectoryLayout(board);
  const std::vector<std::string> names = trajectoryHeader(layout);
  auto has = [&](const std::string& name) { return std::find(names.begin(), names.end(), name) != names.end(); };
  EXPECT_TRUE(has("contact.back_foot.s"));
  EXPECT_TRUE(has("contact.front_foot.s"));
  EXPECT_FALSE(has("contact.rear_wheel.s"));
  EXPECT_FALSE(has("contact.tail.s"));
  const fs::path path = dir_ / "feet.csv";
  TrajectoryCsvWriter writer(path.string(), layout);
  writer.beginRow(0, board.q0, board.v0, Eigen::VectorXd());
  for (std::size_t c = 0; c < layout.contacts.size(); ++c) {
    ContactRow r;
    r.s = {0.125 * static_cast<double>(c), 9};  // a planar contact writes the first only
    writer.contact(r);
  }
  writer.endRow();
  writer.commit();
  const TrajectoryTable table = readTrajectoryCsv(path.string());
  ASSERT_EQ(table.names(), names);
  for (std::size_t c = 0; c < layout.contacts.size(); ++c) {
    if (layout.contacts[c].plane_axes == 0) continue;
    EXPECT_EQ(table.values("contact." + layout.contacts[c].name + ".s"), std::vector<double>{0.125 * static_cast<double>(c)});
  }
}

TEST_F(TrajectoryCsvTest, AStepperFileHasNoForceColumnsAndKeepsTwelveDigits) {
  const fs::path path = dir_ / "sim.csv";
  TrajectoryLayout layout = twoContacts(false);
  layout.inputs.clear();
  TrajectoryCsvWriter writer(path.string(), layout);
  const double third = 1.0 / 3.0;
  writer.beginRow(third, Eigen::Vector2d(third, 0), Eigen::Vector2d::Zero(), Eigen::VectorXd());
  writer.contact(ContactRow{});
  writer.contact(ContactRow{});
  writer.endRow();
  writer.commit();
  const auto lines = readLines(path);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].size(), 5u + 7u + 5u);  // t, q, v; gap vn vt1 vt2 pn pt1 pt2; gap vn vt pn pt
  EXPECT_EQ(lines[1].size(), lines[0].size());
  EXPECT_NEAR(std::stod(lines[1][0]), third, 1e-12);
  EXPECT_NEAR(std::stod(lines[1][1]), third, 1e-12);
}

TEST_F(TrajectoryCsvTest, RowsThatDoNotMatchTheHeaderAreRefusedAndNothingIsLeft) {
  const fs::path path = dir_ / "bad.csv";
  {
    TrajectoryCsvWriter writer(path.string(), twoContacts(false));
    EXPECT_THROW(writer.beginRow(0, Eigen::VectorXd::Zero(3), Eigen::Vector2d::Zero(), Eigen::VectorXd::Zero(1)),
                 std::invalid_argument);
    writer.beginRow(0, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::VectorXd::Zero(1));
    writer.contact(ContactRow{});
    EXPECT_THROW(writer.endRow(), std::invalid_argument);  // one contact short
    writer.contact(ContactRow{});
    EXPECT_THROW(writer.contact(ContactRow{}), std::invalid_argument);  // one too many
  }  // never committed
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(TrajectoryCsvTest, TheReaderGivesBackWhatTheWriterWrote) {
  const fs::path path = dir_ / "trajectory.csv";
  TrajectoryCsvWriter writer(path.string(), twoContacts(true));
  ContactRow foot;
  foot.gap = 0.25;
  foot.rn = 1.0 / 7.0;
  foot.pt = {3, -4};
  for (int k = 0; k < 3; ++k) {
    const double t = k < 2 ? 0.1 * k : 0.1;  // rows 1 and 2: a velocity jump at one time
    writer.beginRow(t, Eigen::Vector2d(k, -k), Eigen::Vector2d(0.5 * k, 2), Eigen::VectorXd::Constant(1, k / 3.0));
    writer.contact(foot);
    writer.contact(ContactRow{});
    writer.endRow();
  }
  writer.commit();
  const TrajectoryTable table = readTrajectoryCsv(path.string());
  EXPECT_EQ(table.path(), path.string());
  ASSERT_EQ(table.rows(), 3u);
  EXPECT_EQ(table.names(), readLines(path)[0]);
  EXPECT_EQ(table.values("t"), (std::vector<double>{0, 0.1, 0.1}));
  EXPECT_EQ(table.values("q.z"), (std::vector<double>{0, -1, -2}));
  EXPECT_NEAR(table.values("u.x")[2], 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(table.at(1, table.column("contact.foot.rn")), 1.0 / 7.0, 1e-12);
  EXPECT_EQ(table.row(2)[table.column("contact.foot.pt2")], -4);
  EXPECT_FALSE(table.has("contact.foot.pt"));  // a spatial contact has pt1 and pt2
  EXPECT_EQ(table.column("nothing"), -1);
  EXPECT_THROW(table.values("nothing"), std::out_of_range);
}

TEST_F(TrajectoryCsvTest, TheReaderRefusesABadFileNamingTheLineAndColumn) {
  auto refusal = [&](const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    try {
      readTrajectoryCsv(path.string());
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string d = dir_.string() + "/";
  EXPECT_EQ(refusal("nan.csv", "t,q.z\n0,1\n0.1,nan\n"), d + "nan.csv:3: column 'q.z': expected a finite number, got 'nan'");
  EXPECT_EQ(refusal("inf.csv", "t,q.z\n0,1e999\n"), d + "inf.csv:2: column 'q.z': expected a finite number, got '1e999'");
  EXPECT_EQ(refusal("word.csv", "t,q.z\n0,one\n"), d + "word.csv:2: column 'q.z': expected a finite number, got 'one'");
  EXPECT_EQ(refusal("twice.csv", "t,q.z,q.z\n0,1,1\n"), d + "twice.csv:1: column 'q.z' appears twice (columns 2 and 3)");
  EXPECT_EQ(refusal("back.csv", "t,q.z\n0.2,1\n0.1,1\n"),
            d + "back.csv:3: t = 0.1 is before the previous row's; times must not decrease");
  EXPECT_EQ(refusal("short.csv", "t,q.z\n0,1\n0.1\n"), d + "short.csv:3: 1 fields, the header has 2");
  EXPECT_EQ(refusal("first.csv", "q.z,t\n1,0\n"), d + "first.csv:1: expected the first column to be 't', got 'q.z'");
  EXPECT_EQ(refusal("empty.csv", ""), d + "empty.csv: empty file, expected a CSV header starting with 't'");
  EXPECT_EQ(refusal("blank_lines_and_crlf.csv", "t,q.z\r\n\n0,1\r\n"), "accepted");
  // finite but beyond any robot: nothing could be drawn or framed
  EXPECT_EQ(refusal("far.csv", "t,q.z\n0,1\n0.1,-1e308\n"),
            d + "far.csv:3: column 'q.z': -1e308 is beyond the bound of 1e6 m or rad on coordinates "
                "(scene/trajectory_csv.hpp); expected a trajectory of a robot");
  EXPECT_NE(refusal("late.csv", "t,q.z\n0,1\n1e308,1\n").find("late.csv:3: column 't': 1e308 is beyond the bound of 1e9 s"),
            std::string::npos);
  EXPECT_EQ(refusal("bounds.csv", "t,q.z,v.z\n0,1e6,1e300\n1e9,-1e6,0\n"), "accepted");  // at the bounds; v unbounded
  EXPECT_NE(refusal("../nonexistent/x.csv", "").find("cannot read"), std::string::npos);
}

}  // namespace
}  // namespace saltus::scene
