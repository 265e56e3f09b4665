// saltus replay DIR: replays a 'saltus optimize' solution (DIR/variables.csv) from its initial
// state in the Saltus time-stepper and/or Bullet, driven by the optimised inputs (the collocation
// polynomials' mean over each step), optionally with PD tracking of the optimised states
// (verify/replay.hpp has the rules). Writes into --out:
//   replay.json                    the report: per engine the position and velocity deviation
//                                  (maximum, final, RMS, per coordinate), the contact events matched
//                                  with the optimised ones, penetration, energy; Bullet's
//                                  approximations and MLCP fallbacks
//   replay.csv                     the time series (optimised and replayed states, deviations,
//                                  energy, penetration)
//   replay_deviation.png/.svg      |q − q*| per coordinate and engine over time (log), and q
//   replay_energy.png/.svg         energy over time
// Exit status: 0 when every engine stays within --tolerance (maximum position deviation over all
// coordinates, metres and radians alike), 1 when one does not (a line on standard error says
// which and by how much), when an engine fails, or when the charts cannot be drawn (CSV and JSON
// kept); 2 for usage errors.
//
// Default tolerance 10 m/s × dt (1 mm or 1 mrad at the default dt 1e-4 s): an open-loop replay
// of a feasible solution differs from it at first order in dt (an impact resolved up to one step
// late shifts the position by up to |Δv| dt, 2.1e-4 m for the bounce of point_mass_drop at
// dt 1e-4); verify/replay.hpp has the measurements behind the factor, the README the figures.
// A first-order solution's default tolerance adds its own step error (max |q̇| × longest step).
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "collocation/saved_solution.hpp"
#include "verify/replay.hpp"

namespace saltus::cli {

namespace {

namespace fs = std::filesystem;
using verify::ReplayResult;

struct ReplayCliOptions {
  std::string dir;
  std::string engine = "saltus";
  double dt = 1e-4;
  double theta = 0.5;
  std::string feedback = "none";
  double kp = 100, kd = 20;
  double tolerance = 0;  // 0: 10 m/s × dt
  double input_scale = 1.0;
  std::string input_offset;
  std::string bullet_solver = "dantzig";
  std::string out;
};

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
    << "\n# feedback: " << verify::feedbackName(r.options.feedback) << "\n# tolerance: " << r.tolerance;
  s << "\n# coordinates:";
  for (const std::string& c : r.coordinates) s << ' ' << c;
  s << "\n# engines:";
  for (const verify::EngineReplay& e : r.engines) s << ' ' << verify::replayEngineName(e.engine);
  s << "\n# events:";
  for (const verify::ContactEvent& e : r.optimised_events) s << ' ' << verify::eventKindName(e.kind) << '@' << e.t;
  s << "\nt";
  for (const std::string& c : r.coordinates) s << ",opt.q." << csvField(c) << ",opt.v." << csvField(c);
  for (const std::string& c : r.inputs) s << ",opt.u." << csvField(c);
  s << ",opt.energy";
  for (const verify::EngineReplay& e : r.engines) {
    const std::string n = verify::replayEngineName(e.engine);
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
    if (e.engine == verify::ReplayEngine::Bullet) {
      ej["solver"] = verify::bulletSolverName(r.options.bullet.solver);
      ej["mlcp_fallbacks"] = e.mlcp_fallbacks;
      ej["approximations"] = e.approximations;
    } else {
      ej["lcp_failures"] = e.lcp_failures;
    }
    j["engines"][verify::replayEngineName(e.engine)] = ej;
  }
  j["series_csv"] = "replay.csv";
  return j;
}

int replayCommand(const ReplayCliOptions& opt) {
  verify::ReplayOptions o;
  try {
    o.engines = verify::parseReplayEngines(opt.engine);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--engine: ") + e.what());
  }
  try {
    o.feedback = verify::parseFeedback(opt.feedback);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--feedback: ") + e.what());
  }
  try {
    o.bullet.solver = verify::parseBulletSolver(opt.bullet_solver);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--bullet-solver: ") + e.what());
  }
  checkStepOptions("--dt", opt.dt, opt.theta);
  if (!(opt.kp >= 0) || !std::isfinite(opt.kp)) throw UsageError("--kp: expected a non-negative gain, got " + formatNumber(opt.kp));
  if (!(opt.kd >= 0) || !std::isfinite(opt.kd)) throw UsageError("--kd: expected a non-negative gain, got " + formatNumber(opt.kd));
  if (!(opt.tolerance >= 0) || !std::isfinite(opt.tolerance))
    throw UsageError("--tolerance: expected a positive deviation [m or rad] (0: 10 m/s × dt), got " + formatNumber(opt.tolerance));
  if (!std::isfinite(opt.input_scale)) throw UsageError("--input-scale: expected a finite number");
  o.dt = opt.dt;
  o.theta = opt.theta;
  o.kp = opt.kp;
  o.kd = opt.kd;
  o.tolerance = opt.tolerance;
  o.input_scale = opt.input_scale;
  if (fs::exists(opt.out) && !fs::is_directory(opt.out)) throw UsageError("--out " + opt.out + ": exists and is not a directory");

  // The solution.
  std::error_code ec;
  const collocation::SavedSolution solution = collocation::loadSolution(opt.dir);
  const int nu = static_cast<int>(solution.problem->inputs.size());
  if (!opt.input_offset.empty()) {
    if (nu == 0) throw UsageError("--input-offset: the problem has no inputs");
    // Signed values, one per input (parseNumberList refuses negatives).
    std::vector<double> values;
    std::stringstream in(opt.input_offset);
    for (std::string token; std::getline(in, token, ',');) {
      std::size_t used = 0;
      double x = 0;
      try {
        x = std::stod(token, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != token.size() || !std::isfinite(x))
        throw UsageError("--input-offset: '" + token + "' is not a number (expected one per input, comma-separated)");
      values.push_back(x);
    }
    if (static_cast<int>(values.size()) != nu)
      throw UsageError("--input-offset: expected " + std::to_string(nu) + " values (one per input), got " +
                       std::to_string(values.size()));
    o.input_offset = Eigen::Map<const Eigen::VectorXd>(values.data(), nu);
  }

  const ReplayResult r = verify::replay(solution, o);

  fs::create_directories(opt.out, ec);
  if (ec || !fs::is_directory(opt.out)) throw std::runtime_error(opt.out + ": cannot create the output folder (" + ec.message() + ")");
  const fs::path out(opt.out);
  const fs::path csv = out / "replay.csv";
  writeFileAtomically(csv.string(), seriesCsv(r));

  // Charts (stale ones removed first, so a failed chart step leaves none); then the JSON, which
  // lists the charts that were drawn.
  std::vector<std::string> charts;
  std::string chart_error;
  for (const std::string kind : {"deviation", "energy"}) {
    const fs::path png = out / ("replay_" + kind + ".png"), svg = out / ("replay_" + kind + ".svg");
    fs::remove(png, ec);
    fs::remove(svg, ec);
    if (!chart_error.empty()) continue;
    try {
      runChartScript("replay-" + kind, csv.string(), png.string(), svg.string());
      charts.push_back(png.filename().string());
      charts.push_back(svg.filename().string());
    } catch (const std::exception& e) {
      chart_error = e.what();
    }
  }
  nlohmann::ordered_json j = reportJson(r, opt.dir);
  j["charts"] = charts;
  if (!chart_error.empty()) j["chart_error"] = chart_error;
  writeFileAtomically((out / "replay.json").string(), j.dump(2) + "\n");

  int status = 0;
  for (const verify::EngineReplay& e : r.engines) {
    const std::string name = verify::replayEngineName(e.engine);
    if (!e.completed) {
      std::cerr << "saltus replay: " << e.message << "\n";
      status = 1;
    }
    std::cerr << "saltus replay: " << name << ": max position deviation " << formatNumber(e.max_position_deviation, 3)
              << " at t = " << formatNumber(e.t_max_position_deviation, 4) << " s (final "
              << formatNumber(e.final_position_deviation, 3) << ", RMS " << formatNumber(e.rms_position_deviation, 3)
              << "), penetration " << formatNumber(e.max_penetration, 3) << " m, events matched "
              << [&] {
                   int m = 0;
                   for (const verify::EventMatch& x : e.matches) m += x.matched;
                   return m;
                 }()
              << "/" << e.matches.size() << "\n";
    if (e.completed && !e.within_tolerance) {
      std::cerr << "saltus replay: " << name << " exceeds the tolerance: max position deviation "
                << formatNumber(e.max_position_deviation, 4) << " > " << formatNumber(r.tolerance, 4) << " (coordinate ";
      const verify::CoordinateDeviation* worst = &e.coordinates.front();
      for (const verify::CoordinateDeviation& d : e.coordinates)
        if (d.max_q > worst->max_q) worst = &d;
      std::cerr << worst->coordinate << ", t = " << formatNumber(worst->t_max_q, 4) << " s)\n";
      status = 1;
    }
  }
  if (!chart_error.empty()) {
    std::cerr << "saltus replay: " << chart_error << " (replay.csv and replay.json are written)\n";
    status = 1;
  }
  std::cerr << "saltus replay: " << r.problem << " -> " << opt.out << "/replay.json\n";
  return status;
}

}  // namespace

Command addReplayCommand(CLI::App& saltus) {
  auto opt = std::make_shared<ReplayCliOptions>();
  CLI::App* app = saltus.add_subcommand(
      "replay", "Replay an optimised trajectory's inputs in the Saltus time-stepper and/or Bullet and report the deviation");
  app->add_option("dir", opt->dir, "a 'saltus optimize --out' directory (variables.csv)")->required();
  app->add_option("--engine", opt->engine, "saltus (default), bullet or both");
  app->add_option("--dt", opt->dt, "time step [s] (default 1e-4)");
  app->add_option("--theta", opt->theta, "Saltus stepper's theta in [0.5, 1] (default 0.5, midpoint)");
  app->add_option("--feedback", opt->feedback, "none (default: open loop) or pd (tracking on the actuated coordinates)");
  app->add_option("--kp", opt->kp, "PD position gain [N/m or N m/rad] (default 100)");
  app->add_option("--kd", opt->kd, "PD velocity gain [N s/m or N m s/rad] (default 20)");
  app->add_option("--tolerance", opt->tolerance,
                  "largest allowed position deviation over all coordinates [m or rad] (default 10 m/s x dt: 1e-3 at dt 1e-4); exit 1 above it");
  app->add_option("--input-scale", opt->input_scale, "multiply the optimised inputs (a deliberately wrong input; default 1)");
  app->add_option("--input-offset", opt->input_offset, "add a constant to each input, comma-separated (a deliberately wrong input)");
  app->add_option("--bullet-solver", opt->bullet_solver, "dantzig (default), lemke or si");
  app->add_option("--out", opt->out, "report directory (replay.json, replay.csv, charts)")->required();
  return {app, [opt] { return replayCommand(*opt); }};
}

}  // namespace saltus::cli
