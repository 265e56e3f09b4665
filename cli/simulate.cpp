// saltus simulate SCENE: runs the Moreau–Stewart–Trinkle time-stepper (timestepper/stepper.hpp)
// on a scenario (built-in name or file) and writes the trajectory as CSV
// (scene/trajectory_csv.hpp): a row at t = 0 and one after every step (or every N-th: --every,
// --sample-dt), its size estimated and refused above a limit before the run. The file appears
// only when the whole run succeeded. A one-line summary goes to standard error.
#include <cmath>
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
  long every = 1;
  std::optional<double> sample_dt;
  double max_output_mb = 1000;
};

int simulate(const SimulateCliOptions& opt) {
  SimulateOptions options;
  options.dt = opt.dt;
  options.theta = opt.theta;
  options.solver = parseSolverOption(opt.solver);
  options.every = opt.every;
  if (opt.sample_dt) {
    // a whole number of steps, as simulators sample their output
    const double ratio = *opt.sample_dt / opt.dt;
    if (!(ratio >= 1 - 1e-9) || !std::isfinite(ratio) || std::abs(ratio - std::round(ratio)) > 1e-9 * ratio ||
        ratio > 1e15)
      throw UsageError("--sample-dt: expected a whole multiple of --dt " + formatNumber(opt.dt) + " s, got " +
                       formatNumber(*opt.sample_dt) + " s");
    if (opt.every != 1) throw UsageError("--sample-dt and --every: give one of them");
    options.every = static_cast<long>(std::round(ratio));
  }
  if (!(opt.max_output_mb > 0) || !std::isfinite(opt.max_output_mb))
    throw UsageError("--max-output-mb: expected a positive size [MB], got " + formatNumber(opt.max_output_mb));
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
  double bytes = 0;
  try {
    bytes = csvBytesEstimate(scene, options);
  } catch (const std::invalid_argument& e) {
    // a step count from the scene file's duration names the file, from the options the options
    const std::string what = e.what();
    if (!opt.duration && what.find("too many steps") != std::string::npos)
      throw std::runtime_error(scene.source + ": duration: " + formatNumber(scene.duration) + " s at --dt " +
                               formatNumber(opt.dt) + " s is too many steps (expected fewer than 2^53)");
    if (what.find("too many steps") != std::string::npos)
      throw UsageError("--duration " + formatNumber(*opt.duration) + " s at --dt " + formatNumber(opt.dt) +
                       " s: too many steps (expected fewer than 2^53)");
    throw optionError(e);
  }
  // The size is estimated before the run: a mistyped duration is refused, not written at disk speed.
  if (bytes > opt.max_output_mb * 1e6) {
    const long samples = sampleCount(scene, options);
    throw UsageError("--duration: the trajectory would be about " + formatNumber(bytes / 1e6, 3) + " MB (" +
                     std::to_string(samples) + " rows), above --max-output-mb " + formatNumber(opt.max_output_mb) +
                     "; keep fewer rows with --every N or --sample-dt, or raise --max-output-mb");
  }

  std::optional<scene::TrajectoryCsvWriter> writer_or;
  try {
    writer_or.emplace(opt.out, scene::trajectoryLayout(scene));
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("--out ") + e.what());
  }
  scene::TrajectoryCsvWriter& writer = *writer_or;
  const SimulationSummary run = saltus::simulate(scene, options, [&](const SimulationSample& s) { writeSample(writer, s); });
  try {
    writer.commit();
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("--out ") + e.what());
  }

  const timestepper::StepperStats& stats = run.stats;
  std::ostringstream s;
  s << scene.name << ": " << stats.steps << " steps (dt " << formatNumber(opt.dt) << " s to t = "
    << formatNumber(run.end_time) << " s, theta " << formatNumber(opt.theta) << ", " << solverName(options.solver)
    << ") in " << formatNumber(run.wall_seconds * 1e3, 4) << " ms wall ("
    << formatNumber(run.wall_seconds * 1e6 / stats.steps, 4) << " µs per step); LCP failures " << stats.lcp_failures
    << "; largest penetration " << formatNumber(stats.max_penetration, 3) << " m"
    << (scene.limits.empty() ? std::string() : ", of a joint stop " + formatNumber(stats.max_stop_penetration, 3) + " rad or m")
    << "; energy change E_end - E_0 = " << formatNumber(run.energy_end - run.energy_start, 4)
    << " J (E_0 = " << formatNumber(run.energy_start, 4) << " J" << (run.driven ? "; input/belt work included" : "")
    << "); wrote " << opt.out << (options.every > 1 ? " (a row every " + std::to_string(options.every) + " steps)" : "")
    << "\n";
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
  app->add_option("--every", opt->every, "Write the state after every N-th step (and the last)")->capture_default_str();
  app->add_option_function<double>(
      "--sample-dt", [opt](double d) { opt->sample_dt = d; },
      "Write the state every SAMPLE_DT seconds (a whole multiple of --dt; instead of --every)");
  app->add_option("--max-output-mb", opt->max_output_mb,
                  "Refuse a run whose trajectory would exceed this size [MB] (estimated before it runs)")
      ->capture_default_str();
  return {app, [opt] { return simulate(*opt); }};
}

}  // namespace saltus::cli
