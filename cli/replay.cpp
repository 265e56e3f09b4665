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
#include <sstream>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "collocation/saved_solution.hpp"
#include "saltus/saltus.hpp"

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
  std::string restart = "none";
  double tolerance = 0;  // 0: 10 m/s × dt
  double input_scale = 1.0;
  std::string input_offset;
  std::string bullet_solver = "dantzig";
  std::string out;
  bool allow_changed_problem = false;
};

int replayCommand(const ReplayCliOptions& opt) {
  verify::ReplayOptions o;
  try {
    o.engines = verify::parseEngines(opt.engine);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--engine: ") + e.what());
  }
  try {
    o.feedback = verify::parseFeedback(opt.feedback);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--feedback: ") + e.what());
  }
  try {
    o.restart = verify::parseRestart(opt.restart);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--restart: ") + e.what());
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
  checkOutputTarget("--out", opt.out, OutputTarget::Folder);

  // The solution.
  const collocation::SavedSolution solution = collocation::loadSolution(opt.dir);
  collocation::checkSameProblem(solution, opt.allow_changed_problem);
  if (!solution.problem_changed.empty())
    std::cerr << "saltus replay: warning: " << solution.problem_changed << ": the replay uses the problem as it is now\n";
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

  try {
    verify::checkReplayOptions(o, solution);
  } catch (const std::invalid_argument& e) {
    throw optionError(e);
  }
  const ReplayResult r = verify::replay(solution, o);
  const std::string chart_error = writeReplay(opt.out, r, opt.dir);

  int status = 0;
  for (const verify::EngineReplay& e : r.engines) {
    const std::string name = verify::engineName(e.engine);
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
  app->add_option("--engine", opt->engine, "saltus (default), bullet, mujoco, both (saltus and bullet) or all");
  app->add_option("--dt", opt->dt, "time step [s] (default 1e-4)");
  app->add_option("--theta", opt->theta, "Saltus stepper's theta in [0.5, 1] (default 0.5, midpoint)");
  app->add_option("--feedback", opt->feedback, "none (default: open loop) or pd (tracking on the actuated coordinates)");
  app->add_option("--kp", opt->kp, "PD position gain [N/m or N m/rad] (default 100)");
  app->add_option("--kd", opt->kd, "PD velocity gain [N s/m or N m s/rad] (default 20)");
  app->add_option("--restart", opt->restart,
                  "none (default), mesh: start again from the optimised state at every mesh point (before its jump), so "
                  "each element is checked from its own start (for motions that diverge open loop), or mesh-after-jumps: "
                  "the same from the state after the jump (the optimiser's impulse taken as given)");
  app->add_option("--tolerance", opt->tolerance,
                  "largest allowed position deviation over all coordinates [m or rad] (default 10 m/s x dt: 1e-3 at dt 1e-4); exit 1 above it");
  app->add_option("--input-scale", opt->input_scale, "multiply the optimised inputs (a deliberately wrong input; default 1)");
  app->add_option("--input-offset", opt->input_offset, "add a constant to each input, comma-separated (a deliberately wrong input)");
  app->add_option("--bullet-solver", opt->bullet_solver, "dantzig (default), lemke or si");
  app->add_option("--out", opt->out, "report directory (replay.json, replay.csv, charts)")->required();
  app->add_flag("--allow-changed-problem", opt->allow_changed_problem,
                "replay even when the problem file changed since the solve (against the problem as it is now)");
  return {app, [opt] { return replayCommand(*opt); }};
}

}  // namespace saltus::cli
