// saltus run [PROBLEM] [--out DIR]: the main job. Runs the pipeline as subprocesses of this same
// program (and of the chart script), each step into a folder of DIR:
//   optimize  saltus optimize PROBLEM --out DIR/optimize           (trajectory.csv, summary.json, variables.csv)
//   replay    saltus replay DIR/optimize --engine both --out DIR/replay   (replay.json and its charts)
//   render    saltus render DIR/optimize --out DIR/render/video.mp4 --frames ...   (video, one still frame kept)
//   charts    python3 scripts/charts.py trajectory DIR/optimize/trajectory.csv ...  (DIR/charts/trajectory.{png,svg})
// then writes DIR/report.md: the problem, the solve's figures (summary.json), the trajectory
// chart, the replay's deviations per engine and its charts, the video and a still frame, and
// every step's command line, exit status, wall time, outputs and log (DIR/logs/<step>.log).
// The report links only files that exist.
//
// A step that fails (non-zero exit, or exit 0 without the files it must write) is reported as
// failed, never replaced by made-up results. One exception to "non-zero exit = failed": `saltus
// replay` exits 1 when an engine leaves its tolerance; when every engine completed, Saltus's
// replay is within the tolerance and only Bullet's is not (pendulum_conveyor: Bullet has no
// tangential impulse and reaches the belt's speed over tens of ms), the step counts as done and
// the report says so in its Result line and table. An infeasible
// solve (optimize exits 1 but writes its files) still goes on to replay, render and charts, and
// is marked in the report. The exit status is 0 only when every step succeeded and the solve is
// feasible, else 1 (2 for bad options).
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/common.hpp"
#include "cli/optimize.hpp"
#include "cli/run_pipeline.hpp"
#include "scene/cleanup.hpp"
#include "cli/simulation.hpp"
#include "render/animation.hpp"  // kMaxFrames
#include "verify/engine.hpp"
#include "saltus/collocation_source.hpp"

namespace saltus::cli {

namespace {

namespace fs = std::filesystem;
using namespace saltus::cli::pipeline;

struct RunOptions {
  std::string problem = "pendulum_conveyor";
  std::string out;
  std::vector<std::string> set;
  std::string method;
  std::optional<unsigned> seed;
  std::optional<int> N, P;
  std::vector<std::string> ipopt, task_ipopt;
  std::string engine = "both";
  double fps = 30;
  std::optional<double> speed;
  double video_seconds = 4;
  int width = 640, height = 360;
};

// Runs step.command with standard output and error into `log_path` (MPLBACKEND=Agg for the
// chart script); records exit status and wall time.
// A folder a step makes: removed again if the run is interrupted before the step keeps it
// (an earlier folder of that name is left alone).
class MadeFolder {
 public:
  explicit MadeFolder(const fs::path& dir) {
    std::error_code error;
    if (!fs::exists(dir, error)) made_ = std::make_unique<scene::ScopedTemporary>(dir.string());
    fs::create_directories(dir);
  }
  void keep() {
    if (made_) made_->keep();
  }

 private:
  std::unique_ptr<scene::ScopedTemporary> made_;
};

void runPipelineStep(PipelineStep& step, const fs::path& run_dir, const fs::path& log_path) {
  step.log = fs::relative(log_path, run_dir).string();
  // The log is a temporary until the step ends: an interrupted step leaves no log cut short.
  MadeFolder logs(log_path.parent_path());
  scene::ScopedTemporary log(scene::temporaryName(log_path.string()));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  step.ran = true;
  try {
    // MPLBACKEND=Agg for the chart steps; a process group of its own, stopped on an interrupt
    pid = scene::spawnChild(step.command[0], step.command, chartEnvironment(), &actions);
  } catch (const std::exception& e) {
    posix_spawn_file_actions_destroy(&actions);
    step.exit_status = -1;
    step.note = e.what();  // "cannot start PROGRAM (reason)"
    return;
  }
  posix_spawn_file_actions_destroy(&actions);
  const int status = scene::waitChild(pid);
  step.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::error_code error;
  fs::rename(log.path(), log_path, error);
  if (!error) log.keep();
  logs.keep();
  if (WIFEXITED(status)) {
    step.exit_status = WEXITSTATUS(status);
  } else {
    step.exit_status = -1;
    step.note = "killed by signal " + std::to_string(WTERMSIG(status));
  }
}

// This program, to run the steps: /proc/self/exe, else argv[0] as the shell found it.
std::string thisProgram() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (!error && !self.empty()) return self.string();
  return "saltus";
}

void checkRunOptions(const RunOptions& opt) {
  if (!(opt.fps > 0) || !std::isfinite(opt.fps) || opt.fps > 1000)
    throw UsageError("--fps: expected frames per second in (0, 1000], got " + formatNumber(opt.fps));
  if (opt.speed && !(*opt.speed > 0 && std::isfinite(*opt.speed)))
    throw UsageError("--speed: expected a positive playback speed, got " + formatNumber(*opt.speed));
  if (!(opt.video_seconds > 0) || !std::isfinite(opt.video_seconds))
    throw UsageError("--video-seconds: expected a positive duration, got " + formatNumber(opt.video_seconds));
  if (!opt.speed && !(opt.video_seconds * opt.fps <= render::kMaxFrames))
    throw UsageError("--video-seconds: " + formatNumber(opt.video_seconds) + " s at " + formatNumber(opt.fps) +
                     " fps is " + formatNumber(opt.video_seconds * opt.fps, 3) + " frames, more than a million");
  if (opt.width < 2 || opt.height < 2 || opt.width > 8192 || opt.height > 8192 || opt.width % 2 || opt.height % 2)
    throw UsageError("--width/--height: expected even sizes of 2 … 8192 pixels (H.264), got " + std::to_string(opt.width) +
                     "x" + std::to_string(opt.height));
  try {
    verify::parseEngines(opt.engine);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--engine: ") + e.what());
  }
  parseSetOptions(opt.set);  // malformed assignments are usage errors before anything runs
}

// What a step found on disk after it ran: the files it wrote (listed), the files it must have
// written (a step that exits 0 without them failed).
void listOutputs(PipelineStep& s, const fs::path& dir, const std::vector<fs::path>& files) {
  for (const fs::path& f : files)
    if (fs::exists(f)) s.outputs.push_back(fs::relative(f, dir).string());
}
void requireOutputs(PipelineStep& s, const fs::path& dir, const std::vector<fs::path>& required) {
  if (!s.ran || s.exit_status != 0) return;
  for (const fs::path& f : required)
    if (!fs::exists(f)) {
      s.missing_outputs = true;
      s.note += (s.note.empty() ? "" : "; ") + ("exited 0 but did not write " + fs::relative(f, dir).string());
    }
}

void announce(const PipelineStep& s, const fs::path& dir) {
  std::cerr << "saltus run: " << s.name << ": ";
  if (!s.ran)
    std::cerr << "skipped (" << s.note << ")\n";
  else
    std::cerr << (s.ok() ? "ok" : "FAILED (exit status " + std::to_string(s.exit_status) + ")") << " in "
              << formatNumber(s.wall_seconds, 3) << " s" << (s.ok() ? "" : ", log: " + (dir / s.log).string()) << "\n";
}

// The replay step: its files, and whether its exit status 1 is the finding that Bullet leaves the
// tolerance while Saltus stays within it (every engine completed, charts drawn).
void runReplayStep(PipelineStep& replay, const RunFolders& f) {
  std::error_code error;
  MadeFolder folder(f.replay);
  runPipelineStep(replay, f.dir, f.dir / "logs" / "replay.log");
  folder.keep();
  if (replay.exit_status == 2 && logTail(f.dir / "logs" / "replay.log", 5).find("unknown command") != std::string::npos)
    replay.note = "this saltus has no 'replay' command";
  std::vector<fs::path> replay_files{f.replay / "replay.json"};
  const std::optional<nlohmann::json> rj = readJsonFile(f.replay / "replay.json");
  if (rj && rj->contains("charts") && (*rj)["charts"].is_array())
    for (const auto& c : (*rj)["charts"])
      if (c.is_string()) replay_files.push_back(f.replay / c.get<std::string>());
  listOutputs(replay, f.dir, replay_files);
  requireOutputs(replay, f.dir, {f.replay / "replay.json"});
  if (replay.exit_status == 1 && rj && rj->contains("engines") && (*rj)["engines"].is_object()) {
    const nlohmann::json& engines = (*rj)["engines"];
    bool completed = !engines.empty(), saltus_within = false, bullet_outside = false;
    for (const auto& [name, e] : engines.items()) {
      completed = completed && e.value("completed", false);
      const bool within = e.value("within_tolerance", false);
      if (name == "saltus") saltus_within = within;
      if (name == "bullet") bullet_outside = !within;
    }
    // Charts listed in replay.json must exist (a failed chart also exits 1).
    bool charts_present = true;
    if (rj->contains("charts") && (*rj)["charts"].is_array())
      for (const auto& c : (*rj)["charts"])
        charts_present = charts_present && c.is_string() && fs::exists(f.replay / c.get<std::string>());
    if (completed && saltus_within && bullet_outside && charts_present && !rj->contains("chart_error")) {
      replay.bullet_outside_tolerance = true;
      replay.note = "Bullet's replay is outside the tolerance (Saltus's is within it): a result, see Replay";
    }
  }
  if (fs::is_empty(f.replay, error)) fs::remove(f.replay, error);  // nothing written: no empty folder
}

// The render step; one frame is kept as the still: just after the first impulse (its marker
// showing), else the middle one.
void runRenderStep(PipelineStep& render, const RunFolders& f, double first_impulse, double speed, double fps) {
  std::error_code error;
  MadeFolder folder(f.render);
  runPipelineStep(render, f.dir, f.dir / "logs" / "render.log");
  folder.keep();
  if (render.ok()) {
    std::vector<fs::path> frames;
    for (const auto& entry : fs::directory_iterator(f.frames, error)) frames.push_back(entry.path());
    std::sort(frames.begin(), frames.end());
    if (!frames.empty()) {
      std::size_t k = frames.size() / 2;
      if (first_impulse >= 0)
        k = std::min(frames.size() - 1, static_cast<std::size_t>(std::ceil(first_impulse / speed * fps)) + 2);
      std::error_code rename_error;  // a failure leaves the still missing: the render step is marked failed
      fs::rename(frames[k], f.still, rename_error);
    }
    fs::remove_all(f.frames);
  }
  listOutputs(render, f.dir, {f.video, f.still});
  requireOutputs(render, f.dir, {f.video, f.still});
  if (fs::is_empty(f.render, error)) fs::remove(f.render, error);  // nothing written: no empty folder
}

int run(const RunOptions& opt) {
  checkRunOptions(opt);
  // The optimize step's options and the problem, checked before anything is created.
  OptimizeCliOptions optimize_options;
  optimize_options.problem = opt.problem;
  if (!opt.method.empty()) optimize_options.method = opt.method;
  optimize_options.seed = opt.seed;
  optimize_options.N = opt.N;
  optimize_options.P = opt.P;
  optimize_options.set = opt.set;
  optimize_options.ipopt = opt.ipopt;
  optimize_options.task_ipopt = opt.task_ipopt;
  prepareOptimize(optimize_options);
  RunFacts facts;
  facts.problem_word = fs::path(opt.problem).stem().string();
  facts.fps = opt.fps;
  facts.width = opt.width;
  facts.height = opt.height;
  const RunFolders f(fs::absolute(opt.out.empty() ? "out/run_" + facts.problem_word : opt.out).lexically_normal());
  std::error_code error;
  checkOutputTarget("--out", f.dir.string(), OutputTarget::Folder);
  // A fresh run: the step folders and the report of an earlier run in DIR are removed first, so
  // that nothing stale is reported.
  for (const char* sub : {"optimize", "replay", "render", "charts", "logs"}) fs::remove_all(f.dir / sub);
  fs::remove(f.dir / "report.md");
  // A folder made by this run goes again if the run is interrupted before its report.
  std::unique_ptr<scene::ScopedTemporary> made;
  if (!fs::exists(f.dir, error)) made = std::make_unique<scene::ScopedTemporary>(f.dir.string());
  fs::create_directories(f.dir);
  const std::string saltus = thisProgram();

  // 1. optimize
  RunSteps steps{{"optimize", {saltus, "optimize", opt.problem, "--out", f.optimize.string()}},
                 {"replay", {saltus, "replay", f.optimize.string(), "--engine", opt.engine, "--out", f.replay.string()}},
                 {"render", {}},
                 {"charts", {}}};
  PipelineStep& optimize = steps.optimize;
  if (!opt.method.empty()) optimize.command.insert(optimize.command.end(), {"--method", opt.method});
  if (opt.seed) optimize.command.insert(optimize.command.end(), {"--seed", std::to_string(*opt.seed)});
  if (opt.N) optimize.command.insert(optimize.command.end(), {"--N", std::to_string(*opt.N)});
  if (opt.P) optimize.command.insert(optimize.command.end(), {"--P", std::to_string(*opt.P)});
  for (const std::string& s : opt.set) optimize.command.insert(optimize.command.end(), {"--set", s});
  for (const std::string& s : opt.ipopt) optimize.command.insert(optimize.command.end(), {"--ipopt", s});
  for (const std::string& s : opt.task_ipopt) optimize.command.insert(optimize.command.end(), {"--task-ipopt", s});
  std::cerr << "saltus run: " << opt.problem << " -> " << f.dir.string() << "\n";
  runPipelineStep(optimize, f.dir, f.dir / "logs" / "optimize.log");
  const std::vector<fs::path> solution_files{f.optimize / "summary.json", f.optimize / "trajectory.csv",
                                             f.optimize / "variables.csv"};
  listOutputs(optimize, f.dir, solution_files);
  requireOutputs(optimize, f.dir, solution_files);
  facts.summary = readJsonFile(f.optimize / "summary.json");
  facts.solved = facts.summary && fs::exists(f.optimize / "variables.csv") && fs::exists(f.optimize / "trajectory.csv");
  facts.feasible = facts.solved && facts.summary->value("feasible", false);
  if (optimize.exit_status == 1 && facts.solved)
    optimize.note = "the solve ended infeasible (files written; later steps use them)";
  announce(optimize, f.dir);

  // The trajectory's time range and first impulse, for the playback speed and the still frame.
  double total_time = 0, first_impulse = -1;
  if (facts.solved) {
    try {
      const CollocationSource source = CollocationSource::load(f.optimize.string());
      total_time = source.endTime();
      if (!source.impulses().empty()) first_impulse = source.impulses().front().t;
    } catch (const std::exception& e) {
      std::cerr << "saltus run: cannot read the solution back: " << e.what() << "\n";
    }
  }
  facts.speed = opt.speed ? *opt.speed : total_time > 0 ? std::min(1.0, total_time / opt.video_seconds) : 1.0;

  // 2. replay (in Saltus's time-stepper and in Bullet), 3. render, 4. charts
  steps.render.command = {saltus, "render", f.optimize.string(), "--out", f.video.string(), "--frames", f.frames.string(),
                          "--fps", formatNumber(opt.fps), "--speed", formatNumber(facts.speed, 8), "--width",
                          std::to_string(opt.width), "--height", std::to_string(opt.height)};
  steps.charts.command = chartCommand("trajectory", (f.optimize / "trajectory.csv").string(), f.chart_png.string(),
                                      f.chart_svg.string());
  steps.charts.command.insert(
      steps.charts.command.end(),
      {"--title", facts.problem_word + " (" + (facts.summary ? jsonNumber(*facts.summary, "method") : opt.method) + ")"});
  if (!facts.solved) {
    for (PipelineStep* s : {&steps.replay, &steps.render, &steps.charts})
      s->note = "no solution: the optimize step wrote no summary.json/variables.csv";
  } else {
    runReplayStep(steps.replay, f);
    runRenderStep(steps.render, f, first_impulse, facts.speed, opt.fps);
    MadeFolder charts(f.charts);
    runPipelineStep(steps.charts, f.dir, f.dir / "logs" / "charts.log");
    charts.keep();
    listOutputs(steps.charts, f.dir, {f.chart_png, f.chart_svg});
    requireOutputs(steps.charts, f.dir, {f.chart_png, f.chart_svg});
    std::error_code error;
    if (fs::is_empty(f.charts, error)) fs::remove(f.charts, error);
  }
  for (const PipelineStep* s : {&steps.replay, &steps.render, &steps.charts}) announce(*s, f.dir);

  const bool all_ok = facts.feasible && steps.allOk();
  writeFileAtomically((f.dir / "report.md").string(), runReport(f, facts, steps));
  if (made) made->keep();
  std::cerr << "saltus run: " << (all_ok ? "done" : "FAILED") << ": " << (f.dir / "report.md").string() << "\n";
  return all_ok ? 0 : 1;
}

}  // namespace

Command addRunCommand(CLI::App& saltus) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* app = saltus.add_subcommand(
      "run", "The main job: optimise, replay in Saltus and Bullet, render the video, draw the charts, write report.md");
  app->add_option("problem", opt->problem, "built-in problem name or problem file (.yaml)")->capture_default_str();
  app->add_option("--out", opt->out, "output directory (default out/run_<problem>)");
  app->add_option("--set", opt->set, "override a problem parameter: name=value (repeatable; passed to optimize)");
  app->add_option("--method", opt->method, "impulsive (default), continuous or first-order (passed to optimize)");
  app->add_option("--seed", opt->seed, "random seed of the initial guess's perturbation (passed to optimize)");
  app->add_option("--N", opt->N, "finite elements (passed to optimize)");
  app->add_option("--P", opt->P, "collocation points per element (passed to optimize)");
  app->add_option("--ipopt", opt->ipopt, "Ipopt option name=value (repeatable; passed to optimize)");
  app->add_option("--task-ipopt", opt->task_ipopt,
                  "Ipopt option of the task stage only, name=value (repeatable; passed to optimize)");
  app->add_option("--engine", opt->engine, "replay engines: saltus, bullet, mujoco, both (saltus and bullet) or all")
      ->capture_default_str();
  app->add_option("--fps", opt->fps, "video frames per second")->capture_default_str();
  app->add_option("--speed", opt->speed,
                  "playback speed, trajectory seconds per video second (default: the whole trajectory in --video-seconds, at most 1)");
  app->add_option("--video-seconds", opt->video_seconds, "video length when --speed is not given")->capture_default_str();
  app->add_option("--width", opt->width, "video width [pixels]")->capture_default_str();
  app->add_option("--height", opt->height, "video height [pixels]")->capture_default_str();
  return {app, [opt] { return run(*opt); }};
}

}  // namespace saltus::cli
