// saltus simulate SCENE: runs the Moreau–Stewart–Trinkle time-stepper (timestepper/stepper.hpp)
// on a scenario (built-in name or file) and writes the trajectory as CSV
// (scene/trajectory_csv.hpp): a row at t = 0 and one after every step. The file appears
// only when the whole run succeeded. A one-line summary goes to standard error.
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "saltus/saltus.hpp"

namespace saltus::cli {

namespace {

struct SimulateCliOptions {
  std::string scene;
  double dt = 1e-3;
  std::optional<double> duration;
  std::vector<std::string> set;
  std::string solver = "lemke";
  double theta = 1.0;
  std::string out;
};

int simulate(const SimulateCliOptions& opt) {
  SimulateOptions options;
  options.dt = opt.dt;
  options.theta = opt.theta;
  options.solver = parseSolverOption(opt.solver);
  if (opt.duration) {
    if (!(*opt.duration > 0))
      throw UsageError("--duration: expected a positive time [s], got " + formatNumber(*opt.duration));
    options.duration = *opt.duration;
  }
  // The API's messages start with the option's name.
  try {
    checkSimulateOptions(options);
  } catch (const std::invalid_argument& e) {
    throw optionError(e);
  }
  const scene::Scene scene = loadScene(opt.scene, parseSetOptions(opt.set));
  try {
    stepCount(options.duration > 0 ? options.duration : scene.duration, options.dt);
  } catch (const std::invalid_argument& e) {
    throw optionError(e);
  }

  scene::TrajectoryCsvWriter writer(opt.out, scene::trajectoryLayout(scene));
  const SimulationSummary run = saltus::simulate(scene, options, [&](const SimulationSample& s) { writeSample(writer, s); });
  writer.commit();

  const timestepper::StepperStats& stats = run.stats;
  std::ostringstream s;
  s << scene.name << ": " << stats.steps << " steps (dt " << formatNumber(opt.dt) << " s to t = "
    << formatNumber(run.end_time) << " s, theta " << formatNumber(opt.theta) << ", " << solverName(options.solver)
    << ") in " << formatNumber(run.wall_seconds * 1e3, 4) << " ms wall ("
    << formatNumber(run.wall_seconds * 1e6 / stats.steps, 4) << " µs per step); LCP failures " << stats.lcp_failures
    << "; largest penetration " << formatNumber(stats.max_penetration, 3)
    << " m; energy change E_end - E_0 = " << formatNumber(run.energy_end - run.energy_start, 4)
    << " J (E_0 = " << formatNumber(run.energy_start, 4) << " J" << (run.driven ? "; input/belt work included" : "")
    << "); wrote " << opt.out << "\n";
  std::cerr << s.str() << std::flush;
  return 0;
}

}  // namespace

Command addSimulateCommand(CLI::App& saltus) {
  auto opt = std::make_shared<SimulateCliOptions>();
  CLI::App* app = saltus.add_subcommand(
      "simulate",
      "Simulate a scene with the Moreau-Stewart-Trinkle time-stepper and write the trajectory as CSV "
      "(t, q.*, v.*, contact.<name>.gap/vn/vt/pn/pt). Summary on stderr.");
  app->add_option("SCENE", opt->scene, "Built-in scene name (ball_drop, block_slide, ...) or scenario file path")
      ->required();
  app->add_option("--dt", opt->dt, "Time step [s]")->capture_default_str();
  app->add_option_function<double>(
      "--duration", [opt](double d) { opt->duration = d; }, "Simulated time [s] (default: the scene's duration)");
  app->add_option("--set", opt->set, "Override a scene parameter: --set name=value (repeatable)")
      ->allow_extra_args(false);
  app->add_option("--solver", opt->solver, "LCP solver: lemke or pgs")->capture_default_str();
  app->add_option("--theta", opt->theta, "θ of the θ-method, in [0.5, 1] (1: Stewart-Trinkle, 0.5: Moreau midpoint)")
      ->capture_default_str();
  app->add_option("--out", opt->out, "Trajectory CSV to write")->required();
  return {app, [opt] { return simulate(*opt); }};
}

}  // namespace saltus::cli
