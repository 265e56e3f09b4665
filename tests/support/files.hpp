// Files in tests: a file's bytes, and a scratch folder under the temporary folder (a test leaves
// nothing behind in it).
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

// A scratch folder that lives as long as the object: created empty, removed with everything in
// it when the object goes (also when the test fails an assertion and returns early).
class ScratchDir {
 public:
  ScratchDir(const std::string& suite, const std::string& name) : path_(scratchPath(suite, name)) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// The bytes of `path` ("" when it cannot be read).
inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace saltus::testing
