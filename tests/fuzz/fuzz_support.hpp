// Shared helpers of the libFuzzer targets (tests/fuzz/fuzz_*.cpp): the readers that take a path
// get each input written to a file in a per-process folder /tmp/saltus_fuzz_<target>_<pid>,
// removed when the process exits normally (a crashing run leaves it behind).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "saltus/build_paths.hpp"

namespace saltus::fuzz {

namespace fs = std::filesystem;

// A harness failure (cannot write its own temporary file): loud, not a finding of a reader.
[[noreturn]] inline void harnessError(const std::string& what) {
  std::fprintf(stderr, "fuzz harness: %s\n", what.c_str());
  std::abort();
}

inline fs::path& tempDirSlot() {
  static fs::path dir;
  return dir;
}

inline void removeTempDir() {
  std::error_code ec;
  if (!tempDirSlot().empty()) fs::remove_all(tempDirSlot(), ec);
}

// /tmp/saltus_fuzz_<target>_<pid>, made (empty) on the first call.
inline const fs::path& tempDir(const std::string& target) {
  fs::path& dir = tempDirSlot();
  if (dir.empty()) {
    dir = fs::path("/tmp") / ("saltus_fuzz_" + target + "_" + std::to_string(::getpid()));
    std::error_code ec;
    fs::remove_all(dir, ec);  // left by an earlier process of the same pid
    if (!fs::create_directories(dir, ec)) harnessError("cannot create " + dir.string() + ": " + ec.message());
    std::atexit(removeTempDir);
  }
  return dir;
}

// Writes the input, byte for byte, to `path` (replacing it).
inline void writeFile(const fs::path& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) harnessError("cannot write " + path.string());
  const bool ok = size == 0 || std::fwrite(data, 1, size, f) == size;
  if (std::fclose(f) != 0 || !ok) harnessError("cannot write " + path.string());
}

// A folder laid out like the source tree for YAML files that name URDF models by relative path:
// <dir>/tests/data/<kind>/ holds the input; <dir>/models, <dir>/tests/data/urdf and
// <dir>/tests/data/pendulum are links to the source tree's models/, tests/data/urdf/ and
// models/pendulum/, so the paths used by models/scenes, models/problems and tests/data
// (../pendulum/x.urdf, ../urdf/x.urdf, ../../../models/pendulum/x.urdf) all resolve.
// Returns the input's path, <dir>/tests/data/<kind>/<file_name>.
inline fs::path yamlInputPath(const std::string& target, const std::string& kind, const std::string& file_name) {
  static fs::path path;
  if (path.empty()) {
    const fs::path dir = tempDir(target), source = SALTUS_SOURCE_DIR;
    std::error_code ec;
    fs::create_directories(dir / "tests" / "data" / kind, ec);
    fs::create_directory_symlink(source / "models", dir / "models", ec);
    fs::create_directory_symlink(source / "tests" / "data" / "urdf", dir / "tests" / "data" / "urdf", ec);
    fs::create_directory_symlink(source / "models" / "pendulum", dir / "tests" / "data" / "pendulum", ec);
    path = dir / "tests" / "data" / kind / file_name;
  }
  return path;
}

}  // namespace saltus::fuzz
