#include "scene/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace saltus::scene {

void writeFileAtomically(const std::string& path, const std::string& text) {
  std::error_code ec;
  const auto status = std::filesystem::symlink_status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw std::runtime_error(path + ": exists and is not a regular file; refusing to replace it");
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write (" + std::strerror(errno) + ")");
  // Flushed to the disk before the rename: after a crash the target is the old file or the
  // whole new one, never an empty or cut one.
  const bool write_ok = std::fwrite(text.data(), 1, text.size(), f) == text.size() && std::fflush(f) == 0 &&
                        ::fsync(::fileno(f)) == 0;
  const bool close_ok = std::fclose(f) == 0;
  if (!write_ok || !close_ok) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": writing failed (" + std::strerror(errno) + ")");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename the finished file into place (" + std::strerror(err) + ")");
  }
}

}  // namespace saltus::scene
