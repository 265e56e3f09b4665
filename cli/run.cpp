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
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "saltus/collocation_source.hpp"
#include "cli/common.hpp"
#include "cli/simulation.hpp"

namespace saltus::cli {

namespace {

namespace fs = std::filesystem;

struct RunOptions {
  std::string problem = "pendulum_conveyor";
  std::string out;
  std::vector<std::string> set;
  std::string method;
  std::optional<unsigned> seed;
  std::optional<int> N, P;
  std::vector<std::string> ipopt;
  std::string engine = "both";
  double fps = 30;
  std::optional<double> speed;
  double video_seconds = 4;
  int width = 640, height = 360;
};

// One pipeline step as it ran.
struct PipelineStep {
  PipelineStep(std::string step_name, std::vector<std::string> step_command)
      : name(std::move(step_name)), command(std::move(step_command)) {}
  std::string name;
  std::vector<std::string> command;
  bool ran = false;         // false: skipped (reason in `note`)
  int exit_status = -1;     // −1: killed by a signal or could not start
  double wall_seconds = 0;
  std::string note;         // why it was skipped, or what its exit status means
  std::vector<std::string> outputs;  // files it produced, relative to the run directory
  std::string log;                   // its standard output and error, relative to the run directory
  bool missing_outputs = false;      // exited 0 but did not write what it must
  // Replay only: the step ran to the end (replay.json with every engine completed) and exited 1
  // because Bullet's replay is outside the tolerance, while Saltus's is within it (a finding the
  // report shows, not a failure of the run; see the file comment).
  bool bullet_outside_tolerance = false;
  bool ok() const { return ran && !missing_outputs && (exit_status == 0 || bullet_outside_tolerance); }
};

std::string shellWord(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=.,/:@%") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string commandLine(const std::vector<std::string>& command) {
  std::string line;
  for (const std::string& a : command) line += (line.empty() ? "" : " ") + shellWord(a);
  return line;
}

// Runs step.command with standard output and error into `log_path` (MPLBACKEND=Agg for the
// chart script); records exit status and wall time.
void runPipelineStep(PipelineStep& step, const fs::path& run_dir, const fs::path& log_path) {
  step.log = fs::relative(log_path, run_dir).string();
  std::vector<std::string> args = step.command;
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = chartEnvironment();  // MPLBACKEND=Agg for the chart steps
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::fflush(nullptr);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const std::string& program = step.command[0];
  const int rc = program.find('/') == std::string::npos
                     ? ::posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), envp.data())
                     : ::posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  step.ran = true;
  if (rc != 0) {
    step.exit_status = -1;
    step.note = "could not start " + program + ": " + std::strerror(rc);
    return;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("saltus run: waitpid: " + std::string(std::strerror(errno)));
  step.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (WIFEXITED(status)) {
    step.exit_status = WEXITSTATUS(status);
  } else {
    step.exit_status = -1;
    step.note = "killed by signal " + std::to_string(WTERMSIG(status));
  }
}

// The last lines of a log, for the report of a failed step.
std::string logTail(const fs::path& path, int lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);)
    if (line.find('\r') == std::string::npos) all.push_back(line);  // progress bars redraw with \r
  std::string out;
  for (std::size_t i = all.size() > static_cast<std::size_t>(lines) ? all.size() - lines : 0; i < all.size(); ++i)
    out += all[i] + "\n";
  return out;
}

std::optional<nlohmann::json> readJsonFile(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

std::string jsonNumber(const nlohmann::json& j, const std::string& key, int digits = 4) {
  if (!j.contains(key)) return "—";
  const nlohmann::json& v = j[key];
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) return formatNumber(v.get<double>(), digits);
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

// This program, to run the steps: /proc/self/exe, else argv[0] as the shell found it.
std::string thisProgram() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (!error && !self.empty()) return self.string();
  return "saltus";
}

int run(const RunOptions& opt) {
  if (!(opt.fps > 0) || !std::isfinite(opt.fps) || opt.fps > 1000)
    throw UsageError("--fps: expected frames per second in (0, 1000], got " + formatNumber(opt.fps));
  if (opt.speed && !(*opt.speed > 0 && std::isfinite(*opt.speed)))
    throw UsageError("--speed: expected a positive playback speed, got " + formatNumber(*opt.speed));
  if (!(opt.video_seconds > 0) || !std::isfinite(opt.video_seconds))
    throw UsageError("--video-seconds: expected a positive duration, got " + formatNumber(opt.video_seconds));
  if (opt.width < 2 || opt.height < 2 || opt.width > 8192 || opt.height > 8192 || opt.width % 2 || opt.height % 2)
    throw UsageError("--width/--height: expected even sizes of 2 … 8192 pixels (H.264), got " + std::to_string(opt.width) +
                     "x" + std::to_string(opt.height));
  if (opt.engine != "saltus" && opt.engine != "bullet" && opt.engine != "both")
    throw UsageError("--engine: expected saltus, bullet or both, got '" + opt.engine + "'");
  parseSetOptions(opt.set);  // malformed assignments are usage errors before anything runs

  const std::string problem_word = fs::path(opt.problem).stem().string();
  const fs::path dir = fs::absolute(opt.out.empty() ? "out/run_" + problem_word : opt.out).lexically_normal();
  std::error_code error;
  if (fs::exists(dir, error) && !fs::is_directory(dir, error))
    throw UsageError("--out " + dir.string() + ": exists and is not a directory");
  // A fresh run: the step folders and the report of an earlier run in DIR are removed first, so
  // that nothing stale is reported.
  for (const char* sub : {"optimize", "replay", "render", "charts", "logs"}) fs::remove_all(dir / sub);
  fs::remove(dir / "report.md");
  fs::create_directories(dir / "logs");
  const std::string saltus = thisProgram();
  const fs::path opt_dir = dir / "optimize", replay_dir = dir / "replay", render_dir = dir / "render",
                 chart_dir = dir / "charts";
  std::vector<PipelineStep> steps;
  auto announce = [&](const PipelineStep& s) {
    std::cerr << "saltus run: " << s.name << ": ";
    if (!s.ran)
      std::cerr << "skipped (" << s.note << ")\n";
    else
      std::cerr << (s.ok() ? "ok" : "FAILED (exit status " + std::to_string(s.exit_status) + ")") << " in "
                << formatNumber(s.wall_seconds, 3) << " s" << (s.ok() ? "" : ", log: " + (dir / s.log).string()) << "\n";
  };
  auto existing = [&](PipelineStep& s, const std::vector<fs::path>& files) {
    for (const fs::path& f : files)
      if (fs::exists(f)) s.outputs.push_back(fs::relative(f, dir).string());
  };
  // A step that exits 0 must have written `required`; else it failed.
  auto require = [&](PipelineStep& s, const std::vector<fs::path>& required) {
    if (!s.ran || s.exit_status != 0) return;
    for (const fs::path& f : required)
      if (!fs::exists(f)) {
        s.missing_outputs = true;
        s.note += (s.note.empty() ? "" : "; ") + ("exited 0 but did not write " + fs::relative(f, dir).string());
      }
  };

  // 1. optimize
  PipelineStep optimize{"optimize", {saltus, "optimize", opt.problem, "--out", opt_dir.string()}};
  if (!opt.method.empty()) optimize.command.insert(optimize.command.end(), {"--method", opt.method});
  if (opt.seed) optimize.command.insert(optimize.command.end(), {"--seed", std::to_string(*opt.seed)});
  if (opt.N) optimize.command.insert(optimize.command.end(), {"--N", std::to_string(*opt.N)});
  if (opt.P) optimize.command.insert(optimize.command.end(), {"--P", std::to_string(*opt.P)});
  for (const std::string& s : opt.set) optimize.command.insert(optimize.command.end(), {"--set", s});
  for (const std::string& s : opt.ipopt) optimize.command.insert(optimize.command.end(), {"--ipopt", s});
  std::cerr << "saltus run: " << opt.problem << " -> " << dir.string() << "\n";
  runPipelineStep(optimize, dir, dir / "logs" / "optimize.log");
  existing(optimize, {opt_dir / "summary.json", opt_dir / "trajectory.csv", opt_dir / "variables.csv"});
  require(optimize, {opt_dir / "summary.json", opt_dir / "trajectory.csv", opt_dir / "variables.csv"});
  const std::optional<nlohmann::json> summary = readJsonFile(opt_dir / "summary.json");
  const bool solved = summary && fs::exists(opt_dir / "variables.csv") && fs::exists(opt_dir / "trajectory.csv");
  const bool feasible = solved && summary->value("feasible", false);
  if (optimize.exit_status == 1 && solved) optimize.note = "the solve ended infeasible (files written; later steps use them)";
  announce(optimize);
  steps.push_back(optimize);

  // The trajectory's time range and first impulse, for the playback speed and the still frame.
  double total_time = 0, first_impulse = -1;
  if (solved) {
    try {
      const CollocationSource source = CollocationSource::load(opt_dir.string());
      total_time = source.endTime();
      if (!source.impulses().empty()) first_impulse = source.impulses().front().t;
    } catch (const std::exception& e) {
      std::cerr << "saltus run: cannot read the solution back: " << e.what() << "\n";
    }
  }
  const double speed = opt.speed ? *opt.speed : total_time > 0 ? std::min(1.0, total_time / opt.video_seconds) : 1.0;

  // 2. replay (in Saltus's time-stepper and in Bullet)
  PipelineStep replay{"replay", {saltus, "replay", opt_dir.string(), "--engine", opt.engine, "--out", replay_dir.string()}};
  // 3. render
  const fs::path frames_dir = render_dir / "frames", video = render_dir / "video.mp4", still = render_dir / "still.png";
  PipelineStep render{"render",
                      {saltus, "render", opt_dir.string(), "--out", video.string(), "--frames", frames_dir.string(),
                       "--fps", formatNumber(opt.fps), "--speed", formatNumber(speed, 8), "--width",
                       std::to_string(opt.width), "--height", std::to_string(opt.height)}};
  // 4. charts
  const fs::path chart_png = chart_dir / "trajectory.png", chart_svg = chart_dir / "trajectory.svg";
  PipelineStep charts{"charts", chartCommand("trajectory", (opt_dir / "trajectory.csv").string(), chart_png.string(),
                                                   chart_svg.string())};
  charts.command.insert(charts.command.end(), {"--title", problem_word + " (" + (summary ? jsonNumber(*summary, "method") : opt.method) + ")"});

  if (!solved) {
    for (PipelineStep* s : {&replay, &render, &charts}) s->note = "no solution: the optimize step wrote no summary.json/variables.csv";
  } else {
    fs::create_directories(replay_dir);
    runPipelineStep(replay, dir, dir / "logs" / "replay.log");
    if (replay.exit_status == 2 && logTail(dir / "logs" / "replay.log", 5).find("unknown command") != std::string::npos)
      replay.note = "this saltus has no 'replay' command";
    std::vector<fs::path> replay_files{replay_dir / "replay.json"};
    if (const auto rj = readJsonFile(replay_dir / "replay.json"); rj && rj->contains("charts") && (*rj)["charts"].is_array())
      for (const auto& c : (*rj)["charts"])
        if (c.is_string()) replay_files.push_back(replay_dir / c.get<std::string>());
    existing(replay, replay_files);
    require(replay, {replay_dir / "replay.json"});
    if (const auto rj = readJsonFile(replay_dir / "replay.json");
        replay.exit_status == 1 && rj && rj->contains("engines") && (*rj)["engines"].is_object()) {
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
          charts_present = charts_present && c.is_string() && fs::exists(replay_dir / c.get<std::string>());
      if (completed && saltus_within && bullet_outside && charts_present && !rj->contains("chart_error")) {
        replay.bullet_outside_tolerance = true;
        replay.note = "Bullet's replay is outside the tolerance (Saltus's is within it): a result, see Replay";
      }
    }
    if (fs::is_empty(replay_dir, error)) fs::remove(replay_dir, error);  // nothing written: no empty folder

    fs::create_directories(render_dir);
    runPipelineStep(render, dir, dir / "logs" / "render.log");
    if (render.ok()) {
      // Keep one frame: just after the first impulse (its marker showing), else the middle.
      std::vector<fs::path> frames;
      for (const auto& entry : fs::directory_iterator(frames_dir, error)) frames.push_back(entry.path());
      std::sort(frames.begin(), frames.end());
      if (!frames.empty()) {
        std::size_t k = frames.size() / 2;
        if (first_impulse >= 0)
          k = std::min(frames.size() - 1, static_cast<std::size_t>(std::ceil(first_impulse / speed * opt.fps)) + 2);
        std::error_code rename_error;  // a failure leaves the still missing: the render step is marked failed
        fs::rename(frames[k], still, rename_error);
      }
      fs::remove_all(frames_dir);
    }
    existing(render, {video, still});
    require(render, {video, still});

    fs::create_directories(chart_dir);
    runPipelineStep(charts, dir, dir / "logs" / "charts.log");
    existing(charts, {chart_png, chart_svg});
    require(charts, {chart_png, chart_svg});
  }
  for (PipelineStep* s : {&replay, &render, &charts}) {
    announce(*s);
    steps.push_back(*s);
  }

  // The report.
  const bool all_ok = feasible && std::all_of(steps.begin(), steps.end(), [](const PipelineStep& s) { return s.ok(); });
  std::ostringstream md;
  auto link = [&](const fs::path& file) { return fs::relative(file, dir).string(); };
  auto exists = [&](const fs::path& file) { return fs::exists(file); };
  md << "# Saltus run: " << (summary ? jsonNumber(*summary, "problem") : problem_word) << "\n\n";
  md << "Result: **" << (all_ok ? "ok" : "FAILED") << "**";
  if (!all_ok) {
    std::vector<std::string> why;
    if (solved && !feasible) why.push_back("the solve is infeasible");
    for (const PipelineStep& s : steps)
      if (!s.ok()) why.push_back("step " + s.name + (s.ran ? " failed" : " skipped"));
    md << " (";
    for (std::size_t i = 0; i < why.size(); ++i) md << (i ? "; " : "") << why[i];
    md << ")";
  }
  md << "\n\n";
  if (replay.bullet_outside_tolerance)
    md << "Note: Bullet's replay of the optimised inputs leaves the tolerance while Saltus's stays within it "
          "(table under *Replay*); the run counts this as a measured result, not a failure.\n\n";

  md << "## Problem and solve\n\n";
  if (summary) {
    const nlohmann::json& s = *summary;
    std::string stage_status;
    if (s.contains("stages"))
      for (const auto& st : s["stages"])
        stage_status += (stage_status.empty() ? "" : ", ") + st.value("name", std::string("?")) + ": " +
                        st.value("status", std::string("?"));
    std::string parameters;
    if (s.contains("parameters"))
      for (const auto& [k, v] : s["parameters"].items())
        parameters += (parameters.empty() ? "" : ", ") + k + " = " + (v.is_number() ? formatNumber(v.get<double>()) : v.dump());
    md << "| | |\n| --- | --- |\n";
    md << "| problem | " << jsonNumber(s, "problem") << " (`" << jsonNumber(s, "source") << "`) |\n";
    md << "| parameters | " << (parameters.empty() ? "—" : parameters) << " |\n";
    md << "| method | " << jsonNumber(s, "method") << ", N = " << jsonNumber(s, "N") << " elements, P = " << jsonNumber(s, "P")
       << " |\n";
    md << "| status | " << (feasible ? "feasible" : "**NOT feasible**") << " (" << stage_status << ") |\n";
    md << "| iterations | " << jsonNumber(s, "iterations") << " |\n";
    md << "| wall time | " << jsonNumber(s, "wall_seconds") << " s (" << jsonNumber(s, "evaluation_seconds")
       << " s evaluating functions and derivatives) |\n";
    md << "| largest complementarity product | " << jsonNumber(s, "largest_product") << " (tolerance "
       << jsonNumber(s, "complementarity_tolerance") << ") |\n";
    md << "| mean local error | " << jsonNumber(s, "mean_local_error") << " |\n";
    md << "| objective | " << jsonNumber(s, "objective", 6) << " |\n";
    md << "| trajectory time | " << jsonNumber(s, "total_time") << " s |\n";
    if (s.contains("note")) md << "| note | " << jsonNumber(s, "note") << " |\n";
    md << "\nFiles: ";
    for (std::size_t i = 0; i < optimize.outputs.size(); ++i)
      md << (i ? ", " : "") << "[" << fs::path(optimize.outputs[i]).filename().string() << "](" << optimize.outputs[i] << ")";
    md << "\n\n";
  } else {
    md << "The optimize step wrote no summary (exit status " << optimize.exit_status << "); see [its log]("
       << optimize.log << ").\n\n";
  }

  md << "## Trajectory\n\n";
  if (exists(chart_png)) {
    md << "Positions, velocities (a velocity jump is a dashed vertical segment), contact forces at the collocation "
          "points and impulses (stems, right-hand axis); dotted lines are element boundaries.\n\n";
    md << "![trajectory chart](" << link(chart_png) << ")\n\n";
    if (exists(chart_svg)) md << "[SVG](" << link(chart_svg) << ")\n\n";
  } else {
    md << "No trajectory chart: the charts step " << (charts.ran ? "failed" : "was skipped") << ".\n\n";
  }

  md << "## Replay in Saltus and Bullet\n\n";
  const std::optional<nlohmann::json> replay_json = readJsonFile(replay_dir / "replay.json");
  if (replay_json && replay_json->contains("engines") && (*replay_json)["engines"].is_object()) {
    const nlohmann::json& rj = *replay_json;
    md << "The optimised inputs replayed open loop from the initial state";
    if (rj.contains("tolerance")) md << "; tolerance " << jsonNumber(rj, "tolerance");
    md << " ([replay.json](" << link(replay_dir / "replay.json") << ")).\n\n";
    md << "| engine | max position deviation | final | RMS | within tolerance | max penetration |\n"
          "| --- | --- | --- | --- | --- | --- |\n";
    for (const auto& [engine, e] : rj["engines"].items())
      md << "| " << engine << " | " << jsonNumber(e, "max_position_deviation") << " | "
         << jsonNumber(e, "final_position_deviation") << " | " << jsonNumber(e, "rms_position_deviation") << " | "
         << jsonNumber(e, "within_tolerance") << " | " << jsonNumber(e, "max_penetration") << " |\n";
    md << "\n";
    if (rj.contains("charts") && rj["charts"].is_array())
      for (const auto& c : rj["charts"]) {
        if (!c.is_string()) continue;
        const fs::path file = replay_dir / c.get<std::string>();
        if (!exists(file)) {
          md << "Chart `" << c.get<std::string>() << "` is named by replay.json but missing.\n\n";
          continue;
        }
        // PNG images shown; SVG (the same chart) and other files linked.
        const std::string ext = file.extension().string();
        if (ext == ".png" || ext == ".jpg")
          md << "![" << file.stem().string() << "](" << link(file) << ")\n\n";
        else
          md << "[" << file.filename().string() << "](" << link(file) << ")\n\n";
      }
  } else {
    md << "No replay results: the replay step " << (replay.ran ? "failed" : "was skipped");
    if (!replay.note.empty()) md << " (" << replay.note << ")";
    if (replay.ran) md << "; see [its log](" << replay.log << ")";
    md << ".\n\n";
  }

  md << "## Video\n\n";
  if (exists(video)) {
    md << "[video.mp4](" << link(video) << "): " << opt.width << "×" << opt.height << ", " << formatNumber(opt.fps)
       << " fps, playback speed " << formatNumber(speed, 3)
       << " (trajectory seconds per video second); states between the collocation points from the collocation "
          "polynomials, impulses marked at their instants.\n\n";
    if (exists(still)) md << "![still frame](" << link(still) << ")\n\n";
  } else {
    md << "No video: the render step " << (render.ran ? "failed" : "was skipped") << ".\n\n";
  }

  md << "## Steps\n\n| step | status | wall time | command | outputs | log |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const PipelineStep& s : steps) {
    std::string status = !s.ran                         ? "skipped"
                         : s.ok() && s.exit_status == 0 ? "ok"
                         : s.ok()                       ? "ok (exit " + std::to_string(s.exit_status) + ")"
                                                        : "failed (exit " + std::to_string(s.exit_status) + ")";
    if (!s.note.empty()) status += ": " + s.note;
    std::string outputs;
    for (const std::string& o : s.outputs) outputs += (outputs.empty() ? "" : "<br>") + ("[" + o + "](" + o + ")");
    std::string command = commandLine(s.command);
    std::string escaped;
    for (char c : command) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
    md << "| " << s.name << " | " << status << " | " << (s.ran ? formatNumber(s.wall_seconds, 3) + " s" : "—") << " | `"
       << escaped << "` | " << (outputs.empty() ? "—" : outputs) << " | "
       << (!s.ran || !exists(dir / s.log) ? "—" : fs::file_size(dir / s.log) == 0 ? "(empty)" : "[" + s.log + "](" + s.log + ")")
       << " |\n";
  }
  for (const PipelineStep& s : steps)
    if (s.ran && !s.ok()) {
      md << "\n### " << s.name << " failed\n\n```\n" << logTail(dir / s.log, 12) << "```\n";
    }

  writeFileAtomically((dir / "report.md").string(), md.str());
  std::cerr << "saltus run: " << (all_ok ? "done" : "FAILED") << ": " << (dir / "report.md").string() << "\n";
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
  app->add_option("--engine", opt->engine, "replay engines: saltus, bullet or both")->capture_default_str();
  app->add_option("--fps", opt->fps, "video frames per second")->capture_default_str();
  app->add_option("--speed", opt->speed,
                  "playback speed, trajectory seconds per video second (default: the whole trajectory in --video-seconds, at most 1)");
  app->add_option("--video-seconds", opt->video_seconds, "video length when --speed is not given")->capture_default_str();
  app->add_option("--width", opt->width, "video width [pixels]")->capture_default_str();
  app->add_option("--height", opt->height, "video height [pixels]")->capture_default_str();
  return {app, [opt] { return run(*opt); }};
}

}  // namespace saltus::cli
