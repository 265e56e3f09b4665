#include "render/image_io.hpp"

#include <fcntl.h>
#include <png.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace saltus::render {

namespace {

// libpng reports errors through a callback that must not return: throw from it (libpng is C,
// but built with unwinding tables on Debian; the png structs are freed by the caller's guard).
[[noreturn]] void pngError(png_structp, png_const_charp message) { throw std::runtime_error(message); }
void pngWarning(png_structp, png_const_charp) {}

// Whether `program` can be run: an executable path, or found in PATH.
bool findProgram(const std::string& program) {
  if (program.find('/') != std::string::npos) return ::access(program.c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

// The last `lines` lines of a file.
std::string tail(const std::string& path, int lines) {
  std::ifstream in(path);
  std::vector<std::string> kept;
  for (std::string line; std::getline(in, line);) {
    kept.push_back(line);
    if (static_cast<int>(kept.size()) > lines) kept.erase(kept.begin());
  }
  std::string out;
  for (const std::string& line : kept) out += "\n  " + line;
  return out;
}

}  // namespace

void writePng(const std::string& path, const std::vector<std::uint8_t>& rgb, int width, int height) {
  if (rgb.size() != static_cast<std::size_t>(width) * height * 3)
    throw std::runtime_error(path + ": image buffer does not hold " + std::to_string(width) + "x" + std::to_string(height) + " RGB pixels");
  scene::AtomicFile file(path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, pngError, pngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  try {
    if (!info) throw std::runtime_error("out of memory");
    png_init_io(png, file.stream());
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 3);  // frames: speed over size
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) png_write_row(png, rgb.data() + static_cast<std::size_t>(y) * width * 3);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
  } catch (const std::exception& e) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(path + ": cannot write PNG (" + e.what() + ")");
  }
  file.commit();
}

std::vector<std::uint8_t> readPng(const std::string& path, int* width, int* height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str()))
    throw std::runtime_error(path + ": cannot read PNG (" + image.message + ")");
  image.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> rgb(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) {
    png_image_free(&image);
    throw std::runtime_error(path + ": cannot read PNG (" + image.message + ")");
  }
  *width = static_cast<int>(image.width);
  *height = static_cast<int>(image.height);
  return rgb;
}

VideoWriter::VideoWriter(const std::string& path, int width, int height, double fps)
    : path_(path),
      video_(path, scene::AtomicFile::Mode::External, ".mp4"),
      log_(scene::temporaryName(path, ".ffmpeg.log")),
      width_(width),
      height_(height) {
  if (width % 2 != 0 || height % 2 != 0)
    throw std::runtime_error(path + ": H.264 (yuv420p) needs an even width and height, got " + std::to_string(width) +
                             "x" + std::to_string(height));
  const char* env = std::getenv("SALTUS_FFMPEG");
  program_ = env && *env ? env : "ffmpeg";
  if (!findProgram(program_))
    throw std::runtime_error("cannot encode " + path + ": the program '" + program_ +
                             "' was not found (install Debian's ffmpeg package, or set SALTUS_FFMPEG)");
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.10g", fps);
  const std::vector<std::string> arguments = {
      program_, "-nostdin", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s",
      std::to_string(width) + "x" + std::to_string(height), "-framerate", rate, "-i", "-", "-an", "-c:v", "libx264",
      "-preset", "medium", "-crf", "20", "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4",
      video_.temporaryPath()};
  // A pipe whose reader died must fail the write (EPIPE), not kill the process.
  std::signal(SIGPIPE, SIG_IGN);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw std::runtime_error("cannot encode " + path + ": cannot create a pipe (" + std::strerror(errno) + ")");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log_.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  try {
    pid_ = scene::spawnChild(program_, arguments, {}, &actions, scene::ChildStop::Kill);  // its video is a temporary
  } catch (const std::exception& e) {
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error("cannot encode " + path + ": " + e.what());
  }
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  pipe_ = ::fdopen(fds[1], "wb");
}

VideoWriter::~VideoWriter() {
  if (pipe_) std::fclose(pipe_);
  if (pid_ > 0) {
    ::kill(-pid_, SIGTERM);  // not finished: the video is dropped
    scene::waitChild(pid_);
  }
}

// Closes ffmpeg's input and waits for it; its wait status.
int VideoWriter::close() {
  if (pipe_) std::fclose(pipe_);
  pipe_ = nullptr;
  const int status = scene::waitChild(pid_);
  pid_ = -1;
  return status;
}

std::string VideoWriter::failure(const std::string& what) const {
  return "cannot encode " + path_ + ": " + program_ + " " + what + "; its last messages:" + tail(log_.path(), 8);
}

void VideoWriter::addFrame(const std::vector<std::uint8_t>& rgb) {
  if (rgb.size() != static_cast<std::size_t>(width_) * height_ * 3)
    throw std::runtime_error(path_ + ": frame is not " + std::to_string(width_) + "x" + std::to_string(height_) + " RGB");
  if (std::fwrite(rgb.data(), 1, rgb.size(), pipe_) != rgb.size()) {
    close();
    throw std::runtime_error(failure("stopped reading frames"));
  }
}

void VideoWriter::finish() {
  const int status = close();
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error(failure(WIFEXITED(status) ? "failed with exit status " + std::to_string(WEXITSTATUS(status))
                                                       : std::string("was killed")));
  video_.commit();
}

}  // namespace saltus::render
