// saltus::replay and saltus::writeReplay (saltus/saltus.hpp): a solution replayed in the
// engines, and its files: replay.csv (the time series), replay.json (the report) and the charts.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "collocation/saved_solution.hpp"
#include "saltus/format.hpp"
#include "saltus/saltus.hpp"
#include "scene/atomic_file.hpp"

namespace saltus {

namespace {

namespace fs = std::filesystem;
using verify::ReplayResult;

nlohmann::ordered_json eventJson(const verify::ContactEvent& e, const ReplayResult& r) {
  return {{"kind", verify::eventKindName(e.kind)}, {"contact", r.contacts.at(e.contact)}, {"t", e.t}};
}

// Non-finite numbers as strings ("nan", "inf"), which JSON has not.
nlohmann::ordered_json replayNumber(double x) {
  if (std::isfinite(x)) return x;
  return formatNumber(x);
}

std::string seriesCsv(const ReplayResult& r) {
  std::ostringstream s;
  s.precision(10);
  s << "# saltus replay: optimised and replayed trajectories\n";
  s << "# problem: " << r.problem << "\n# method: " << r.method << "\n# dt: " << r.options.dt
    << "\n# feedback: " << verify::feedbackName(r.options.feedback)
    << "\n# restart: " << verify::restartName(r.options.restart) << "\n# tolerance: " << r.tolerance;
  s << "\n# coordinates:";
  for (const std::string& c : r.coordinates) s << ' ' << c;
  s << "\n# engines:";
  for (const verify::EngineReplay& e : r.engines) s << ' ' << verify::engineName(e.engine);
  s << "\n# events:";
  for (const verify::ContactEvent& e : r.optimised_events) s << ' ' << verify::eventKindName(e.kind) << '@' << e.t;
  s << "\nt";
  for (const std::string& c : r.coordinates) s << ",opt.q." << csvField(c) << ",opt.v." << csvField(c);
  for (const std::string& c : r.inputs) s << ",opt.u." << csvField(c);
  s << ",opt.energy";
  for (const verify::EngineReplay& e : r.engines) {
    const std::string n = verify::engineName(e.engine);
    for (const std::string& c : r.coordinates)
      s << ',' << n << ".q." << csvField(c) << ',' << n << ".dq." << csvField(c) << ',' << n << ".dv." << csvField(c);
    s << ',' << n << ".energy," << n << ".penetration";
  }
  s << '\n';
  const int nv = static_cast<int>(r.coordinates.size());
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    s << r.t[k];
    for (int i = 0; i < nv; ++i) s << ',' << r.q_opt[k][i] << ',' << r.v_opt[k][i];
    for (Eigen::Index i = 0; i < r.u_applied[k].size(); ++i) s << ',' << r.u_applied[k][i];
    s << ',' << r.energy_opt[k];
    for (const verify::EngineReplay& e : r.engines) {
      const bool have = k < e.series.t.size();  // a failed engine stops early
      for (int i = 0; i < nv; ++i) {
        if (have)
          s << ',' << e.series.q[k][i] << ',' << e.series.dq[k][i] << ',' << e.series.dv[k][i];
        else
          s << ",,,";
      }
      if (have)
        s << ',' << e.series.energy[k] << ',' << e.series.penetration[k];
      else
        s << ",,";
    }
    s << '\n';
  }
  return s.str();
}

nlohmann::ordered_json reportJson(const ReplayResult& r, const std::string& dir) {
  nlohmann::ordered_json j;
  j["solution"] = fs::absolute(dir).lexically_normal().string();
  j["problem"] = r.problem;
  j["source"] = r.source;
  j["method"] = r.method;
  j["end_time"] = r.end_time;
  j["dt"] = r.options.dt;
  j["steps"] = r.steps;
  j["theta"] = r.options.theta;
  j["input_rule"] = "mean of the collocation input polynomial over each step (Gauss-Legendre, exact)";
  j["feedback"] = {{"kind", verify::feedbackName(r.options.feedback)},
                   {"kp", r.options.kp},
                   {"kd", r.options.kd},
                   {"coordinates", r.options.feedback == verify::Feedback::Pd ? r.inputs : std::vector<std::string>{}}};
  j["restart"] = verify::restartName(r.options.restart);
  if (r.options.input_scale != 1.0 || r.options.input_offset.size() > 0) {
    j["input_modified"] = {{"scale", r.options.input_scale},
                           {"offset", std::vector<double>(r.options.input_offset.data(),
                                                          r.options.input_offset.data() + r.options.input_offset.size())}};
  }
  j["tolerance"] = r.tolerance;
  j["tolerance_rule"] = r.options.tolerance > 0       ? "given (--tolerance)"
                        : r.method_allowance > 0    ? "10 m/s x dt + the first-order scheme's error (max |v| x longest step)"
                                                    : "10 m/s x dt (default)";
  if (r.method_allowance > 0) j["method_allowance"] = r.method_allowance;
  j["tolerance_applies_to"] = "max_position_deviation: largest |q_i - q*_i| over steps and coordinates [m or rad]";
  j["within_tolerance"] = r.withinTolerance();
  j["coordinates"] = r.coordinates;
  j["inputs"] = r.inputs;
  j["contacts"] = r.contacts;
  j["mesh_times"] = r.mesh_times;
  for (const scene::Surface& s : r.surfaces) {
    nlohmann::ordered_json sj{{"name", s.name}, {"velocity_schedule", nlohmann::json::array()}};
    for (const scene::Surface::Step& step : s.velocity_schedule)
      sj["velocity_schedule"].push_back({{"t", step.time}, {"velocity", {step.velocity.x(), step.velocity.y(), step.velocity.z()}}});
    j["surfaces"].push_back(sj);
  }
  j["event_thresholds"] = {{"gap", r.options.gap_threshold},
                           {"jump", r.options.jump_threshold},
                           {"approach", r.options.approach_threshold},
                           {"match_window", r.options.match_window}};
  j["optimised_events"] = nlohmann::json::array();
  for (const verify::ContactEvent& e : r.optimised_events) j["optimised_events"].push_back(eventJson(e, r));
  j["optimised_energy"] = {{"start", r.energy_opt.front()}, {"end", r.energy_opt.back()}};

  j["engines"] = nlohmann::ordered_json::object();
  for (const verify::EngineReplay& e : r.engines) {
    nlohmann::ordered_json ej;
    ej["completed"] = e.completed;
    if (!e.message.empty()) ej["message"] = e.message;
    ej["steps"] = e.steps;
    ej["max_position_deviation"] = replayNumber(e.max_position_deviation);
    ej["t_max_position_deviation"] = e.t_max_position_deviation;
    ej["final_position_deviation"] = replayNumber(e.final_position_deviation);
    ej["rms_position_deviation"] = replayNumber(e.rms_position_deviation);
    ej["max_velocity_deviation"] = replayNumber(e.max_velocity_deviation);
    ej["final_velocity_deviation"] = replayNumber(e.final_velocity_deviation);
    ej["within_tolerance"] = e.within_tolerance;
    ej["max_penetration"] = replayNumber(e.max_penetration);
    ej["energy"] = {{"start", replayNumber(e.energy_start)}, {"end", replayNumber(e.energy_end)}};
    for (const verify::CoordinateDeviation& d : e.coordinates)
      ej["coordinates"].push_back({{"coordinate", d.coordinate},
                                   {"max_position_deviation", replayNumber(d.max_q)},
                                   {"t_max_position_deviation", d.t_max_q},
                                   {"final_position_deviation", replayNumber(d.final_q)},
                                   {"rms_position_deviation", replayNumber(d.rms_q)},
                                   {"max_velocity_deviation", replayNumber(d.max_v)},
                                   {"final_velocity_deviation", replayNumber(d.final_v)},
                                   {"rms_velocity_deviation", replayNumber(d.rms_v)}});
    int matched = 0;
    ej["event_matches"] = nlohmann::json::array();
    for (const verify::EventMatch& m : e.matches) {
      nlohmann::ordered_json mj = eventJson(m.optimised, r);
      mj["matched"] = m.matched;
      if (m.matched) {
        mj["t_replayed"] = m.replayed.t;
        mj["dt"] = m.dt;
        ++matched;
      }
      ej["event_matches"].push_back(mj);
    }
    ej["events_matched"] = matched;
    ej["events_optimised"] = static_cast<int>(e.matches.size());
    ej["events"] = nlohmann::json::array();
    for (const verify::ContactEvent& ev : e.events) ej["events"].push_back(eventJson(ev, r));
    ej["unmatched_events"] = nlohmann::json::array();
    for (const verify::ContactEvent& ev : e.unmatched) ej["unmatched_events"].push_back(eventJson(ev, r));
    if (e.engine == verify::EngineKind::Bullet) {
      ej["solver"] = verify::bulletSolverName(r.options.bullet.solver);
      ej["mlcp_fallbacks"] = e.mlcp_fallbacks;
      ej["approximations"] = e.approximations;
    } else if (e.engine == verify::EngineKind::Mujoco) {
      ej["warnings"] = e.mujoco_warnings;
      ej["approximations"] = e.approximations;
    } else {
      ej["lcp_failures"] = e.lcp_failures;
    }
    j["engines"][verify::engineName(e.engine)] = ej;
  }
  j["series_csv"] = "replay.csv";
  return j;
}

}  // namespace

ReplayResult replay(const std::string& solution_dir, const verify::ReplayOptions& options, bool allow_changed_problem) {
  const collocation::SavedSolution solution = collocation::loadSolution(solution_dir);
  collocation::checkSameProblem(solution, allow_changed_problem);
  return verify::replay(solution, options);
}

std::string writeReplay(const std::string& out_dir, const ReplayResult& result, const std::string& solution_dir,
                        bool charts) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir))
    throw std::runtime_error(out_dir + ": cannot create the output folder (" + ec.message() + ")");
  const fs::path out(out_dir);
  const fs::path csv = out / "replay.csv";
  scene::writeFileAtomically(csv.string(), seriesCsv(result));

  // Charts (stale ones removed first, so a failed chart step leaves none); then the JSON, which
  // lists the charts that were drawn.
  std::vector<std::string> drawn;
  std::string chart_error;
  for (const std::string kind : {"deviation", "energy"}) {
    const fs::path png = out / ("replay_" + kind + ".png"), svg = out / ("replay_" + kind + ".svg");
    fs::remove(png, ec);
    fs::remove(svg, ec);
    if (!charts || !chart_error.empty()) continue;
    try {
      drawChart("replay-" + kind, csv.string(), png.string(), svg.string());
      drawn.push_back(png.filename().string());
      drawn.push_back(svg.filename().string());
    } catch (const std::exception& e) {
      chart_error = e.what();
    }
  }
  nlohmann::ordered_json j = reportJson(result, solution_dir);
  j["charts"] = drawn;
  if (!chart_error.empty()) j["chart_error"] = chart_error;
  scene::writeFileAtomically((out / "replay.json").string(), j.dump(2) + "\n");
  return chart_error;
}

}  // namespace saltus
