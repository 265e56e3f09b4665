// Files in tests: a file's bytes, and a scratch folder under the temporary folder.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace saltus::testing {

// A path under the temporary folder for one test's output, "saltus_<suite>_<name>_<pid>", removed
// if an earlier run left it (not created).
inline std::filesystem::path scratchPath(const std::string& suite, const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("saltus_" + suite + "_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  return d;
}

// The bytes of `path` ("" when it cannot be read).
inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace saltus::testing
