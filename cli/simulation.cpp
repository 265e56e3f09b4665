#include "cli/simulation.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <stdexcept>

#include "cli/common.hpp"
#include "scene/scenario.hpp"

extern char** environ;

namespace saltus::cli {

timestepper::LcpMethod parseSolverOption(const std::string& value) {
  if (value == "lemke") return timestepper::LcpMethod::Lemke;
  if (value == "pgs") return timestepper::LcpMethod::Pgs;
  throw UsageError("--solver: expected lemke or pgs, got '" + value + "'");
}

const char* solverName(timestepper::LcpMethod method) {
  return method == timestepper::LcpMethod::Lemke ? "lemke" : "pgs";
}

void checkStepOptions(const std::string& dt_option, double dt, double theta) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw UsageError(dt_option + ": expected a positive time step [s], got " + formatNumber(dt));
  if (!(theta >= 0.5 && theta <= 1))
    throw UsageError("--theta: expected a number in [0.5, 1] (0.5: Moreau midpoint, 1: Stewart-Trinkle), got " +
                     formatNumber(theta));
}

std::map<std::string, double> parseSetOptions(const std::vector<std::string>& assignments) {
  try {
    return scene::parseOverrides(assignments);
  } catch (const scene::ScenarioError& e) {
    throw UsageError(e.what());  // the message starts with "--set '<item>'"
  }
}

std::vector<double> parseNumberList(const std::string& option, const std::string& text, bool positive) {
  std::vector<double> values;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    std::string token = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto b = token.find_first_not_of(" \t"), e = token.find_last_not_of(" \t");
    token = b == std::string::npos ? "" : token.substr(b, e - b + 1);
    double x = 0;
    const char* first = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(first, token.data() + token.size(), x);
    if (token.empty() || ec != std::errc() || end != token.data() + token.size() || !std::isfinite(x))
      throw UsageError(option + ": '" + token + "' is not a number (expected a comma-separated list, e.g. " + option +
                       " 1e-2,5e-3)");
    if (positive ? !(x > 0) : x < 0)
      throw UsageError(option + ": '" + token + "' must be " + (positive ? "positive" : "non-negative"));
    values.push_back(x);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return values;
}

bool hasMovingSurfaceOrInput(const timestepper::Scene& scene) {
  for (const timestepper::Surface& s : scene.surfaces)
    for (const auto& step : s.velocity_schedule)
      if (step.velocity.squaredNorm() > 0) return true;
  return scene.tau.size() > 0 && scene.tau.cwiseAbs().maxCoeff() > 0;
}

long stepCount(double duration, double dt) {
  const double r = duration / dt;
  const double nearest = std::round(r);
  const long n = std::abs(r - nearest) <= 1e-9 * std::max(1.0, r) ? static_cast<long>(nearest)
                                                                   : static_cast<long>(std::ceil(r));
  return std::max(1L, n);
}

double cpuSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<std::string> chartScriptCommand(const std::string& kind, const std::string& csv, const std::string& png,
                                            const std::string& svg) {
  const std::string script = scene::dataDirectory() + "/scripts/charts.py";
  std::string python = "python3";
  if (const char* env = std::getenv("SALTUS_PYTHON"); env && *env)
    python = env;
  else if (::access("/usr/bin/python3", X_OK) == 0)
    python = "/usr/bin/python3";
  return {python, script, kind, csv, "--png", png, "--svg", svg};
}

std::vector<std::string> chartEnvironment() {
  std::vector<std::string> env;
  for (char** e = environ; e && *e; ++e)
    if (std::strncmp(*e, "MPLBACKEND=", 11) != 0) env.emplace_back(*e);
  env.emplace_back("MPLBACKEND=Agg");
  return env;
}

void runChartScript(const std::string& kind, const std::string& csv, const std::string& png, const std::string& svg) {
  std::vector<std::string> args = chartScriptCommand(kind, csv, png, svg);
  const std::string python = args[0], script = args[1];
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = chartEnvironment();
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);  // stdout stays ours
  std::fflush(nullptr);
  pid_t pid = 0;
  const int rc = python.find('/') == std::string::npos
                     ? ::posix_spawnp(&pid, python.c_str(), &actions, nullptr, argv.data(), envp.data())
                     : ::posix_spawn(&pid, python.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw std::runtime_error("chart step failed: cannot start " + python + " (" + std::strerror(rc) +
                             "); install python3-matplotlib or set SALTUS_PYTHON");
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("chart step failed: waitpid: " + std::string(std::strerror(errno)));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                              : "was killed by signal " + std::to_string(WTERMSIG(status));
    throw std::runtime_error("chart step failed: " + python + " " + script + " " + kind + " " + how);
  }
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' || c == '\r' ? ' ' : c);
  return q + "\"";
}

std::string formatNumber(double x, int digits) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return std::string(buf) == "-0" ? "0" : buf;
}

}  // namespace saltus::cli
