// Running the built `saltus` program (SALTUS_BINARY) from a test: standard output through a
// pipe, standard error through a temporary file, no standard input.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace saltus::testing {

struct RunResult {
  int status = -1;  // exit code, −1 when killed by a signal
  std::string out, err;
};

inline std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `[ENV] saltus ARGS...`; ENV is a shell prefix such as "SALTUS_PYTHON=/bin/false".
inline RunResult runSaltus(const std::vector<std::string>& args, const std::string& env = "") {
  const std::filesystem::path err_path =
      std::filesystem::temp_directory_path() / ("saltus_test_" + std::to_string(::getpid()) + ".stderr");
  std::string cmd = env;
  if (!cmd.empty()) cmd += ' ';
  cmd += shellQuote(SALTUS_BINARY);
  // Appended piece by piece: "literal" + std::string&& trips a false -Wrestrict in GCC 12.
  for (const auto& a : args) {
    cmd += ' ';
    cmd += shellQuote(a);
  }
  cmd += " </dev/null 2>";
  cmd += shellQuote(err_path.string());
  RunResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = readFile(err_path);
  std::filesystem::remove(err_path);
  return r;
}

}  // namespace saltus::testing
