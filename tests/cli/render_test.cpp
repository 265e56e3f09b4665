// saltus render: a simulated trajectory to an MP4 (checked with ffprobe) and PNG frames, an
// optimisation directory through its summary.json, and the errors for bad input.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/support/run_saltus.hpp"

namespace {

namespace fs = std::filesystem;
using saltus::testing::runSaltus;

fs::path renderScratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("saltus_cli_render_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::string probeVideo(const fs::path& path) {
  std::string out;
  FILE* pipe = ::popen(("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                        "stream=width,height,nb_read_frames -of csv=p=0 '" + path.string() + "'").c_str(), "r");
  char buf[256];
  for (std::size_t n; pipe && (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  if (pipe) ::pclose(pipe);
  return out;
}

TEST(CliRender, SimulatedTrajectoryToVideoAndFrames) {
  const fs::path csv = renderScratch("ball.csv"), video = renderScratch("ball.mp4"), frames = renderScratch("frames");
  ASSERT_EQ(runSaltus({"simulate", "ball_drop", "--duration", "0.2", "--out", csv.string()}).status, 0);
  const auto r = runSaltus({"render", csv.string(), "--scene", "ball_drop", "--out", video.string(), "--frames",
                            frames.string(), "--fps", "20", "--width", "160", "--height", "120"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("saltus render: 5 frames 160x120"), std::string::npos) << r.err;
  EXPECT_EQ(probeVideo(video), "160,120,5\n");  // t = 0, 0.05, …, 0.2
  EXPECT_TRUE(fs::exists(frames / "frame_00000.png"));
  EXPECT_TRUE(fs::exists(frames / "frame_00004.png"));
  EXPECT_FALSE(fs::exists(frames / "frame_00005.png"));
  fs::remove_all(csv.parent_path());
}

TEST(CliRender, OptimizeDirectoryLoadsItsProblemScene) {
  const fs::path dir = renderScratch("run");
  fs::create_directories(dir);
  std::ofstream(dir / "summary.json") << R"({"source": "builtin:point_mass_drop", "parameters": {"height": 0.1, "restitution": 0}})";
  std::ofstream(dir / "trajectory.csv") << "t,q.z,v.z,contact.ball.rn,contact.ball.pn\n"
                                           "0,0.1,0,0,0\n0.1,0.05,-1,0,0\n0.1,0.05,0,0,1\n0.2,0.05,0,9.81,0\n";
  const auto r = runSaltus({"render", dir.string(), "--frames", (dir / "frames").string(), "--fps", "10",
                            "--width", "80", "--height", "60", "--speed", "0.5"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_00004.png"));  // 0.2 s at half speed, 10 fps
  EXPECT_FALSE(fs::exists(dir / "frames" / "frame_00005.png"));
  fs::remove_all(dir.parent_path());
}

TEST(CliRender, BadInputGivesClearErrors) {
  const fs::path dir = renderScratch("bad");
  fs::create_directories(dir);
  auto r = runSaltus({"render", "/nonexistent/t.csv", "--scene", "ball_drop", "--out", "x.mp4"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/nonexistent/t.csv: no such file"), std::string::npos) << r.err;

  r = runSaltus({"render", dir.string(), "--out", (dir / "x.mp4").string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("summary.json: missing"), std::string::npos) << r.err;

  std::ofstream(dir / "summary.json") << R"({"problem": "x", "parameters": {}})";
  r = runSaltus({"render", dir.string(), "--out", (dir / "x.mp4").string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("no key \"source\""), std::string::npos) << r.err;

  const fs::path csv = dir / "t.csv";
  std::ofstream(csv) << "t,q.z\n0,1\n0.1,1\n";
  r = runSaltus({"render", csv.string(), "--scene", "ball_drop", "--out", (dir / "x.mp4").string(), "--fps", "0"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--fps: expected frames per second"), std::string::npos) << r.err;

  r = runSaltus({"render", csv.string(), "--out", (dir / "x.mp4").string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--scene: required"), std::string::npos) << r.err;

  r = runSaltus({"render", csv.string(), "--scene", "ball_drop"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nothing to write"), std::string::npos) << r.err;

  r = runSaltus({"render", csv.string(), "--scene", "ball_drop", "--out", (dir / "x.mp4").string(), "--camera", "orbit"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--camera: unknown camera 'orbit'"), std::string::npos) << r.err;

  // ffmpeg missing: exit 1, the program named, no video left behind
  r = runSaltus({"render", csv.string(), "--scene", "ball_drop", "--out", (dir / "x.mp4").string(), "--width", "80",
                 "--height", "60"},
                "SALTUS_FFMPEG=/nonexistent/ffmpeg");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("'/nonexistent/ffmpeg' was not found"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.mp4"));
  fs::remove_all(dir.parent_path());
}

}  // namespace
