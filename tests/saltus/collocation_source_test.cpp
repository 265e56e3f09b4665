// saltus/collocation_source.hpp: an optimised point-mass drop (inelastic) read back as a
// render::TrajectorySource. The solution is a saved `saltus optimize` output directory,
// tests/data/solutions/point_mass_drop_inelastic (see its README): the optimiser itself is tested
// in tests/collocation and tests/cli/optimize_test.cpp, and a saved solve keeps these tests off
// Ipopt's round-off (and ~15 s per test under ASan). In flight the position between the rows is the degree-P
// polynomial through the element's rows (and the parabola z0 − g t²/2 to the solver's
// tolerance), which the CSV's straight lines between rows are not; the impact is one impulse at the instant of the velocity jump; the
// forces reproduce the collocation-point reactions of trajectory.csv; and saltus::openSolution
// renders a solution folder through it.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/csv_trajectory.hpp"
#include "render/image_io.hpp"
#include "saltus/build_paths.hpp"
#include "saltus/collocation_source.hpp"
#include "saltus/saltus.hpp"
#include "scene/trajectory_csv.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::CollocationSource;

// trajectory.csv as columns by name (scene::readTrajectoryCsv).
std::map<std::string, std::vector<double>> readTrajectoryColumns(const fs::path& path) {
  const saltus::scene::TrajectoryTable table = saltus::scene::readTrajectoryCsv(path.string());
  std::map<std::string, std::vector<double>> columns;
  for (const std::string& name : table.names()) columns[name] = table.values(name);
  return columns;
}

class CollocationSourceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A copy, since `saltus render DIR` writes next to it.
    dir_ = fs::temp_directory_path() / ("saltus_collocation_source_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::copy(fs::path(SALTUS_SOURCE_DIR) / "tests/data/solutions/point_mass_drop_inelastic", dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path dir_;
};
fs::path CollocationSourceTest::dir_;

TEST_F(CollocationSourceTest, PositionsFollowThePolynomialsNotStraightLines) {
  const CollocationSource source = CollocationSource::load(dir_.string());
  auto csv = readTrajectoryColumns(dir_ / "trajectory.csv");
  const std::vector<double>& t = csv["t"];
  ASSERT_GT(t.size(), 10u);
  EXPECT_DOUBLE_EQ(source.startTime(), 0.0);
  EXPECT_NEAR(source.endTime(), t.back(), 1e-10);
  ASSERT_EQ(source.impulses().size(), 1u);
  const double impact = source.impulses()[0].t;
  // Free fall from rest: z = z0 − g t²/2, g from the first point's velocity (v = −g t).
  const double z0 = csv["q.z"][0], g = -csv["v.z"][1] / t[1];
  EXPECT_NEAR(g, 9.81, 1e-6);
  const saltus::render::CsvTrajectory lines((dir_ / "trajectory.csv").string(), source.scene());
  // Elements are the runs of rows between repeated times (each mesh point n ≥ 1 is written
  // before and after its jump): start, the P collocation points, end. The state polynomial has
  // degree P, so the one through the first P + 1 rows (built here by Lagrange's formula) passes
  // through the end row as well and is the source's q between the rows.
  auto lagrange = [](const std::vector<double>& ts, const std::vector<double>& ys, double x) {
    double sum = 0;
    for (std::size_t j = 0; j < ts.size(); ++j) {
      double l = 1;
      for (std::size_t m = 0; m < ts.size(); ++m)
        if (m != j) l *= (x - ts[m]) / (ts[j] - ts[m]);
      sum += l * ys[j];
    }
    return sum;
  };
  const std::vector<double>& z = csv["q.z"];
  double largest_line_error = 0;
  int elements = 0;
  for (std::size_t start = 0; start < t.size();) {
    std::size_t end = start + 1;
    while (end < t.size() && t[end] != t[end - 1]) ++end;
    end -= 1;  // the element's last row (before the jump), or the last row of the file
    if (t[end] >= impact) break;
    ASSERT_GE(end - start, 3u);
    const std::vector<double> ts(t.begin() + start, t.begin() + end), ys(z.begin() + start, z.begin() + end);
    EXPECT_NEAR(lagrange(ts, ys, t[end]), z[end], 1e-8);
    for (std::size_t i = start; i < end; ++i) {
      const double tm = 0.5 * (t[i] + t[i + 1]);
      // The rows lie on the polynomial to the solver's constraint tolerance (~1e-9).
      EXPECT_NEAR(source.q(tm)[0], lagrange(ts, ys, tm), 1e-8) << "t = " << tm;
      // Free fall within the solver's tolerance.
      EXPECT_NEAR(source.q(tm)[0], z0 - 0.5 * g * tm * tm, 1e-7) << "t = " << tm;
      largest_line_error = std::max(largest_line_error, std::abs(lines.q(tm)[0] - source.q(tm)[0]));
    }
    ++elements;
    start = end + 1;
  }
  EXPECT_GE(elements, 5);
  // Linear interpolation misses by g Δt²/8 (Δt ≈ 1.5 ms: ~3e-6 m); the polynomials do not.
  EXPECT_GT(largest_line_error, 1e-7);
  // Clamped outside the range.
  EXPECT_NEAR(source.q(-1.0)[0], z0, 1e-12);
  EXPECT_NEAR(source.q(source.endTime() + 1)[0], source.q(source.endTime())[0], 1e-12);
}

TEST_F(CollocationSourceTest, ImpulseAtTheJumpAndForcesThroughTheCollocationPoints) {
  const CollocationSource source = CollocationSource::load(dir_.string());
  auto csv = readTrajectoryColumns(dir_ / "trajectory.csv");
  const std::vector<double>& t = csv["t"];
  // The one impulse: at the velocity jump's instant (two CSV rows share it), the jump listed by
  // the trajectory at that same mesh time, the normal impulse of the CSV's row after the jump.
  ASSERT_EQ(source.impulses().size(), 1u);
  const saltus::render::Impulse& impulse = source.impulses()[0];
  EXPECT_EQ(impulse.contact, 0);
  const auto jumps = source.trajectory().jumps(1e-3);
  ASSERT_EQ(jumps.size(), 1u);
  EXPECT_DOUBLE_EQ(jumps[0].t, impulse.t);
  std::size_t row = 0;
  while (row + 1 < t.size() && !(t[row] == t[row + 1] && std::abs(t[row] - impulse.t) < 1e-10)) ++row;
  ASSERT_LT(row + 1, t.size()) << "no repeated CSV time at the impulse t = " << impulse.t;
  EXPECT_NEAR(impulse.p.normal, csv["contact.ball.pn"][row + 1], 1e-9);
  EXPECT_GT(impulse.p.normal, 1.0);  // m |v⁻| = 1 kg × √(2 g 0.1 m) ≈ 1.4 N s
  EXPECT_NEAR(impulse.p.normal, jumps[0].dv[0], 1e-6 * impulse.p.normal);  // unit mass: p = Δv

  // At every collocation point (a row with a force) the force polynomial takes the row's value;
  // before the impact there is none.
  int checked = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double rn = csv["contact.ball.rn"][i];
    if (rn == 0) continue;
    EXPECT_NEAR(source.contactForces(t[i])[0].normal, rn, 1e-6 * std::max(1.0, std::abs(rn))) << "t = " << t[i];
    ++checked;
  }
  EXPECT_GT(checked, 10);
  EXPECT_NEAR(source.contactForces(0.5 * impulse.t)[0].normal, 0.0, 1e-6);
  // Resting after the landing: the force carries the weight (1 kg × g) on average.
  double sum = 0;
  const int samples = 200;
  const double t0 = impulse.t + 0.2 * (source.endTime() - impulse.t), t1 = source.endTime();
  for (int k = 0; k < samples; ++k) sum += source.contactForces(t0 + (t1 - t0) * (k + 0.5) / samples)[0].normal;
  EXPECT_NEAR(sum / samples, 9.81, 0.5);
}

TEST_F(CollocationSourceTest, RenderOfASolutionFolderUsesIt) {
  const saltus::RenderInput input = saltus::openSolution(dir_.string());
  ASSERT_NE(dynamic_cast<const CollocationSource*>(input.trajectory.get()), nullptr);
  EXPECT_EQ(input.scene.name, CollocationSource::load(dir_.string()).scene().name);
  saltus::render::AnimationOptions options;
  options.fps = 20;
  options.width = 64;
  options.height = 48;
  const fs::path frames = dir_ / "frames";
  std::ostringstream warnings;
  const saltus::RenderReport report = saltus::renderTrajectory(input, options, "", frames.string(), warnings);
  const int expected = static_cast<int>(std::floor(input.trajectory->endTime() * 20 + 1e-9)) + 1;
  EXPECT_EQ(report.frames, expected);
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", expected - 1);
  EXPECT_TRUE(fs::exists(frames / name)) << warnings.str();
  std::snprintf(name, sizeof name, "frame_%05d.png", expected);
  EXPECT_FALSE(fs::exists(frames / name));

  // Frame by frame in memory: the same pixels as the files.
  saltus::FrameRenderer frame_renderer(input, options, warnings);
  ASSERT_EQ(frame_renderer.frames(), expected);
  EXPECT_DOUBLE_EQ(frame_renderer.time(0), 0.0);
  for (int k : {0, expected - 1}) {
    std::snprintf(name, sizeof name, "frame_%05d.png", k);
    int width = 0, height = 0;
    const std::vector<std::uint8_t> png = saltus::render::readPng((frames / name).string(), &width, &height);
    ASSERT_EQ(width, frame_renderer.width());
    ASSERT_EQ(height, frame_renderer.height());
    EXPECT_EQ(frame_renderer.draw(k), png) << name;
  }
  EXPECT_THROW(frame_renderer.draw(expected), std::out_of_range);
}

}  // namespace
