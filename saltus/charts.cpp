// saltus::drawChart (saltus/saltus.hpp): the chart script (scripts/charts.py, installed with the
// models) run through python3, its standard output sent to our standard error.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "saltus/saltus.hpp"
#include "scene/cleanup.hpp"
#include "scene/scenario.hpp"

extern char** environ;

namespace saltus {

std::vector<std::string> chartCommand(const std::string& kind, const std::string& csv, const std::string& png,
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

void drawChart(const std::string& kind, const std::string& csv, const std::string& png, const std::string& svg) {
  const std::vector<std::string> args = chartCommand(kind, csv, png, svg);
  const std::string& python = args[0];
  const std::string& script = args[1];
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);  // stdout stays ours
  pid_t pid = 0;
  try {
    pid = scene::spawnChild(python, args, chartEnvironment(), &actions);
  } catch (const std::exception& e) {
    posix_spawn_file_actions_destroy(&actions);
    throw std::runtime_error(std::string("chart step failed: ") + e.what() + "; install python3-matplotlib or set SALTUS_PYTHON");
  }
  posix_spawn_file_actions_destroy(&actions);
  const int status = scene::waitChild(pid);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                              : "was killed by signal " + std::to_string(WTERMSIG(status));
    throw std::runtime_error("chart step failed: " + python + " " + script + " " + kind + " " + how);
  }
}

}  // namespace saltus
