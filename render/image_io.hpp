// Writing frames: PNG files through libpng, and H.264 MP4 videos through the ffmpeg program (raw
// RGB frames piped to `ffmpeg -f rawvideo`). Both write through scene::AtomicFile (a temporary name
// beside the target, renamed when complete), so a failed run leaves no half-written file.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "scene/atomic_file.hpp"
#include "scene/cleanup.hpp"

namespace saltus::render {

// Writes an 8-bit RGB image (top row first) as PNG; throws std::runtime_error naming the file.
void writePng(const std::string& path, const std::vector<std::uint8_t>& rgb, int width, int height);

// Reads an 8-bit RGB or RGBA PNG into RGB (for tests and checks); throws std::runtime_error.
std::vector<std::uint8_t> readPng(const std::string& path, int* width, int* height);

class VideoWriter {
 public:
  // Starts `ffmpeg` (the program: $SALTUS_FFMPEG when set, else ffmpeg from PATH) encoding
  // width × height RGB frames at fps into an H.264 MP4 (yuv420p, so width and height must be
  // even). Throws std::runtime_error when the size is odd or ffmpeg cannot be started. Sets
  // SIGPIPE to be ignored (for the process) so that an ffmpeg that died fails a write instead.
  VideoWriter(const std::string& path, int width, int height, double fps);
  ~VideoWriter();  // stops ffmpeg and removes the temporary file unless finished
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Throws std::runtime_error (with the tail of ffmpeg's messages) when ffmpeg stopped reading.
  void addFrame(const std::vector<std::uint8_t>& rgb);
  // Waits for ffmpeg and renames the video into place; throws std::runtime_error with the tail
  // of ffmpeg's messages when it failed.
  void finish();

 private:
  std::string failure(const std::string& what) const;
  int close();
  std::string path_;
  scene::AtomicFile video_;   // written by ffmpeg
  scene::ScopedTemporary log_;  // ffmpeg's messages
  std::string program_;
  int width_, height_;
  pid_t pid_ = -1;  // ffmpeg, in a process group of its own (scene::spawnChild)
  std::FILE* pipe_ = nullptr;
};

}  // namespace saltus::render
