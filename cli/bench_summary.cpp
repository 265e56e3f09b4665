// saltus bench summary: every scene (the built-in ones, or --scenes), every engine that can build
// it, Saltus at θ = 1 and ½: the stability map and the work-precision chart of each in
// OUT/<scene>/ (cli/bench.cpp), then OUT/summary.csv and summary.md, read from those files: per
// scene and engine the largest grid step `ok` in every cell of the map at it and at every smaller
// step, and the cost per step at the largest step whose error is at most --target.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

#include "cli/bench_commands.hpp"
#include "cli/bench_runs.hpp"
#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "scene/cleanup.hpp"
#include "scene/scenario.hpp"

namespace saltus::cli::bench {

namespace {

using saltus::scene::loadScene;
using saltus::timestepper::LcpMethod;
namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();


// The rows of a bench CSV by column name (comment lines skipped; a quoted field may hold commas).
std::vector<std::map<std::string, std::string>> readBenchCsv(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot read what the bench wrote");
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (c == '"') {
        if (quoted && i + 1 < line.size() && line[i + 1] == '"') fields.back() += '"', ++i;
        else quoted = !quoted;
      } else if (c == ',' && !quoted) {
        fields.emplace_back();
      } else {
        fields.back() += c;
      }
    }
    if (header.empty()) {
      header = fields;
      continue;
    }
    std::map<std::string, std::string> row;
    for (std::size_t k = 0; k < header.size() && k < fields.size(); ++k) row[header[k]] = fields[k];
    rows.push_back(std::move(row));
  }
  return rows;
}

struct SummaryRow {
  std::string scene, engine, note;
  double stable_dt = kNaN;  // the largest grid dt at which it and every smaller dt are ok in every cell
  double dt_at_target = kNaN, ns_at_target = kNaN, best_error = kNaN;
};

}  // namespace

int summary(const SummaryOptions& opt) {
  if (!(opt.target > 0)) throw UsageError("--target: expected a positive error");
  if (!(opt.min_time >= 0) || !std::isfinite(opt.min_time))
    throw UsageError("--min-time: expected a non-negative number of seconds");
  std::vector<std::string> names;
  if (opt.scenes == "all") {
    names = scene::builtinSceneNames();
  } else {
    names = splitCommaList(opt.scenes);
  }
  std::vector<Scene> scenes;
  for (const std::string& name : names) {
    try {
      scenes.push_back(loadScene(name));
    } catch (const std::exception& e) {
      throw UsageError("--scenes: '" + name + "': " + e.what());
    }
  }
  checkOutputTarget("--out", opt.out, OutputTarget::Folder);
  // Everything is written into a temporary folder beside --out and moved into it at the end: an
  // interrupted or failed summary leaves no part of itself (scene::ScopedTemporary).
  const scene::ScopedTemporary work(scene::temporaryName(fs::path(opt.out).lexically_normal().string()));
  const fs::path out(work.path());
  std::vector<SummaryRow> rows;
  for (const Scene& scene : scenes) {
    // The engines that can build the scene; the others get a row saying why not.
    std::string list;
    std::vector<SummaryRow> refused;
    for (EngineKind kind : {EngineKind::Saltus, EngineKind::Bullet, EngineKind::Mujoco}) {
      try {
        verify::makeEngine(scene, engineSetup(kind, 1e-3, 1.0, LcpMethod::Lemke, verify::BulletSolver::MlcpDantzig, true));
        list += (list.empty() ? "" : ",") + std::string(verify::engineName(kind));
      } catch (const std::invalid_argument& e) {
        SummaryRow r;
        r.scene = scene.name;
        r.engine = verify::engineName(kind);
        r.note = std::string("not built: ") + e.what();
        refused.push_back(r);
      }
    }
    for (double theta : {1.0, 0.5}) {
      const fs::path dir = theta == 1.0 ? out / scene.name : out / scene.name / "theta_half";
      const std::string engines = theta == 1.0 ? list : "saltus";
      StabilityOptions so;
      so.scene = scene.name;
      so.engine = engines;
      so.theta = theta;
      so.out = dir.string();
      stability(so);
      WorkPrecisionOptions wo;
      wo.scene = scene.name;
      wo.engine = engines;
      wo.theta = theta;
      wo.min_time = opt.min_time;
      wo.out = dir.string();
      workPrecision(wo);
      const auto stab = readBenchCsv(dir / "stability.csv");
      const auto wp = readBenchCsv(dir / "work_precision.csv");
      for (const std::string& engine : std::vector<std::string>{"saltus", "bullet", "mujoco"}) {
        if (engines.find(engine) == std::string::npos) continue;
        SummaryRow r;
        r.scene = scene.name;
        r.engine = engine == "saltus" ? (theta == 1.0 ? "saltus θ=1" : "saltus θ=½") : engine;
        std::map<double, bool> ok_at;  // dt -> every cell ok
        for (const auto& row : stab)
          if (row.at("engine") == engine) {
            const double dt = std::stod(row.at("dt"));
            const bool ok = row.at("outcome") == "ok";
            ok_at[dt] = ok_at.count(dt) ? ok_at[dt] && ok : ok;
          }
        for (const auto& [dt, ok] : ok_at) {
          if (!ok) break;
          r.stable_dt = dt;
        }
        for (const auto& row : wp)
          if (row.at("engine") == engine) {
            const double dt = std::stod(row.at("dt")), error = std::stod(row.at("error"));
            if (std::isfinite(error) && (std::isnan(r.best_error) || error < r.best_error)) r.best_error = error;
            if (std::isfinite(error) && error <= opt.target && (std::isnan(r.dt_at_target) || dt > r.dt_at_target)) {
              r.dt_at_target = dt;
              r.ns_at_target = std::stod(row.at("ns_per_step"));
            }
          }
        rows.push_back(r);
      }
    }
    rows.insert(rows.end(), refused.begin(), refused.end());
  }
  const auto cell = [](double x, int digits) { return std::isnan(x) ? std::string("—") : formatNumber(x, digits); };
  std::ostringstream csv, md;
  csv << "# saltus bench summary: per scene and engine, the largest grid dt stable in every cell of its map "
         "(and at every smaller dt), and the cost per step at the largest dt whose error is at most "
      << formatNumber(opt.target) << " (work-precision); maps and charts in the scene's folder\n"
      << "scene,engine,largest_stable_dt,dt_at_target,ns_per_step_at_target,best_error,note\n";
  md << "| scene | engine | largest stable dt [s] | dt with error ≤ " << formatNumber(opt.target)
     << " [s] | ns per step there | smallest error |\n| --- | --- | ---: | ---: | ---: | ---: |\n";
  for (const SummaryRow& r : rows) {
    csv << r.scene << "," << r.engine << "," << (std::isnan(r.stable_dt) ? "" : formatNumber(r.stable_dt)) << ","
        << (std::isnan(r.dt_at_target) ? "" : formatNumber(r.dt_at_target)) << ","
        << (std::isnan(r.ns_at_target) ? "" : formatNumber(r.ns_at_target, 4)) << ","
        << (std::isnan(r.best_error) ? "" : formatNumber(r.best_error, 3)) << "," << csvField(r.note) << "\n";
    if (!r.note.empty())
      md << "| " << r.scene << " | " << r.engine << " | " << r.note << " | | | |\n";
    else
      md << "| " << r.scene << " | " << r.engine << " | " << cell(r.stable_dt, 6) << " | " << cell(r.dt_at_target, 6)
         << " | " << cell(r.ns_at_target, 4) << " | " << cell(r.best_error, 3) << " |\n";
  }
  writeFileAtomically((out / "summary.csv").string(), csv.str());
  writeFileAtomically((out / "summary.md").string(), md.str());
  // Into place: each entry replaces the one of that name an earlier summary left (and nothing else).
  const fs::path dir = prepareOutputDirectory(opt.out);
  for (const auto& entry : fs::directory_iterator(out)) {
    const fs::path target = dir / entry.path().filename();
    fs::remove_all(target);
    fs::rename(entry.path(), target);
  }
  std::cerr << "summary: wrote " << (dir / "summary.csv").string() << ", " << (dir / "summary.md").string()
            << " and a folder per scene" << std::endl;
  return 0;
}

}  // namespace saltus::cli::bench
