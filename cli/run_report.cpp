// The report of `saltus run` (cli/run_pipeline.hpp).
#include <algorithm>
#include <fstream>
#include <sstream>

#include "cli/run_pipeline.hpp"
#include "cli/simulation.hpp"

namespace saltus::cli::pipeline {

bool RunSteps::allOk() const {
  for (const PipelineStep* s : all())
    if (!s->ok()) return false;
  return true;
}

namespace {

std::string shellWord(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=.,/:@%") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

std::string commandLine(const std::vector<std::string>& command) {
  std::string line;
  for (const std::string& a : command) line += (line.empty() ? "" : " ") + shellWord(a);
  return line;
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

std::string jsonNumber(const nlohmann::json& j, const std::string& key, int digits) {
  if (!j.contains(key)) return "—";
  const nlohmann::json& v = j[key];
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) return formatNumber(v.get<double>(), digits);
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

std::string runReport(const RunFolders& f, const RunFacts& facts, const RunSteps& steps) {
  const bool all_ok = facts.feasible && steps.allOk();
  std::ostringstream md;
  auto link = [&](const fs::path& file) { return fs::relative(file, f.dir).string(); };
  auto exists = [&](const fs::path& file) { return fs::exists(file); };
  md << "# Saltus run: " << (facts.summary ? jsonNumber(*facts.summary, "problem") : facts.problem_word) << "\n\n";
  md << "Result: **" << (all_ok ? "ok" : "FAILED") << "**";
  if (!all_ok) {
    std::vector<std::string> why;
    if (facts.solved && !facts.feasible) why.push_back("the solve is infeasible");
    for (const PipelineStep* step : steps.all())
      if (const PipelineStep& s = *step; !s.ok()) why.push_back("step " + s.name + (s.ran ? " failed" : " skipped"));
    md << " (";
    for (std::size_t i = 0; i < why.size(); ++i) md << (i ? "; " : "") << why[i];
    md << ")";
  }
  md << "\n\n";
  if (steps.replay.bullet_outside_tolerance)
    md << "Note: Bullet's replay of the optimised inputs leaves the tolerance while Saltus's stays within it "
          "(table under *Replay*); the run counts this as a measured result, not a failure.\n\n";

  md << "## Problem and solve\n\n";
  if (facts.summary) {
    const nlohmann::json& s = *facts.summary;
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
    md << "| status | " << (facts.feasible ? "feasible" : "**NOT feasible**") << " (" << stage_status << ") |\n";
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
    for (std::size_t i = 0; i < steps.optimize.outputs.size(); ++i)
      md << (i ? ", " : "") << "[" << fs::path(steps.optimize.outputs[i]).filename().string() << "](" << steps.optimize.outputs[i] << ")";
    md << "\n\n";
  } else {
    md << "The optimize step wrote no summary (exit status " << steps.optimize.exit_status << "); see [its log]("
       << steps.optimize.log << ").\n\n";
  }

  md << "## Trajectory\n\n";
  if (exists(f.chart_png)) {
    md << "Positions, velocities (a velocity jump is a dashed vertical segment), contact forces at the collocation "
          "points and impulses (stems, right-hand axis); dotted lines are element boundaries.\n\n";
    md << "![trajectory chart](" << link(f.chart_png) << ")\n\n";
    if (exists(f.chart_svg)) md << "[SVG](" << link(f.chart_svg) << ")\n\n";
  } else {
    md << "No trajectory chart: the charts step " << (steps.charts.ran ? "failed" : "was skipped") << ".\n\n";
  }

  md << "## Replay in Saltus and Bullet\n\n";
  const std::optional<nlohmann::json> replay_json = readJsonFile(f.replay / "replay.json");
  if (replay_json && replay_json->contains("engines") && (*replay_json)["engines"].is_object()) {
    const nlohmann::json& rj = *replay_json;
    md << "The optimised inputs replayed open loop from the initial state";
    if (rj.contains("tolerance")) md << "; tolerance " << jsonNumber(rj, "tolerance");
    md << " ([replay.json](" << link(f.replay / "replay.json") << ")).\n\n";
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
        const fs::path file = f.replay / c.get<std::string>();
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
    md << "No replay results: the replay step " << (steps.replay.ran ? "failed" : "was skipped");
    if (!steps.replay.note.empty()) md << " (" << steps.replay.note << ")";
    if (steps.replay.ran) md << "; see [its log](" << steps.replay.log << ")";
    md << ".\n\n";
  }

  md << "## Video\n\n";
  if (exists(f.video)) {
    md << "[video.mp4](" << link(f.video) << "): " << facts.width << "×" << facts.height << ", " << formatNumber(facts.fps)
       << " fps, playback speed " << formatNumber(facts.speed, 3)
       << " (trajectory seconds per video second); states between the collocation points from the collocation "
          "polynomials, impulses marked at their instants.\n\n";
    if (exists(f.still)) md << "![still frame](" << link(f.still) << ")\n\n";
  } else {
    md << "No video: the render step " << (steps.render.ran ? "failed" : "was skipped") << ".\n\n";
  }

  md << "## Steps\n\n| step | status | wall time | command | outputs | log |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const PipelineStep* step : steps.all()) {
    const PipelineStep& s = *step;
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
       << (!s.ran || !exists(f.dir / s.log) ? "—" : fs::file_size(f.dir / s.log) == 0 ? "(empty)" : "[" + s.log + "](" + s.log + ")")
       << " |\n";
  }
  for (const PipelineStep* s : steps.all())
    if (s->ran && !s->ok()) {
      md << "\n### " << s->name << " failed\n\n```\n" << logTail(f.dir / s->log, 12) << "```\n";
    }

  return md.str();
}

}  // namespace saltus::cli::pipeline
