// saltus sweep SPEC.yaml --out DIR [--jobs N] [--list]: the grid of seeded solves of a spec
// (sweep/spec.hpp) on N local processes, one record per solve (sweep/runner.hpp), and then
//   DIR/summary.csv, DIR/summary.json   statistics per cell (sweep/record.hpp)
//   DIR/report.md                       success rates per cell, failures, the charts
//   DIR/charts/sweep_{time,error,cost}.{png,svg}   the paper's Figs. 6–8 per cell and method
// The spec is checked, and every problem loaded with each of its parameter combinations,
// before any solve starts. Run again with the same arguments, the sweep skips the solves that
// have a record. Exit status: 0 when every solve has a record, 130 or 143 when interrupted by SIGINT or SIGTERM (the
// summary covers the records so far), 1 for errors (a bad spec names file, line and key).
// With --slurm the solves without a record go to a Slurm job array instead (sweep_slurm.cpp).
#include <csignal>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "cli/sweep.hpp"
#include "collocation/solver.hpp"
#include "sweep/runner.hpp"

namespace saltus::cli {

namespace {

namespace fs = std::filesystem;
using namespace saltus::sweep;

std::string duration(double seconds) {
  if (seconds < 0) return "?";
  const long s = std::lround(seconds);
  std::ostringstream o;
  if (s >= 3600) o << s / 3600 << "h" << (s % 3600) / 60 << "m";
  else if (s >= 60) o << s / 60 << "m" << s % 60 << "s";
  else o << s << "s";
  return o.str();
}

}  // namespace

std::string sweepOutcome(const SweepRecord& r) {
  if (r.status == "error") return "error: " + r.error;
  std::ostringstream o;
  o << (r.success() ? "success" : !r.feasible ? "not feasible" : "not physical")
    << (r.success() && r.physical == false ? ", not physical" : "")
    << (r.feasible && !r.converged ? ", not converged" : "") << " (" << r.status << ", "
    << r.iterations << " it, " << formatNumber(r.wall_seconds, 3) << " s, largest product "
    << formatNumber(r.largest_product, 2);
  if (r.replay_deviation >= 0) o << ", replay deviation " << formatNumber(r.replay_deviation, 2);
  return o.str() + ")";
}

void printSweepProgress(const Progress& p, bool terminal) {
  const int left = p.total - p.done;
  if (terminal) {
    const int width = 30, filled = p.total ? width * p.done / p.total : width;
    std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << p.done << "/"
              << p.total << " done, " << p.failed << " failed, " << left << " left, ETA " << duration(p.eta_seconds)
              << "   " << std::flush;
    if (left == 0) std::cerr << "\n";
    return;
  }
  if (!p.last) {
    std::cerr << "saltus sweep: " << p.total << " solves, " << p.skipped << " with a record already\n";
    return;
  }
  std::cerr << "[" << p.done << "/" << p.total << "] " << p.last->id << ": " << sweepOutcome(*p.last) << "; " << left
            << " left, ETA " << duration(p.eta_seconds) << "\n";
}

namespace {

std::string quartileText(const Quartiles& q, int digits = 3) {
  if (q.count == 0) return "–";
  return formatNumber(q.median, digits) + " [" + formatNumber(q.q1, digits) + ", " + formatNumber(q.q3, digits) + "]";
}

std::string report(const std::string& spec_file, const std::vector<SweepCase>& cases, const std::vector<SkippedCell>& skipped,
                   const std::vector<SweepRecord>& records, const std::vector<CellSummary>& cells, bool charts) {
  // Every case carries the spec's rule; an empty grid has no rule to tell.
  const bool physical_decides = cases.empty() || cases.front().physical_required;
  std::ostringstream md;
  md << "# Sweep " << fs::path(spec_file).filename().string() << "\n\n"
     << "Spec `" << spec_file << "`; " << records.size() << " of " << cases.size() << " solves have a record"
     << (records.size() < cases.size() ? " (the sweep is not finished: run the same command again)" : "") << ".\n\n"
     << "A solve succeeds when it is feasible (at its solution every complementarity product is at most the "
        "problem's tolerance and every constraint holds within "
     << formatValue(collocation::SolveOptions{}.violation_tolerance) << ")"
     << (physical_decides ? " and physically right (its replay in Saltus' time-stepper stays within the replay tolerance)"
                          : "; the spec's `success: feasible` (the paper's rule) leaves the replay out of it, and physical "
                            "counts the solves whose replay in Saltus' time-stepper stays within the replay tolerance")
     << ". Converged: feasible, and Ipopt solved the stage the solution comes from (a task stage "
        "stopped by its iteration limit at a feasible point is feasible, not converged). Time, iterations, mean local error and cost are over the successful solves: median "
        "[first quartile, third quartile].\n\n"
     << "| problem | method | parameters | success | feasible | converged | physical | wall s | iterations | "
        "mean local error | cost |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const CellSummary& c : cells) {
    std::string parameters;
    for (const auto& [name, value] : c.set) parameters += (parameters.empty() ? "" : ", ") + name + " = " + formatValue(value);
    md << "| " << c.problem_name << " | " << c.method << (c.variant.empty() ? "" : " [" + c.variant + "]") << " | "
       << (parameters.empty() ? "–" : parameters) << " | " << c.successes << "/" << c.solves << " (" << std::lround(100 * c.success_rate) << " %) | " << c.feasible << " | "
       << c.converged << " | " << c.physical << " | " << quartileText(c.wall_seconds) << " | " << quartileText(c.iterations) << " | "
       << quartileText(c.mean_local_error, 2) << " | " << quartileText(c.objective, 3) << " |\n";
  }
  int total = 0, successes = 0;
  for (const CellSummary& c : cells) total += c.solves, successes += c.successes;
  md << "\nOverall: " << successes << " of " << total << " solves succeeded.\n";
  if (!skipped.empty()) {
    md << "\n## Not applicable\n\nCells left out because their method cannot represent the problem there:\n\n"
          "| problem | method | parameters | why |\n|---|---|---|---|\n";
    for (const SkippedCell& c : skipped) {
      std::string parameters;
      for (const auto& [name, value] : c.set) parameters += (parameters.empty() ? "" : ", ") + name + " = " + formatValue(value);
      md << "| " << c.problem_name << " | " << c.method << " | " << (parameters.empty() ? "–" : parameters) << " | "
         << c.reason << " |\n";
    }
  }
  if (charts)
    md << "\n## Charts\n\nPer cell and method: mean (circle), median (tick), range (thin line), interquartile range (thick line), "
          "as in the paper's Figs. 6–8 (Shield, Johnson & Patel, IEEE T-RO 2023).\n\n"
          "![solve time](charts/sweep_time.png)\n\n![mean local error](charts/sweep_error.png)\n\n"
          "![cost](charts/sweep_cost.png)\n";
  bool header = false;
  for (const SweepRecord& r : records) {
    if (r.success()) continue;
    if (!header) md << "\n## Failed solves\n\n| solve | outcome | command |\n|---|---|---|\n";
    header = true;
    std::string text = sweepOutcome(r);
    for (char& ch : text)
      if (ch == '|' || ch == '\n') ch = ' ';
    md << "| " << r.id << " | " << text << " | `" << r.command << "` |\n";
  }
  return md.str();
}

}  // namespace

std::string writeSweepSummary(const std::string& spec, const std::string& out_dir, const std::vector<SweepCase>& cases,
                              const std::vector<SkippedCell>& skipped, const std::vector<SweepRecord>& records) {
  const std::vector<CellSummary> cells = summarise(records);
  const fs::path out(out_dir);
  writeFileAtomically((out / "summary.csv").string(), summaryCsv(cells));
  writeFileAtomically((out / "summary.json").string(), summaryJson(cells, records).dump(2) + "\n");
  bool charts = false;
  std::string chart_error;
  if (!records.empty()) {
    try {
      fs::create_directories(out / "charts");
      for (const char* kind : {"time", "error", "cost"}) {
        const std::string stem = (out / "charts" / (std::string("sweep_") + kind)).string();
        drawChart(std::string("sweep-") + kind, (out / "summary.json").string(), stem + ".png", stem + ".svg");
      }
      charts = true;
    } catch (const std::exception& e) {
      chart_error = e.what();
    }
  }
  writeFileAtomically((out / "report.md").string(), report(spec, cases, skipped, records, cells, charts));
  return chart_error;
}

void printSweepLine(const std::string& out, std::size_t records, std::size_t cases, int ran,
                    const std::vector<SweepRecord>& all) {
  int successes = 0;
  for (const SweepRecord& r : all) successes += r.success();
  std::cerr << "saltus sweep: " << records << " of " << cases << " solves have a record";
  if (ran >= 0) std::cerr << " (" << ran << " run now)";
  std::cerr << ", " << successes << " succeeded -> " << (fs::path(out) / "report.md").string() << "\n";
}

namespace {

int sweepCommand(const SweepOptions& opt) {
  if (opt.spec.empty()) throw UsageError("a sweep spec (SPEC.yaml) is required, or one of: status, collect");
  if (opt.out.empty()) throw UsageError("--out is required: the sweep's folder");
  const bool slurm = opt.slurm || opt.script_only;
  if (slurm && opt.jobs > 0)
    throw UsageError("--jobs: not with --slurm (Slurm runs one solve per core; --max-parallel limits the tasks at once)");
  if (!slurm && (!opt.submit.partition.empty() || !opt.submit.time.empty() ||
                     !opt.submit.mem.empty() || opt.submit.max_parallel > 0 || opt.submit.solves_per_task > 0 ||
                     !opt.submit.sbatch_args.empty()))
    throw UsageError("--partition, --time, --mem, --max-parallel, --solves-per-task and --sbatch-arg go with "
                     "--slurm");
  const SweepSpec spec = readSweepSpec(opt.spec);
  std::vector<SkippedCell> skipped;
  const std::vector<SweepCase> cases = expandSweep(spec, &skipped);
  if (!skipped.empty())
    std::cerr << "saltus sweep: " << skipped.size() << " cell(s) left out, their method cannot represent the problem there ("
              << skipped.front().method << ", " << skipped.front().problem_name << ": " << skipped.front().reason
              << (skipped.size() > 1 ? "; ..." : "") << "); report.md lists them\n";
  if (opt.list) {
    for (const SweepCase* c : startOrder(cases)) {  // the order a run starts them in
      std::vector<std::string> args = c->optimizeArguments(caseDirectory(opt.out, *c) + "/solution");
      args.insert(args.begin(), "saltus");
      std::cout << shellCommand(args) << "\n";
    }
    return 0;
  }
  if (fs::exists(opt.out) && !fs::is_directory(opt.out)) throw UsageError("--out " + opt.out + ": exists and is not a directory");
  // A resume keeps every record: say which were made by another command than the spec gives now.
  if (const std::vector<std::string> other = recordsOfAnotherCommand(opt.out, cases); !other.empty())
    std::cerr << "saltus sweep: warning: " << other.size() << " record(s) in " << opt.out
              << " were made by another command than the spec gives now, and are kept as they are (remove a "
                 "case's folder under runs/ to solve it again): "
              << other.front() << (other.size() > 1 ? "; ..." : "") << "\n";
  if (slurm) return submitSweep(opt, cases, skipped);
  fs::create_directories(opt.out);
  slurm::refuseWhileActive(opt.out);  // a Slurm array of this sweep would run the same solves
  slurm::writeSweepFolder(opt.out, {opt.spec, opt.out, fs::current_path().string()});
  RunnerOptions ro;
  ro.saltus = fs::read_symlink("/proc/self/exe").string();
  ro.jobs = opt.jobs > 0 ? opt.jobs : std::max(1u, std::thread::hardware_concurrency());
  const bool terminal = ::isatty(STDERR_FILENO);
  const RunResult result =
      runSweep(spec, cases, opt.out, ro, [&](const Progress& p) { printSweepProgress(p, terminal); });
  if (terminal && result.interrupted) std::cerr << "\n";

  const std::string chart_error = writeSweepSummary(opt.spec, opt.out, cases, skipped, result.records);
  printSweepLine(opt.out, result.records.size(), cases.size(), result.ran, result.records);
  if (result.interrupted) {
    std::cerr << "saltus sweep: interrupted; run the same command again to finish\n";
    return 128 + (result.signal > 0 ? result.signal : SIGINT);  // 130 (SIGINT), 143 (SIGTERM)
  }
  if (!chart_error.empty()) {
    std::cerr << "saltus: " << chart_error << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

Command addSweepCommand(CLI::App& saltus) {
  auto opt = std::make_shared<SweepOptions>();
  CLI::App* app = saltus.add_subcommand(
      "sweep", "A grid of seeded solves on local processes or a Slurm job array, with statistics and charts");
  app->add_option("spec", opt->spec, "sweep spec (.yaml): problems, methods, set, seeds, options");
  app->add_option("--out", opt->out, "output folder (runs/<id>/record.json, summary.csv/.json, report.md, charts/)");
  app->add_option("--jobs", opt->jobs, "solves at once (default: the number of cores)")->check(CLI::NonNegativeNumber);
  app->add_flag("--list", opt->list, "print the saltus optimize command of every solve, in the order a run starts them, and stop");
  auto* slurm = app->add_option_group("Slurm", "Run the solves without a record as one Slurm job array");
  slurm->add_flag("--slurm", opt->slurm, "submit the solves without a record as one job array (sbatch) and return");
  slurm->add_option("--partition", opt->submit.partition, "Slurm partition (default: the cluster's)");
  slurm->add_option("--time", opt->submit.time, "time limit of one array task, as sbatch --time (HH:MM:SS)");
  slurm->add_option("--mem", opt->submit.mem, "memory of one array task, as sbatch --mem (e.g. 2G)");
  slurm->add_option("--max-parallel", opt->submit.max_parallel, "array tasks running at once (the array's %K)")
      ->check(CLI::PositiveNumber);
  slurm->add_option("--solves-per-task", opt->submit.solves_per_task,
                    "solves per array task (default: 1, or what fits the cluster's MaxArraySize)")
      ->check(CLI::PositiveNumber);
  slurm->add_option("--sbatch-arg", opt->submit.sbatch_args, "a further sbatch option, e.g. --sbatch-arg=--qos=long "
                                                             "(repeatable; one #SBATCH line each)")
      ->allow_extra_args(false);
  slurm->add_flag("--slurm-script-only", opt->script_only,
                  "write DIR/slurm/sweep.sbatch without submitting it (for clusters that need edits; implies --slurm)");
  const std::function<bool(int&)> subcommand = addSweepSubcommands(*app);
  app->require_subcommand(0, 1);
  return {app, [opt, subcommand] {
            int code = 0;
            if (subcommand(code)) return code;
            return sweepCommand(*opt);
          }};
}

}  // namespace saltus::cli
