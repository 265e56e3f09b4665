#include "scene/cleanup.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace saltus::scene {

namespace fs = std::filesystem;

namespace {

// The registry. An interrupt takes the mutex and never gives it back (the process ends), so that
// nothing is registered, created or started after the cleanup looked.
std::mutex& registryMutex() {
  static std::mutex m;
  return m;
}
std::vector<std::string>& temporaries() {
  static std::vector<std::string> v;
  return v;
}
std::vector<pid_t>& children() {
  static std::vector<pid_t> v;
  return v;
}
std::set<pid_t>& killedAtOnce() {  // children whose whole output is a temporary (spawnChild)
  static std::set<pid_t> v;
  return v;
}

std::string hostName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "localhost";
  return name;
}

int g_signal_pipe[2] = {-1, -1};
std::atomic<bool> g_interrupting{false};

void onSignal(int signal) {
  const unsigned char byte = static_cast<unsigned char>(signal);
  [[maybe_unused]] const ssize_t n = ::write(g_signal_pipe[1], &byte, 1);  // async-signal-safe
}

// Stops a child's process group: SIGTERM, then SIGKILL when it has not ended within the grace time.
// Stops the children's process groups: SIGTERM to all at once (a saltus child then removes its own
// temporaries and stops its children; SIGKILL to one started with ChildStop::Kill), SIGKILL to
// what is left after 3 s.
void stopGroups(const std::vector<pid_t>& pids) {
  for (pid_t pid : pids) ::kill(-pid, killedAtOnce().count(pid) ? SIGKILL : SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  std::vector<pid_t> running = pids;
  while (!running.empty()) {
    std::erase_if(running, [](pid_t pid) {
      int status = 0;
      const pid_t r = ::waitpid(pid, &status, WNOHANG);
      return r == pid || (r < 0 && errno == ECHILD);  // ended (or reaped by the main thread)
    });
    if (running.empty() || std::chrono::steady_clock::now() > deadline) break;
    ::usleep(10000);
  }
  for (pid_t pid : running) {
    ::kill(-pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  for (pid_t pid : pids) ::kill(-pid, SIGKILL);  // what the groups' leaders left running
}

std::size_t removeTemporaries() {
  std::size_t removed = 0;
  for (const std::string& path : temporaries()) {
    std::error_code error;
    removed += fs::remove_all(path, error) > 0;
  }
  return removed;
}

[[noreturn]] void cleanUpAndExit(const std::string& program, int signal) {
  g_interrupting = true;
  registryMutex().lock();  // held until _exit
  // The children first, so that none writes into a folder after it was removed; then the
  // temporaries (the children removed their own; one killed after its grace time leaves its
  // own for the next run in that folder: removeStaleTemporaries).
  const std::size_t n_children = children().size();
  stopGroups(children());
  const std::size_t removed = removeTemporaries();
  std::string message = program + ": interrupted by " + (signal == SIGINT ? "SIGINT" : "SIGTERM");
  if (n_children > 0) message += "; stopped " + std::to_string(n_children) + " child process" + (n_children > 1 ? "es" : "");
  if (removed > 0) message += "; removed " + std::to_string(removed) + " unfinished file" + (removed > 1 ? "s" : "");
  message += "\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, message.data(), message.size());
  ::_exit(128 + signal);
}

// "<name>.tmp-<pid>[@<host>][suffix]": the pid and host, or pid 0 when `name` is not a temporary.
pid_t temporaryOwner(const std::string& name, std::string* host) {
  const std::size_t at = name.rfind(".tmp-");
  if (at == std::string::npos || at == 0) return 0;
  std::size_t i = at + 5, digits = 0;
  pid_t pid = 0;
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i])) && digits < 10) {
    pid = pid * 10 + (name[i] - '0');
    ++i, ++digits;
  }
  if (digits == 0) return 0;
  host->clear();
  if (i < name.size() && name[i] == '@') {
    const std::size_t end = name.find_first_of("./", i + 1);  // a suffix starts with '.'
    *host = name.substr(i + 1, end == std::string::npos ? std::string::npos : end - i - 1);
    i = end == std::string::npos ? name.size() : end;
  }
  if (i < name.size() && name[i] != '.') return 0;
  return pid;
}

}  // namespace

std::string temporaryName(const std::string& target, const std::string& suffix) {
  static const std::string tag = ".tmp-" + std::to_string(::getpid()) + "@" + hostName();
  return target + tag + suffix;
}

void registerTemporary(const std::string& path) {
  std::lock_guard<std::mutex> lock(registryMutex());
  temporaries().push_back(path);
}

void forgetTemporary(const std::string& path) {
  std::lock_guard<std::mutex> lock(registryMutex());
  auto& v = temporaries();
  const auto it = std::find(v.begin(), v.end(), path);
  if (it != v.end()) v.erase(it);
}

ScopedTemporary::ScopedTemporary(std::string path) : path_(std::move(path)) { registerTemporary(path_); }

ScopedTemporary::~ScopedTemporary() {
  if (!keep_) {
    std::error_code error;
    fs::remove_all(path_, error);
  }
  forgetTemporary(path_);
}

void ScopedTemporary::keep() { keep_ = true; }

pid_t spawnChild(const std::string& program, const std::vector<std::string>& arguments,
                 const std::vector<std::string>& environment, const posix_spawn_file_actions_t* actions,
                 ChildStop stop) {
  std::vector<std::string> args = arguments, env = environment;
  if (env.empty())
    for (char** e = environ; e && *e; ++e) env.emplace_back(*e);
  // A saltus child stops when this process dies, even by SIGKILL (installInterruptCleanup).
  std::erase_if(env, [](const std::string& e) { return e.rfind("SALTUS_PARENT_PID=", 0) == 0; });
  env.push_back("SALTUS_PARENT_PID=" + std::to_string(::getpid()));
  std::vector<char*> argv, envp;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  char** child_environment = envp.data();

  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults, none;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigaddset(&defaults, SIGPIPE);  // the parent ignores SIGPIPE; its children need not
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setpgroup(&attributes, 0);  // a group of its own: stopped with everything it starts
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);

  std::fflush(nullptr);
  pid_t pid = 0;
  int rc = 0;
  {
    std::lock_guard<std::mutex> lock(registryMutex());  // an interrupt sees the child or none
    rc = program.find('/') == std::string::npos
             ? ::posix_spawnp(&pid, program.c_str(), actions, &attributes, argv.data(), child_environment)
             : ::posix_spawn(&pid, program.c_str(), actions, &attributes, argv.data(), child_environment);
    if (rc == 0) children().push_back(pid);
    if (rc == 0 && stop == ChildStop::Kill) killedAtOnce().insert(pid);
  }
  posix_spawnattr_destroy(&attributes);
  if (rc != 0) throw std::runtime_error("cannot start " + program + " (" + std::strerror(rc) + ")");
  return pid;
}

int waitChild(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno == EINTR) continue;
    status = -1;  // ECHILD: reaped by an interrupt's cleanup, which ends the process
    break;
  }
  std::lock_guard<std::mutex> lock(registryMutex());
  auto& v = children();
  v.erase(std::remove(v.begin(), v.end(), pid), v.end());
  killedAtOnce().erase(pid);
  return status;
}

void installInterruptCleanup(const std::string& program) {
  if (g_signal_pipe[0] >= 0) return;
  // Started by a saltus process (spawnChild): SIGTERM when it dies, however it dies.
  if (const char* parent = std::getenv("SALTUS_PARENT_PID"); parent && *parent) {
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (std::to_string(::getppid()) != parent) ::raise(SIGTERM);  // it died before the line above
  }
  if (::pipe2(g_signal_pipe, O_CLOEXEC) != 0) throw std::runtime_error("cannot create the signal pipe");
  // The work is done by a thread, outside the signal handler, where removing files is safe.
  std::thread([program] {
    unsigned char byte = 0;
    while (::read(g_signal_pipe[0], &byte, 1) != 1) {
    }
    cleanUpAndExit(program, byte);
  }).detach();
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

void yieldToInterrupt() {
  if (g_interrupting) registryMutex().lock();  // blocks: the cleanup ends the process
}

std::vector<std::string> removeStaleTemporaries(const std::string& folder) {
  std::vector<std::string> removed;
  static std::mutex m;
  static std::set<std::string> done;
  {
    std::lock_guard<std::mutex> lock(m);
    if (!done.insert(folder).second) return removed;
  }
  static const std::string here = hostName();
  std::error_code error;
  for (fs::directory_iterator it(folder.empty() ? "." : folder, error), end; !error && it != end; it.increment(error)) {
    std::string host;
    const pid_t pid = temporaryOwner(it->path().filename().string(), &host);
    if (pid <= 0 || pid == ::getpid()) continue;
    if (!host.empty() && host != here) continue;  // another machine's process (a shared file system)
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to ask)
    std::error_code remove_error;
    if (fs::remove_all(it->path(), remove_error) > 0) removed.push_back(it->path().string());
  }
  return removed;
}

}  // namespace saltus::scene
