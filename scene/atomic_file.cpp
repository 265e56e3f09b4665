#include "scene/atomic_file.hpp"

#include "scene/cleanup.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace saltus::scene {

AtomicFile::AtomicFile(std::string path, Mode mode, const std::string& suffix)
    : path_(std::move(path)), tmp_path_(temporaryName(path_, suffix)) {
  std::error_code ec;
  const auto status = std::filesystem::symlink_status(path_, ec);
  if (mode == Mode::Stream && writtenInPlace(path_)) {
    // /dev/null, /dev/stdout, a pipe: written into, never replaced (nothing to make atomic)
    file_ = std::fopen(path_.c_str(), "wb");
    if (!file_) throw std::runtime_error(path_ + ": cannot write (" + std::strerror(errno) + ")");
    direct_ = true;
    return;
  }
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw std::runtime_error(path_ + ": exists and is not a regular file (" +
                             (std::filesystem::is_directory(status) ? "a folder" : std::filesystem::is_symlink(status) ? "a symlink" : "a special file") +
                             "); refusing to replace it");
  removeStaleTemporaries(std::filesystem::path(path_).parent_path().string());
  registerTemporary(tmp_path_);
  if (mode == Mode::External) return;
  file_ = std::fopen(tmp_path_.c_str(), "wb");
  if (!file_) {
    const int err = errno;
    forgetTemporary(tmp_path_);
    throw std::runtime_error(path_ + ": cannot write (" + std::strerror(err) + ")");
  }
}

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!committed_ && !direct_) {
    std::remove(tmp_path_.c_str());
    forgetTemporary(tmp_path_);
  }
}

void AtomicFile::commit() {
  if (committed_) return;
  if (file_) {
    // Flushed to the disk before the rename: after a crash the target is the old file or the
    // whole new one, never an empty or cut one.
    const bool write_ok = std::ferror(file_) == 0 && std::fflush(file_) == 0 && (direct_ || ::fsync(::fileno(file_)) == 0);
    const int err = errno;
    const bool close_ok = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!write_ok || !close_ok)
      throw std::runtime_error(path_ + ": writing failed (" + std::strerror(write_ok ? errno : err) + ")");
  }
  if (direct_) {
    committed_ = true;
    return;
  }
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error(path_ + ": cannot rename the finished file into place (" + std::strerror(errno) + ")");
  committed_ = true;
  forgetTemporary(tmp_path_);
}

bool writtenInPlace(const std::string& path) {
  std::error_code ec;
  const auto target = std::filesystem::status(path, ec);  // through a symlink
  if (!std::filesystem::exists(target)) return false;
  // /dev/stdout and /dev/fd/N lead through /proc/self/fd to whatever the descriptor is
  const bool descriptor = path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0;
  return std::filesystem::is_character_file(target) || std::filesystem::is_fifo(target) || descriptor;
}

void writeFileAtomically(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  if (std::fwrite(text.data(), 1, text.size(), file.stream()) != text.size())
    throw std::runtime_error(path + ": writing failed (" + std::strerror(errno) + ")");
  file.commit();
}

}  // namespace saltus::scene
