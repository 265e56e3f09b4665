// The pieces of `saltus run` (cli/run.cpp): a pipeline step as it ran, the run's folders, and the
// Markdown report written from them (cli/run_report.cpp).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace saltus::cli::pipeline {

namespace fs = std::filesystem;

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

// The run's folders and the files its steps must write.
struct RunFolders {
  explicit RunFolders(const fs::path& run_dir)
      : dir(run_dir), optimize(dir / "optimize"), replay(dir / "replay"), render(dir / "render"), charts(dir / "charts"),
        frames(render / "frames"), video(render / "video.mp4"), still(render / "still.png"),
        chart_png(charts / "trajectory.png"), chart_svg(charts / "trajectory.svg") {}
  fs::path dir, optimize, replay, render, charts, frames, video, still, chart_png, chart_svg;
};

// What the report says besides the steps.
struct RunFacts {
  std::string problem_word;                // the problem's name or file stem
  std::optional<nlohmann::json> summary;   // optimize/summary.json
  bool solved = false, feasible = false;   // the solve wrote its files / is feasible
  double speed = 1, fps = 30;              // playback speed, video frames per second
  int width = 0, height = 0;               // video size [pixels]
};

// The steps in order: optimize, replay, render, charts.
struct RunSteps {
  PipelineStep optimize, replay, render, charts;
  std::vector<const PipelineStep*> all() const { return {&optimize, &replay, &render, &charts}; }
  bool allOk() const;
};

// A command line as a shell would read it back (words quoted where needed).
std::string commandLine(const std::vector<std::string>& command);
// The last lines of a log, for the report of a failed step.
std::string logTail(const fs::path& path, int lines);
// A JSON file, or nothing when it is missing or not valid JSON.
std::optional<nlohmann::json> readJsonFile(const fs::path& path);
// A value of a JSON object as report text: "yes"/"no", an integer, a number of `digits` digits,
// a string; "—" when the key is missing.
std::string jsonNumber(const nlohmann::json& j, const std::string& key, int digits = 4);

// report.md: result, problem and solve, trajectory chart, replay table and charts, video and
// still frame, and every step's command, status, time, outputs and log; links only files that exist.
std::string runReport(const RunFolders& folders, const RunFacts& facts, const RunSteps& steps);

}  // namespace saltus::cli::pipeline
