#include "sweep/runner.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "collocation/saved_solution.hpp"
#include "scene/atomic_file.hpp"
#include "verify/replay.hpp"

extern char** environ;

namespace saltus::sweep {

namespace fs = std::filesystem;

namespace {

volatile sig_atomic_t g_interrupted = 0;
void onSignal(int signal) { g_interrupted = signal; }

// Installs SIGINT/SIGTERM handlers without SA_RESTART (so waitpid returns on a signal) and
// restores the previous ones on destruction.
class SignalGuard {
 public:
  SignalGuard() {
    g_interrupted = 0;
    struct sigaction sa {};
    sa.sa_handler = onSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~SignalGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

std::string lastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

// Starts `saltus ARGS` with standard output to /dev/null and standard error to `log`.
pid_t spawn(const std::string& saltus, const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> argv_storage = {saltus};
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  // One thread per solve: the sweep runs `jobs` of them at once.
  std::vector<std::string> env_storage = {"OMP_NUM_THREADS=1", "OPENBLAS_NUM_THREADS=1"};
  for (char** e = environ; *e; ++e) {
    const std::string var = *e;
    if (var.rfind("OMP_NUM_THREADS=", 0) != 0 && var.rfind("OPENBLAS_NUM_THREADS=", 0) != 0) env_storage.push_back(var);
  }
  std::vector<char*> envp;
  for (std::string& e : env_storage) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = -1;
  const int err = posix_spawn(&pid, saltus.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) throw std::runtime_error(saltus + ": cannot start (" + std::strerror(err) + ")");
  return pid;
}

void replayCheck(SweepRecord& r, const std::string& solution_dir, const ReplayCheck& check) {
  try {
    const collocation::SavedSolution solution = collocation::loadSolution(solution_dir);
    verify::ReplayOptions o;
    o.engines = {verify::EngineKind::Saltus};
    o.dt = check.dt;
    o.tolerance = check.tolerance;
    o.restart = check.restart;
    o.max_series = 2;  // only the figures are kept
    const verify::ReplayResult result = verify::replay(solution, o);
    const verify::EngineReplay& e = result.engines.at(0);
    r.replay_deviation = e.max_position_deviation;
    r.physical = e.completed && e.within_tolerance;
    if (!e.completed) r.replay_message = e.message;
  } catch (const std::exception& e) {
    r.physical = false;
    r.replay_message = e.what();
  }
}

}  // namespace

DirectoryLock::DirectoryLock(const std::string& dir) {
  const std::string path = (fs::path(dir) / ".lock").string();
  fd_ = ::open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error(path + ": cannot open (" + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    throw std::runtime_error(dir + ": another saltus sweep is running in this folder");
  }
}

DirectoryLock::~DirectoryLock() { ::close(fd_); }

std::string shellCommand(const std::vector<std::string>& arguments) {
  std::string s;
  for (const std::string& a : arguments) {
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                          "0123456789_-.,/=+:@%") == std::string::npos;
    if (!s.empty()) s += ' ';
    if (plain) {
      s += a;
    } else {
      s += '\'';
      for (char ch : a) s += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
      s += '\'';
    }
  }
  return s;
}

std::string caseDirectory(const std::string& out, const SweepCase& c) {
  return (fs::path(out) / "runs" / c.id).string();
}

std::vector<SweepRecord> readRecords(const std::string& out, const std::vector<SweepCase>& cases) {
  std::vector<SweepRecord> records;
  for (const SweepCase& c : cases) {
    const fs::path path = fs::path(caseDirectory(out, c)) / "record.json";
    if (!fs::exists(path)) continue;
    std::ifstream in(path);
    try {
      records.push_back(recordFromJson(nlohmann::json::parse(in)));
      records.back().physical_required = c.physical_required;  // the spec in force decides
    } catch (const std::exception& e) {
      throw std::runtime_error(path.string() + ": " + e.what());
    }
  }
  return records;
}

std::string optimizeCommand(const SweepCase& c, const std::string& case_dir) {
  std::vector<std::string> shown = {"saltus"};
  const std::vector<std::string> args = c.optimizeArguments((fs::path(case_dir) / "solution").string());
  shown.insert(shown.end(), args.begin(), args.end());
  return shellCommand(shown);
}

std::vector<std::string> recordsOfAnotherCommand(const std::string& out, const std::vector<SweepCase>& cases) {
  // optimizeArguments ends with --out and the solution's folder
  const auto withoutOut = [](const std::string& command) { return command.substr(0, command.rfind(" --out ")); };
  std::vector<std::string> lines;
  const std::vector<SweepRecord> records = readRecords(out, cases);
  std::map<std::string, const SweepCase*> by_id;
  for (const SweepCase& c : cases) by_id[c.id] = &c;
  for (const SweepRecord& r : records) {
    const auto it = by_id.find(r.id);
    if (it == by_id.end()) continue;
    const std::string now = optimizeCommand(*it->second, caseDirectory(out, *it->second));
    if (withoutOut(r.command) != withoutOut(now))
      lines.push_back(r.id + ": made by `" + r.command + "`, the spec now runs `" + now + "`");
  }
  return lines;
}

SweepRecord makeRecord(const SweepCase& c, const std::string& case_dir, int exit_code, const std::string& command,
                       const ReplayCheck& check) {
  SweepRecord r;
  r.id = c.id;
  r.problem = c.problem;
  r.problem_name = c.problem_name;
  r.method = c.method;
  r.set = c.set;
  r.variant = c.variant;
  r.seed = c.seed;
  r.physical_required = c.physical_required;
  r.command = command;
  r.exit_code = exit_code;
  const fs::path solution = fs::path(case_dir) / "solution";
  const fs::path summary = solution / "summary.json";
  if (!fs::exists(summary)) {
    r.status = "error";
    r.error = lastLine((fs::path(case_dir) / "optimize.log").string());
    if (r.error.empty()) r.error = "saltus optimize ended with status " + std::to_string(exit_code) + " and no message";
    return r;
  }
  try {
    std::ifstream in(summary);
    const nlohmann::json j = nlohmann::json::parse(in);
    // The kept stage's status (a summary of an earlier version has none: its last stage's).
    r.status = j.contains("status") ? j.at("status").get<std::string>()
                                    : j.at("stages").back().at("status").get<std::string>();
    r.feasible = j.at("feasible").get<bool>();
    r.converged = j.value("converged", r.feasible);
    r.iterations = j.at("iterations").get<int>();
    r.wall_seconds = j.at("wall_seconds").get<double>();
    r.evaluation_seconds = j.at("evaluation_seconds").get<double>();
    r.largest_product = j.at("largest_product").get<double>();
    r.mean_local_error = j.at("mean_local_error").get<double>();
    r.objective = j.at("objective").get<double>();
    r.variables = j.at("variables").get<int>();
    r.constraints = j.at("constraints").get<int>();
    r.attempts = static_cast<int>(j.at("attempts").size());
  } catch (const std::exception& e) {
    r.status = "error";
    r.error = summary.string() + ": " + e.what();
    return r;
  }
  if (check.enabled && r.feasible) replayCheck(r, solution.string(), check);
  return r;
}

std::vector<const SweepCase*> startOrder(const std::vector<SweepCase>& cases) {
  std::vector<const SweepCase*> order;
  order.reserve(cases.size());
  for (const SweepCase& c : cases) order.push_back(&c);
  std::stable_sort(order.begin(), order.end(), [](const SweepCase* a, const SweepCase* b) { return a->seed < b->seed; });
  return order;
}

RunResult runSweep(const SweepSpec& spec, const std::vector<SweepCase>& cases, const std::string& out,
                   const RunnerOptions& options, const std::function<void(const Progress&)>& progress) {
  fs::create_directories(fs::path(out) / "runs");
  std::optional<DirectoryLock> lock;
  if (options.lock) lock.emplace(out);
  RunResult result;
  std::vector<const SweepCase*> pending;
  Progress p;
  p.total = static_cast<int>(cases.size());
  for (const SweepCase* c : startOrder(cases)) {
    if (fs::exists(fs::path(caseDirectory(out, *c)) / "record.json"))
      ++p.skipped;
    else
      pending.push_back(c);
  }
  p.done = p.skipped;
  for (const SweepRecord& r : readRecords(out, cases)) p.failed += !r.success();

  SignalGuard signals;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  struct Running {
    const SweepCase* c;
    std::string dir, command;
  };
  std::map<pid_t, Running> running;
  // Stops the solves still running (on an interrupt, or an error leaving this function).
  auto stopAll = [&] {
    for (const auto& [pid, job] : running) ::kill(pid, SIGTERM);
    for (const auto& [pid, job] : running) {
      int status = 0;
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    running.clear();
  };
  std::size_t next = 0;
  const int jobs = std::max(1, options.jobs);
  try {
    if (progress) progress(p);
    while ((next < pending.size() || !running.empty()) && !g_interrupted) {
      while (next < pending.size() && static_cast<int>(running.size()) < jobs && !g_interrupted) {
        const SweepCase& c = *pending[next++];
        const std::string dir = caseDirectory(out, c);
        fs::remove_all(dir);  // what a killed run left
        fs::create_directories(dir);
        const std::vector<std::string> args = c.optimizeArguments((fs::path(dir) / "solution").string());
        const pid_t pid = spawn(options.saltus, args, (fs::path(dir) / "optimize.log").string());
        running[pid] = {&c, dir, optimizeCommand(c, dir)};
      }
      // Polled, so that a signal arriving between the check above and a blocking wait is seen
      // within 50 ms rather than when the next solve ends.
      int status = 0;
      const pid_t pid = ::waitpid(-1, &status, WNOHANG);
      if (pid == 0) {
        ::usleep(50000);
        continue;
      }
      if (pid < 0) {
        if (errno == EINTR) continue;
        break;
      }
      const auto it = running.find(pid);
      if (it == running.end()) continue;
      const Running job = it->second;
      running.erase(it);
      if (WIFSIGNALED(status) && g_interrupted) break;  // killed with us: no record
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      if (options.stopped_solve_leaves_no_record &&
          (WIFSIGNALED(status) || code == 128 + SIGINT || code == 128 + SIGTERM || code == 128 + SIGKILL)) {
        result.stopped = job.c->id;
        break;
      }
      SweepRecord record = makeRecord(*job.c, job.dir, code, job.command, spec.replay);
      if (WIFSIGNALED(status)) {
        record.status = "error";
        record.error = "saltus optimize was killed by signal " + std::to_string(WTERMSIG(status));
      }
      scene::writeFileAtomically((fs::path(job.dir) / "record.json").string(), toJson(record).dump(2) + "\n");
      ++result.ran;
      ++p.done;
      p.failed += !record.success();
      p.elapsed_seconds = elapsed();
      const int left = p.total - p.done;
      p.eta_seconds = result.ran > 0 ? p.elapsed_seconds / result.ran * left : -1;
      p.last = &record;
      if (progress) progress(p);
      p.last = nullptr;
    }
  } catch (...) {
    stopAll();
    throw;
  }
  if (g_interrupted) {
    result.interrupted = true;
    result.signal = g_interrupted;
  }
  stopAll();  // interrupted, or a solve was stopped from outside: the others go too
  result.records = readRecords(out, cases);
  return result;
}

}  // namespace saltus::sweep
