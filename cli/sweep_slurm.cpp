// `saltus sweep` on a Slurm cluster (sweep/slurm.hpp):
//   saltus sweep SPEC --out DIR --slurm [...]   submits the solves without a record as one job
//                                               array, prints its job id and returns
//   saltus sweep status DIR [--json]            records, and what Slurm says of the tasks
//   saltus sweep collect DIR                    the summary and report from the records
//   saltus sweep task SPEC --out DIR ...        one array task (the batch script's command)
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/common.hpp"
#include "cli/sweep.hpp"
#include "scene/atomic_file.hpp"
#include "scene/cleanup.hpp"
#include "sweep/runner.hpp"

namespace saltus::cli {

namespace {

namespace fs = std::filesystem;
using namespace saltus::sweep;

std::string absoluteFolder(const std::string& path) {
  std::string s = fs::absolute(path).lexically_normal().string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

// The submitting command as the batch script's header shows it.
std::string submittingCommand(const SweepOptions& opt) {
  std::vector<std::string> a = {"saltus", "sweep", opt.spec, "--out", opt.out, "--slurm"};
  const slurm::SubmitOptions& s = opt.submit;
  if (!s.partition.empty()) a.insert(a.end(), {"--partition", s.partition});
  if (!s.time.empty()) a.insert(a.end(), {"--time", s.time});
  if (!s.mem.empty()) a.insert(a.end(), {"--mem", s.mem});
  if (s.max_parallel > 0) a.insert(a.end(), {"--max-parallel", std::to_string(s.max_parallel)});
  if (s.solves_per_task > 0) a.insert(a.end(), {"--solves-per-task", std::to_string(s.solves_per_task)});
  for (const std::string& x : s.sbatch_args) a.push_back("--sbatch-arg=" + x);
  if (opt.script_only) a.push_back("--slurm-script-only");
  return shellCommand(a);
}

// Writes the summary from the records there are; returns the exit code of a command that ends there.
int collectAndReport(const std::string& spec_as_written, const std::string& out, const std::vector<SweepCase>& cases,
                     const std::vector<SkippedCell>& skipped) {
  const std::vector<SweepRecord> records = readRecords(out, cases);
  const std::string chart_error = writeSweepSummary(spec_as_written, out, cases, skipped, records);
  printSweepLine(out, records.size(), cases.size(), -1, records);
  if (!chart_error.empty()) {
    std::cerr << "saltus: " << chart_error << "\n";
    return 1;
  }
  return 0;
}

std::vector<std::string> lastLines(const std::string& path, std::size_t n) {
  std::ifstream in(path);
  std::vector<std::string> all;
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) all.push_back(line);
  if (all.size() > n) all.erase(all.begin(), all.end() - static_cast<long>(n));
  return all;
}

}  // namespace

int submitSweep(const SweepOptions& opt, const std::vector<SweepCase>& cases, const std::vector<SkippedCell>& skipped) {
  // What an #SBATCH line cannot carry is refused before anything is written.
  try {
    slurm::ScriptInputs probe;
    probe.out_absolute = absoluteFolder(opt.out);
    probe.working_directory = fs::current_path().string();
    probe.plan = {1, 1, 1};
    probe.options = opt.submit;
    slurm::sbatchScript(probe);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  fs::create_directories(fs::path(opt.out) / "slurm" / "logs");
  DirectoryLock lock(opt.out);  // no local sweep in the folder while submitting
  slurm::refuseWhileActive(opt.out);
  slurm::writeSweepFolder(opt.out, {opt.spec, opt.out, fs::current_path().string()});
  std::vector<const SweepCase*> pending;
  for (const SweepCase& c : cases)
    if (!fs::exists(fs::path(caseDirectory(opt.out, c)) / "record.json")) pending.push_back(&c);
  if (pending.empty()) {
    std::cerr << "saltus sweep: every solve has a record; nothing to submit\n";
    return collectAndReport(opt.spec, opt.out, cases, skipped);
  }

  slurm::ArrayPlan plan;
  try {
    plan = slurm::planArray(static_cast<int>(pending.size()), slurm::maxArraySize(), opt.submit.solves_per_task);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  slurm::ScriptInputs in;
  in.saltus = fs::read_symlink("/proc/self/exe").string();
  in.spec = opt.spec;
  in.out = opt.out;
  in.working_directory = fs::current_path().string();
  in.out_absolute = absoluteFolder(opt.out);
  in.cases_file = slurm::nextCasesFile(opt.out);
  in.job_name = "saltus-sweep-" + fs::path(in.out_absolute).filename().string();
  in.submitted_by = submittingCommand(opt);
  in.plan = plan;
  in.options = opt.submit;
  std::string script;
  try {
    script = slurm::sbatchScript(in);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const std::string script_path = (fs::path(opt.out) / "slurm" / "sweep.sbatch").string();
  const std::string shape = std::to_string(plan.solves) + " solves in " + std::to_string(plan.tasks) + " array task" +
                            (plan.tasks == 1 ? "" : "s") + " (" + std::to_string(plan.solves_per_task) + " per task" +
                            (opt.submit.max_parallel > 0 ? ", at most " + std::to_string(opt.submit.max_parallel) + " at once" : "") +
                            ")";
  writeFileAtomically(in.cases_file, slurm::casesFileText(pending));
  if (opt.script_only) {
    writeFileAtomically(script_path, script);
    std::cout << script_path << "\n";
    std::cerr << "saltus sweep: wrote " << script_path << " for " << shape << "; submit it with\n  sbatch "
              << script_path << "\nand follow it with\n  saltus sweep status " << opt.out << "\n";
    return 0;
  }
  // Submitted from a temporary file, renamed into place once Slurm took it: a refused submission
  // leaves neither the script nor its list of solves.
  scene::ScopedTemporary temporary(scene::temporaryName(script_path));
  std::string job;
  try {
    std::ofstream(temporary.path()) << script;
    job = slurm::submit(temporary.path());
  } catch (...) {
    fs::remove(in.cases_file);
    throw;
  }
  fs::rename(temporary.path(), script_path);
  temporary.keep();
  slurm::addSubmission(opt.out, {job, in.cases_file, plan, ""});
  std::cout << job << "\n";
  std::cerr << "saltus sweep: submitted job array " << job << ": " << shape << "; follow it with\n  saltus sweep status "
            << opt.out << "\nand build the summary with\n  saltus sweep collect " << opt.out
            << "\n(or the same saltus sweep command again, which also submits the solves left without a record)\n";
  return 0;
}

namespace {

struct TaskOptions {
  std::string spec, out, cases;
  int solves_per_task = 1, index = -1;
};

int taskCommand(const TaskOptions& opt) {
  const SweepSpec spec = readSweepSpec(opt.spec);
  const std::vector<SweepCase> cases = expandSweep(spec);
  const std::vector<SweepCase> mine = slurm::taskCases(cases, opt.cases, opt.solves_per_task, opt.index);
  char host[256] = "?";
  ::gethostname(host, sizeof host - 1);
  const char* job = std::getenv("SLURM_ARRAY_JOB_ID");
  std::cerr << "saltus sweep task " << opt.index << (job ? std::string(" of job ") + job : "") << " on " << host << ": "
            << mine.size() << " solve(s):";
  for (const SweepCase& c : mine) std::cerr << " " << c.id;
  std::cerr << "\n";
  RunnerOptions ro;
  ro.saltus = fs::read_symlink("/proc/self/exe").string();
  ro.jobs = 1;
  ro.lock = false;  // the other tasks share the folder, each on its own solves
  ro.stopped_solve_leaves_no_record = true;
  const RunResult result = runSweep(spec, mine, opt.out, ro, [](const Progress& p) { printSweepProgress(p, false); });
  if (result.interrupted) {
    std::cerr << "saltus sweep task: stopped by signal " << result.signal
              << "; its solves without a record run again when the sweep is submitted again\n";
    return 128 + result.signal;
  }
  if (!result.stopped.empty()) {
    std::cerr << "saltus sweep task: solve " << result.stopped
              << " was stopped from outside (killed by a signal); it has no record and runs again when the sweep is "
                 "submitted again\n";
    return 1;
  }
  return 0;
}

struct StatusOptions {
  std::string out;
  bool json = false;
};

int statusCommand(const StatusOptions& opt) {
  const slurm::SweepFolder folder = slurm::readSweepFolder(opt.out);
  const SweepSpec spec = readSweepSpec(folder.specPath());
  const std::vector<SweepCase> cases = expandSweep(spec);
  // The arrays: those saltus submitted, and those whose tasks wrote a log (a script submitted by hand).
  const std::vector<slurm::Submission> submissions = slurm::readSubmissions(opt.out);
  std::vector<std::string> job_ids;
  for (const slurm::Submission& s : submissions) job_ids.push_back(s.job_id);
  const fs::path logs = fs::path(opt.out) / "slurm" / "logs";
  if (fs::is_directory(logs))
    for (const auto& entry : fs::directory_iterator(logs)) {
      const std::string name = entry.path().stem().string();
      const std::string id = name.substr(0, name.find('_'));
      if (!id.empty() && id.find_first_not_of("0123456789") == std::string::npos &&
          std::find(job_ids.begin(), job_ids.end(), id) == job_ids.end())
        job_ids.push_back(id);
    }
  std::string source;
  const std::vector<slurm::TaskState> tasks = slurm::queryTasks(job_ids, &source);
  std::map<std::string, int> groups;
  for (const slurm::TaskState& t : tasks) ++groups[slurm::stateGroup(t.state)];
  // The records after Slurm's states: a task Slurm saw finished wrote its records before it
  // ended, so they are all read here (read before, a task ending in between would show as
  // finished without its record).
  const std::vector<SweepRecord> records = readRecords(opt.out, cases);
  std::set<std::string> with_record;
  int succeeded = 0;
  for (const SweepRecord& r : records) with_record.insert(r.id), succeeded += r.success();
  const int failed = static_cast<int>(records.size()) - succeeded;

  // Tasks that ended without leaving a record for every solve of theirs: run again on resume.
  struct Unfinished {
    slurm::TaskState task;
    std::vector<std::string> solves, log;
  };
  // Each submission's list of solves, read once (a status of 600 tasks reads it once, not 600 times).
  std::map<std::string, std::vector<std::string>> listed;
  for (const slurm::Submission& s : submissions) {
    std::ifstream in(s.cases_file);
    for (std::string line; std::getline(in, line);) listed[s.job_id].push_back(line);
  }
  std::vector<Unfinished> unfinished;
  for (const slurm::TaskState& t : tasks) {
    if (slurm::isActive(t.state)) continue;
    for (const slurm::Submission& s : submissions) {
      if (s.job_id != t.job_id) continue;
      const std::vector<std::string>& ids = listed[s.job_id];
      std::vector<std::string> missing;
      const std::size_t first = static_cast<std::size_t>(t.task) * s.plan.solves_per_task;
      for (std::size_t n = first; n < ids.size() && n < first + s.plan.solves_per_task; ++n)
        if (!with_record.count(ids[n])) missing.push_back(ids[n]);
      if (missing.empty()) continue;
      const std::string log = (logs / (t.job_id + "_" + std::to_string(t.task) + ".log")).string();
      unfinished.push_back({t, missing, lastLines(log, 4)});
    }
  }
  const int without = static_cast<int>(cases.size() - records.size());
  if (opt.json) {
    nlohmann::json j = {{"solves", cases.size()}, {"records", records.size()}, {"succeeded", succeeded},
                        {"failed", failed},       {"without_record", without}, {"slurm_source", source}};
    j["jobs"] = job_ids;
    j["tasks"] = nlohmann::json::object();
    for (const auto& [group, n] : groups) j["tasks"][group] = n;
    j["unfinished"] = nlohmann::json::array();
    for (const Unfinished& u : unfinished)
      j["unfinished"].push_back({{"job", u.task.job_id}, {"task", u.task.task}, {"state", u.task.state},
                                 {"solves", u.solves}, {"log", u.log}});
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "sweep " << opt.out << " (spec " << folder.spec << "): " << cases.size() << " solves\n"
            << "  with a record: " << records.size() << " (" << succeeded << " succeeded, " << failed
            << " failed; a failed solve is not run again)\n"
            << "  without a record: " << without << "\n";
  if (job_ids.empty()) {
    std::cout << "no Slurm job array submitted from this folder\n";
    return 0;
  }
  std::cout << "Slurm job array" << (job_ids.size() > 1 ? "s " : " ");
  for (std::size_t i = 0; i < job_ids.size(); ++i) std::cout << (i ? ", " : "") << job_ids[i];
  if (tasks.empty()) {
    std::cout << ": Slurm no longer knows the tasks (finished longer ago than its MinJobAge, and no accounting)\n";
  } else {
    std::cout << " (finished tasks from " << (source.empty() ? "nowhere: no sacct or scontrol answer" : source) << "):";
    bool first = true;
    for (const auto& [group, n] : groups) std::cout << (first ? " " : ", ") << n << " " << group, first = false;
    std::cout << "\n";
  }
  for (const slurm::TaskState& t : tasks)
    if (slurm::stateGroup(t.state) == "pending" && !t.reason.empty()) {
      std::cout << "  pending tasks wait for: " << t.reason << "\n";
      break;
    }
  for (const Unfinished& u : unfinished) {
    std::cout << "task " << u.task.job_id << "_" << u.task.task << " " << u.task.state << ", no record for:";
    for (const std::string& s : u.solves) std::cout << " " << s;
    std::cout << " (run again when the sweep is submitted again)\n";
    for (const std::string& l : u.log) std::cout << "  | " << l << "\n";
  }
  return 0;
}

int collectCommand(const std::string& out) {
  const slurm::SweepFolder folder = slurm::readSweepFolder(out);
  const SweepSpec spec = readSweepSpec(folder.specPath());
  std::vector<SkippedCell> skipped;
  const std::vector<SweepCase> cases = expandSweep(spec, &skipped);
  const int code = collectAndReport(folder.spec, out, cases, skipped);
  const std::size_t records = readRecords(out, cases).size();
  if (code == 0 && records < cases.size()) {
    std::cerr << "saltus sweep collect: " << cases.size() - records
              << " solve(s) have no record yet; saltus sweep status " << out << " shows where they are\n";
    return 1;
  }
  return code;
}

}  // namespace

std::function<bool(int&)> addSweepSubcommands(CLI::App& sweep) {
  auto status = std::make_shared<StatusOptions>();
  CLI::App* status_app = sweep.add_subcommand("status", "Where a sweep is: its records, and Slurm's view of its tasks");
  status_app->add_option("dir", status->out, "the sweep's folder (--out of the sweep)")->required();
  status_app->add_flag("--json", status->json, "print the counts as JSON");

  auto collect = std::make_shared<std::string>();
  CLI::App* collect_app = sweep.add_subcommand("collect", "The summary, charts and report of a sweep from its records");
  collect_app->add_option("dir", *collect, "the sweep's folder (--out of the sweep)")->required();

  auto task = std::make_shared<TaskOptions>();
  CLI::App* task_app = sweep.add_subcommand("task", "One array task of a Slurm sweep (the batch script runs it)");
  task_app->group("");  // not in --help: users submit with --slurm
  task_app->add_option("spec", task->spec, "sweep spec")->required();
  task_app->add_option("--out", task->out, "the sweep's folder")->required();
  task_app->add_option("--cases", task->cases, "the submission's list of solves")->required();
  task_app->add_option("--solves-per-task", task->solves_per_task, "solves per task")->required()->check(CLI::PositiveNumber);
  task_app->add_option("--index", task->index, "the array task's index")->required()->check(CLI::NonNegativeNumber);

  return [=](int& code) {
    if (status_app->parsed()) return code = statusCommand(*status), true;
    if (collect_app->parsed()) return code = collectCommand(*collect), true;
    if (task_app->parsed()) return code = taskCommand(*task), true;
    return false;
  };
}

}  // namespace saltus::cli
