// PNG round trip, and MP4 videos through ffmpeg checked with ffprobe (size, frame count), and
// the errors when ffmpeg is missing or fails.
#include "render/image_io.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;
using namespace saltus::render;

fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / ("saltus_image_io_" + std::to_string(::getpid()) + "_" + name);
}

std::vector<std::uint8_t> gradient(int w, int h, int frame) {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * w + x) * 3];
      p[0] = static_cast<std::uint8_t>(4 * x);
      p[1] = static_cast<std::uint8_t>(4 * y);
      p[2] = static_cast<std::uint8_t>(40 * frame);
    }
  return rgb;
}

std::string commandOutput(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return out;
  char buf[256];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  ::pclose(pipe);
  return out;
}

// Restores an environment variable at the end of a test.
struct EnvironmentVariable {
  std::string name;
  EnvironmentVariable(std::string n, const char* value) : name(std::move(n)) { ::setenv(name.c_str(), value, 1); }
  ~EnvironmentVariable() { ::unsetenv(name.c_str()); }
};

TEST(ImageIo, PngRoundTrip) {
  const auto image = gradient(40, 30, 3);
  const std::string path = scratch("roundtrip.png").string();
  writePng(path, image, 40, 30);
  int w = 0, h = 0;
  EXPECT_EQ(readPng(path, &w, &h), image);
  EXPECT_EQ(w, 40);
  EXPECT_EQ(h, 30);
  fs::remove(path);
  EXPECT_THROW(writePng("/nonexistent/dir/x.png", image, 40, 30), std::runtime_error);
}

TEST(ImageIo, VideoHasTheSizeAndFrameCount) {
  const std::string path = scratch("video.mp4").string();
  {
    VideoWriter video(path, 64, 48, 25);
    for (int k = 0; k < 7; ++k) video.addFrame(gradient(64, 48, k));
    EXPECT_FALSE(fs::exists(path));  // only once finished
    video.finish();
  }
  ASSERT_TRUE(fs::exists(path));
  const std::string probe = commandOutput(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries stream=codec_name,width,height,pix_fmt,nb_read_frames "
      "-of csv=p=0 '" + path + "'");
  EXPECT_EQ(probe, "h264,64,48,yuv420p,7\n");
  fs::remove(path);
}

TEST(ImageIo, VideoErrorsAreClearAndLeaveNoFile) {
  const std::string path = scratch("bad.mp4").string();
  try {
    VideoWriter video(path, 63, 48, 25);
    FAIL() << "odd width accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("even width and height"), std::string::npos) << e.what();
  }
  {
    EnvironmentVariable missing("SALTUS_FFMPEG", "/nonexistent/ffmpeg");
    try {
      VideoWriter video(path, 64, 48, 25);
      FAIL() << "missing ffmpeg accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("'/nonexistent/ffmpeg' was not found"), std::string::npos) << e.what();
    }
  }
  {
    // an ffmpeg that prints a message and fails without reading its input
    const fs::path script = scratch("failing_ffmpeg.sh");
    {
      std::FILE* f = std::fopen(script.c_str(), "w");
      std::fputs("#!/bin/sh\necho 'Unknown encoder libx264' >&2\nexit 1\n", f);
      std::fclose(f);
    }
    fs::permissions(script, fs::perms::owner_all);
    EnvironmentVariable failing("SALTUS_FFMPEG", script.c_str());
    std::string message;
    try {
      VideoWriter video(path, 64, 48, 25);
      for (int k = 0; k < 50; ++k) video.addFrame(gradient(64, 48, k));
      video.finish();
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    EXPECT_NE(message.find("Unknown encoder libx264"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(path));
    fs::remove(script);
  }
}

}  // namespace
