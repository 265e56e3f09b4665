#include "sweep/slurm.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene/atomic_file.hpp"
#include "sweep/runner.hpp"

extern char** environ;

namespace saltus::sweep::slurm {

namespace fs = std::filesystem;

namespace {

std::string readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A temporary file removed when the object goes.
struct TempFile {
  std::string path;
  int fd = -1;
  TempFile() {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/saltus-slurm-XXXXXX";
    fd = ::mkstemp(pattern.data());
    if (fd < 0) throw std::runtime_error("cannot create a temporary file (" + std::string(std::strerror(errno)) + ")");
    path = pattern;
  }
  ~TempFile() {
    ::close(fd);
    ::unlink(path.c_str());
  }
};

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!trim(line).empty()) out.push_back(trim(line));
  return out;
}

// "a, b" for a list of ids.
std::string joined(const std::vector<std::string>& items, const std::string& separator = ",") {
  std::string s;
  for (const std::string& item : items) s += (s.empty() ? "" : separator) + item;
  return s;
}

// A path or value that cannot go on an #SBATCH line as it is.
void checkSbatchValue(const std::string& what, const std::string& value) {
  if (value.find_first_of(" \t\n\"'%") != std::string::npos)
    throw std::invalid_argument(what + " " + value +
                                ": contains white space, a quote or '%', which an #SBATCH line cannot carry; use a "
                                "folder without them");
}

std::string nowIso() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::localtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

}  // namespace

ProgramResult runProgram(const std::vector<std::string>& argv) {
  TempFile out, err;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, out.fd, STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, err.fd, STDERR_FILENO);
  std::vector<std::string> storage = argv;
  std::vector<char*> args;
  for (std::string& a : storage) args.push_back(a.data());
  args.push_back(nullptr);
  pid_t pid = -1;
  const int e = ::posix_spawnp(&pid, storage.at(0).c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ProgramResult r;
  if (e != 0) {
    r.err = argv.at(0) + ": cannot start (" + std::strerror(e) + ")";
    return r;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = readWhole(out.path);
  r.err = readWhole(err.path);
  return r;
}

ArrayPlan planArray(int solves, int max_array_size, int solves_per_task) {
  ArrayPlan p;
  p.solves = solves;
  const int limit = std::max(1, max_array_size);
  if (solves_per_task > 0) {
    p.solves_per_task = solves_per_task;
  } else {
    p.solves_per_task = std::max(1, (solves + limit - 1) / limit);
  }
  p.tasks = solves == 0 ? 0 : (solves + p.solves_per_task - 1) / p.solves_per_task;
  if (p.tasks > limit)
    throw std::invalid_argument("--solves-per-task " + std::to_string(solves_per_task) + ": " + std::to_string(solves) +
                                " solves would need " + std::to_string(p.tasks) + " array tasks, more than the cluster's "
                                "MaxArraySize (" + std::to_string(limit) + "); expected at least " +
                                std::to_string((solves + limit - 1) / limit));
  return p;
}

int maxArraySize() {
  const ProgramResult r = runProgram({"scontrol", "show", "config"});
  if (r.status != 0) return 1001;
  static const std::regex line(R"(^\s*MaxArraySize\s*=\s*(\d+))");
  for (const std::string& l : lines(r.out)) {
    std::smatch m;
    if (std::regex_search(l, m, line)) return std::max(1, std::stoi(m[1]));
  }
  return 1001;
}

std::string sbatchScript(const ScriptInputs& in) {
  checkSbatchValue("--out", in.out_absolute);
  checkSbatchValue("the working directory", in.working_directory);
  const int last = in.plan.tasks - 1;
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# A Saltus sweep as one Slurm job array, written by\n#   " << in.submitted_by << "\n"
    << "# from " << in.working_directory << ".\n#\n"
    << "# " << in.plan.solves << " solves without a record, " << in.plan.solves_per_task << " per task: task i runs the "
    << "solves on lines i*" << in.plan.solves_per_task << "+1 to (i+1)*" << in.plan.solves_per_task << " of\n#   "
    << in.cases_file << "\n"
    << "# one after another, each as `saltus optimize` followed by its replay check, and writes\n"
    << "# " << in.out << "/runs/<id>/record.json when a solve ends. A task that Slurm stops (time limit, memory,\n"
    << "# node failure, preemption, scancel) leaves no record for the solve it was running: submitting the\n"
    << "# sweep again (the same saltus sweep command) runs the solves without a record, and\n"
    << "#   saltus sweep status " << in.out << "\n"
    << "# shows where the sweep is. Edit the #SBATCH lines for your cluster (account, QOS, modules) and\n"
    << "# submit it with sbatch; every node must see the saltus program and the sweep folder.\n"
    << "#SBATCH --job-name=" << in.job_name << "\n"
    << "#SBATCH --array=0-" << last;
  if (in.options.max_parallel > 0) s << "%" << in.options.max_parallel;
  s << "\n"
    << "#SBATCH --chdir=" << in.working_directory << "\n"
    << "#SBATCH --output=" << in.out_absolute << "/slurm/logs/%A_%a.log\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=1\n";
  if (!in.options.partition.empty()) s << "#SBATCH --partition=" << in.options.partition << "\n";
  if (!in.options.time.empty()) s << "#SBATCH --time=" << in.options.time << "\n";
  if (!in.options.mem.empty()) s << "#SBATCH --mem=" << in.options.mem << "\n";
  for (const std::string& a : in.options.sbatch_args) {
    if (a.find('\n') != std::string::npos) throw std::invalid_argument("--sbatch-arg: a line break cannot go on an #SBATCH line");
    s << "#SBATCH " << a << "\n";
  }
  s << "\n# One thread per solve: Slurm gave this task one core.\n"
    << "export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1\n"
    << "exec " << shellCommand({in.saltus, "sweep", "task", in.spec, "--out", in.out, "--cases", in.cases_file,
                                 "--solves-per-task", std::to_string(in.plan.solves_per_task), "--index"})
    << " \"$SLURM_ARRAY_TASK_ID\"\n";
  return s.str();
}

std::string submit(const std::string& script_path) {
  const ProgramResult r = runProgram({"sbatch", "--parsable", script_path});
  if (r.status != 0) {
    std::string message = trim(r.err.empty() ? r.out : r.err);
    if (r.status < 0) throw SlurmError(message + "; is Slurm installed (sbatch in PATH)?");
    throw SlurmError("sbatch refused the job array: " + message);
  }
  // --parsable prints "jobid" or "jobid;cluster".
  const std::string out = trim(r.out);
  const std::string id = out.substr(0, out.find(';'));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw SlurmError("sbatch: expected a job id, got '" + out + "'");
  return id;
}

namespace {

// Expands Slurm's array task list "3", "2-5", "1,4-6%2" into indices.
std::vector<int> expandTaskIds(std::string text) {
  std::vector<int> ids;
  text = text.substr(0, text.find('%'));
  if (!text.empty() && text.front() == '[') text = text.substr(1, text.find(']') - 1);
  std::istringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    if (part.empty() || part.find_first_not_of("0123456789-") != std::string::npos) continue;
    const std::size_t dash = part.find('-');
    const int from = std::stoi(part.substr(0, dash));
    const int to = dash == std::string::npos ? from : std::stoi(part.substr(dash + 1));
    for (int i = from; i <= to; ++i) ids.push_back(i);
  }
  return ids;
}

// States of finished tasks from sacct: "123_4|TIMEOUT"; nullopt-like false when sacct cannot answer.
bool fromSacct(const std::vector<std::string>& job_ids, std::map<std::pair<std::string, int>, TaskState>& tasks) {
  const ProgramResult r = runProgram({"sacct", "-n", "-P", "-X", "-j", joined(job_ids), "-o", "JobID,State"});
  if (r.status != 0) return false;
  for (const std::string& l : lines(r.out)) {
    const std::size_t bar = l.find('|'), underscore = l.find('_');
    if (bar == std::string::npos || underscore == std::string::npos || underscore > bar) continue;
    const std::string job = l.substr(0, underscore);
    std::string state = l.substr(bar + 1);
    state = state.substr(0, state.find(' '));  // "CANCELLED by 0"
    for (int task : expandTaskIds(l.substr(underscore + 1, bar - underscore - 1)))
      tasks.emplace(std::make_pair(job, task), TaskState{job, task, state, ""});
  }
  return true;
}

// States from `scontrol -o show job ID`: one line per task, JobState=... ArrayJobId=... ArrayTaskId=...
bool fromScontrol(const std::vector<std::string>& job_ids, std::map<std::pair<std::string, int>, TaskState>& tasks) {
  static const std::regex array_job(R"(\bArrayJobId=(\d+))"), array_task(R"(\bArrayTaskId=(\S+))"),
      state(R"(\bJobState=(\S+))");
  bool answered = false;
  for (const std::string& id : job_ids) {
    const ProgramResult r = runProgram({"scontrol", "-o", "show", "job", id});
    if (r.status != 0) continue;
    answered = true;
    for (const std::string& l : lines(r.out)) {
      std::smatch job, task, st;
      if (!std::regex_search(l, job, array_job) || !std::regex_search(l, task, array_task) ||
          !std::regex_search(l, st, state))
        continue;
      for (int t : expandTaskIds(task[1])) tasks.emplace(std::make_pair(job[1].str(), t), TaskState{job[1], t, st[1], ""});
    }
  }
  return answered;
}

}  // namespace

std::vector<TaskState> queryTasks(const std::vector<std::string>& job_ids, std::string* source) {
  std::map<std::pair<std::string, int>, TaskState> tasks;
  if (source) source->clear();
  if (job_ids.empty()) return {};
  // Live tasks first (squeue -r lists every pending task on its own line). One job at a time:
  // squeue refuses a whole list when one id in it is no longer known.
  for (const std::string& id : job_ids) {
    const ProgramResult q = runProgram({"squeue", "-h", "-r", "-j", id, "-o", "%F|%K|%T|%r"});
    if (q.status != 0) continue;
    for (const std::string& l : lines(q.out)) {
      std::istringstream in(l);
      std::string job, task, state, reason;
      std::getline(in, job, '|');
      std::getline(in, task, '|');
      std::getline(in, state, '|');
      std::getline(in, reason);
      for (int t : expandTaskIds(task)) tasks[{job, t}] = TaskState{job, t, state, reason == "None" ? "" : reason};
    }
  }
  if (fromSacct(job_ids, tasks)) {
    if (source) *source = "sacct";
  } else if (fromScontrol(job_ids, tasks)) {
    if (source) *source = "scontrol";
  }
  std::vector<TaskState> out;
  for (auto& [key, t] : tasks) out.push_back(t);
  return out;
}

std::string stateGroup(const std::string& state) {
  static const std::map<std::string, std::string> groups = {
      {"PENDING", "pending"},         {"CONFIGURING", "pending"},     {"REQUEUED", "pending"},
      {"RESV_DEL_HOLD", "pending"},   {"REQUEUE_HOLD", "pending"},    {"REQUEUE_FED", "pending"},
      {"SUSPENDED", "pending"},       {"RUNNING", "running"},         {"COMPLETING", "running"},
      {"SIGNALING", "running"},       {"STAGE_OUT", "running"},       {"RESIZING", "running"},
      {"COMPLETED", "completed"},     {"FAILED", "failed"},           {"BOOT_FAIL", "failed"},
      {"DEADLINE", "timed out"},      {"TIMEOUT", "timed out"},       {"CANCELLED", "cancelled"},
      {"REVOKED", "cancelled"},       {"OUT_OF_MEMORY", "out of memory"}, {"NODE_FAIL", "node failure"},
      {"PREEMPTED", "preempted"},     {"SPECIAL_EXIT", "failed"},
  };
  const auto it = groups.find(state);
  return it == groups.end() ? state : it->second;
}

bool isActive(const std::string& state) {
  const std::string g = stateGroup(state);
  return g == "pending" || g == "running";
}

// ---- the sweep folder ----

std::string SweepFolder::specPath() const {
  const fs::path p(spec);
  return (p.is_absolute() ? p : fs::path(working_directory) / p).lexically_normal().string();
}

void writeSweepFolder(const std::string& out, const SweepFolder& folder) {
  const nlohmann::json j = {{"spec", folder.spec}, {"out", folder.out}, {"working_directory", folder.working_directory}};
  scene::writeFileAtomically((fs::path(out) / "sweep.json").string(), j.dump(2) + "\n");
}

SweepFolder readSweepFolder(const std::string& out) {
  const fs::path path = fs::path(out) / "sweep.json";
  if (!fs::exists(path))
    throw std::runtime_error(out + ": not a sweep folder (no sweep.json; saltus sweep SPEC --out " + out + " makes one)");
  try {
    std::ifstream in(path);
    const nlohmann::json j = nlohmann::json::parse(in);
    return {j.at("spec").get<std::string>(), j.at("out").get<std::string>(), j.at("working_directory").get<std::string>()};
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

std::vector<Submission> readSubmissions(const std::string& out) {
  const fs::path path = fs::path(out) / "slurm" / "jobs.json";
  std::vector<Submission> subs;
  if (!fs::exists(path)) return subs;
  try {
    std::ifstream in(path);
    const nlohmann::json file = nlohmann::json::parse(in);  // kept alive: the loop walks into it
    for (const nlohmann::json& j : file.at("submissions")) {
      Submission s;
      s.job_id = j.at("job_id").get<std::string>();
      s.cases_file = j.at("cases_file").get<std::string>();
      s.plan.solves = j.at("solves").get<int>();
      s.plan.tasks = j.at("tasks").get<int>();
      s.plan.solves_per_task = j.at("solves_per_task").get<int>();
      s.submitted = j.at("submitted").get<std::string>();
      subs.push_back(s);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
  return subs;
}

void addSubmission(const std::string& out, const Submission& submission) {
  std::vector<Submission> subs = readSubmissions(out);
  Submission s = submission;
  if (s.submitted.empty()) s.submitted = nowIso();
  subs.push_back(s);
  nlohmann::json list = nlohmann::json::array();
  for (const Submission& x : subs)
    list.push_back({{"job_id", x.job_id},
                    {"cases_file", x.cases_file},
                    {"solves", x.plan.solves},
                    {"tasks", x.plan.tasks},
                    {"solves_per_task", x.plan.solves_per_task},
                    {"submitted", x.submitted}});
  scene::writeFileAtomically((fs::path(out) / "slurm" / "jobs.json").string(),
                             nlohmann::json{{"submissions", list}}.dump(2) + "\n");
}

std::string nextCasesFile(const std::string& out) {
  const fs::path folder = fs::absolute(fs::path(out) / "slurm").lexically_normal();
  int k = 1;
  while (fs::exists(folder / ("cases-" + std::to_string(k) + ".txt"))) ++k;
  return (folder / ("cases-" + std::to_string(k) + ".txt")).string();
}

std::vector<SweepCase> taskCases(const std::vector<SweepCase>& cases, const std::string& cases_file,
                                 int solves_per_task, int index) {
  std::ifstream in(cases_file);
  if (!in) throw std::runtime_error(cases_file + ": cannot read the task's list of solves");
  if (solves_per_task < 1 || index < 0)
    throw std::invalid_argument("--solves-per-task and --index: expected a positive batch and an index of 0 or more");
  std::map<std::string, const SweepCase*> by_id;
  for (const SweepCase& c : cases) by_id[c.id] = &c;
  std::vector<SweepCase> mine;
  std::string line;
  const long first = static_cast<long>(index) * solves_per_task, end = first + solves_per_task;
  for (long n = 0; std::getline(in, line); ++n) {
    if (n < first || n >= end) continue;
    line = trim(line);
    const auto it = by_id.find(line);
    if (it == by_id.end())
      throw std::runtime_error(cases_file + ":" + std::to_string(n + 1) + ": solve '" + line +
                               "' is not in the sweep's grid (was the spec changed after submitting?)");
    mine.push_back(*it->second);
  }
  return mine;
}

std::string casesFileText(const std::vector<const SweepCase*>& cases) {
  std::string text;
  for (const SweepCase* c : cases) text += c->id + "\n";
  return text;
}

void refuseWhileActive(const std::string& out) {
  std::vector<std::string> ids;
  for (const Submission& s : readSubmissions(out)) ids.push_back(s.job_id);
  if (ids.empty()) return;
  std::map<std::string, int> active;
  for (const TaskState& t : queryTasks(ids))
    if (isActive(t.state)) ++active[t.job_id];
  if (active.empty()) return;
  std::string list;
  for (const auto& [job, n] : active) list += (list.empty() ? "" : ", ") + std::string("job ") + job + " (" + std::to_string(n) + " tasks)";
  throw SlurmError(out + ": this sweep still has Slurm tasks pending or running: " + list +
                   "; wait for them (saltus sweep status " + out + ") or cancel them with scancel");
}

}  // namespace saltus::sweep::slurm
