// saltus bench: measurements of the time-stepper (timestepper/stepper.hpp) on a scene.
//
//   work-precision  sweeps the time step; for each dt the error against the scene's exact
//                   answer (cli/bench_runs.hpp: timestepper/analytic.hpp and
//                   timestepper/sticking_motion.hpp) or, without one, against a reference run at
//                   dt_min/16 with θ = ½, and the cost (CPU seconds per simulated
//                   second, wall ns per step; stepping only, no I/O). DIR/work_precision.csv and a
//                   log-log chart DIR/work_precision.png/.svg.
//   stability       a grid over large time steps, high friction and high restitution (the scene's
//                   `friction` / `restitution` / `mass_ratio` parameters, where it has them); each
//                   run classified by verify/run_outcome.hpp. DIR/stability.csv and a grid chart
//                   DIR/stability.png/.svg.
//
//   per-step        ns per step of each engine at one dt on several built-in scenes (interleaved
//                   rounds, fastest kept), their ratio and errors; CSV on standard output.
//   summary         every scene and engine at once (cli/bench_summary.cpp).
//
// --engine saltus|bullet|mujoco|both|all (or a comma list): the saltus time-stepper, Bullet's
// btMultiBodyDynamicsWorld and MuJoCo built from the same scene (verify/), tuned settings; rows
// carry an `engine` column. Default saltus.
//
// Charts are drawn by scripts/charts.py (python3 + matplotlib); when that fails the command
// says so and exits 1, with the CSV written.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/bench_runs.hpp"
#include "cli/bench_commands.hpp"
#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "scene/scenario.hpp"
#include "verify/bullet_world.hpp"
#include "verify/run_outcome.hpp"

namespace saltus::cli {

namespace {

using namespace saltus::timestepper;
using namespace saltus::cli::bench;
using saltus::scene::loadScene;
namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();


const char* kDefaultFrictions = "0.3,0.6,1,2,5";
const char* kDefaultRestitutions = "0,0.25,0.5,0.75,0.9,1";
const char* kDefaultMassRatios = "1,10,100,1000,10000";

// Every dt of a grid gives a valid step count over `duration` (before any work).
void checkStepCounts(const std::string& option, const std::vector<double>& dts, double duration) {
  for (double dt : dts) {
    try {
      stepCount(duration, dt);
    } catch (const std::invalid_argument& e) {
      throw UsageError(option + ": " + e.what());
    }
  }
}

// The output folder, made when the results are ready to write (checkOutputTarget has checked
// it before the work), so an interrupted or failed run leaves no empty folder.
}  // namespace

fs::path bench::prepareOutputDirectory(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw std::runtime_error(dir + ": cannot create the output folder (" + ec.message() + ")");
  return fs::path(dir);
}

namespace {

// CSV first (already written), then the charts; stale charts of an earlier run are removed first
// so that a failed chart step leaves none.
void drawCharts(const std::string& kind, const fs::path& csv, const fs::path& png, const fs::path& svg) {
  std::error_code ec;
  fs::remove(png, ec);
  fs::remove(svg, ec);
  drawChart(kind, csv.string(), png.string(), svg.string());
}

// ---------------------------------------------------------------------------------------------
// work-precision

}  // namespace

int bench::workPrecision(const WorkPrecisionOptions& opt) {
  checkStepOptions("--theta", 1.0, opt.theta);
  const LcpMethod solver = parseSolverOption(opt.solver);
  const std::vector<EngineKind> engines = parseEngineOption(opt.engine);
  const verify::BulletSolver bullet_solver = parseBulletSolverOption(opt.bullet_solver);
  const bool locate = !opt.no_locate_impacts;
  std::vector<double> dts = parseNumberList("--dts", opt.dts, true);
  std::sort(dts.begin(), dts.end(), std::greater<>());
  dts.erase(std::unique(dts.begin(), dts.end()), dts.end());
  if (opt.duration && !(*opt.duration > 0)) throw UsageError("--duration: expected a positive time [s]");
  if (!(opt.min_time >= 0) || !std::isfinite(opt.min_time))
    throw UsageError("--min-time: expected a non-negative number of seconds");
  const std::map<std::string, double> overrides = parseSetOptions(opt.set);

  const Scene scene = loadScene(opt.scene, overrides);
  const double duration = opt.duration.value_or(scene.duration);
  checkStepCounts("--dts", dts, duration);
  checkOutputTarget("--out", opt.out, OutputTarget::Folder);
  ErrorModel model = makeErrorModel(scene, dts, duration, solver);

  std::ostringstream csv;
  csv << "# saltus bench work-precision\n"
      << "# scene: " << scene.name << " (" << scene.source << "); parameters: " << parameterList(scene) << "\n"
      << "# method: ";
  for (std::size_t i = 0; i < engines.size(); ++i)
    csv << (i ? "; " : "") << describe(engineSetup(engines[i], dts[0], opt.theta, solver, bullet_solver, locate));
  csv << ", duration " << formatNumber(duration) << " s\n";
  if (std::find(engines.begin(), engines.end(), EngineKind::Bullet) != engines.end()) {
    const verify::BulletWorld probe(scene, engineSetup(EngineKind::Bullet, dts[0], opt.theta, solver, bullet_solver, locate).bullet);
    for (const std::string& a : probe.approximations()) csv << "# bullet approximation: " << a << "\n";
  }
  csv << "# error: " << model.description << "\n"
      << "# timing: stepping only (no I/O), fastest of repeated runs (at least " << formatNumber(opt.min_time)
      << " s CPU per dt); cpu_seconds_per_simulated_second from CLOCK_PROCESS_CPUTIME_ID, ns_per_step from "
         "steady_clock\n"
      << "# solver_failures: saltus LCP failures; bullet MLCP solves that fell back to sequential impulse\n"
      << "engine,dt,error,cpu_seconds_per_simulated_second,ns_per_step,steps,solver_failures\n";
  bool any_failed = false;
  for (EngineKind engine : engines)
    for (double dt : dts) {
      const EngineOptions setup = engineSetup(engine, dt, opt.theta, solver, bullet_solver, locate);
      const long steps = stepCount(duration, dt);
      const RecordedRun run = recordRun(scene, setup, steps, model.tracked);
      const double error = runError(model, run);
      Timing timing;
      if (!run.failed) timing = timeRuns(scene, setup, steps, opt.min_time);
      const double simulated = steps * dt;
      const double cpu_per_s = timing.cpu / simulated, ns_per_step = timing.wall * 1e9 / steps;
      csv << verify::engineName(engine) << "," << formatNumber(dt, 10) << "," << formatNumber(error, 8) << ","
          << formatNumber(cpu_per_s, 6) << "," << formatNumber(ns_per_step, 6) << "," << run.steps << ","
          << run.failures << "\n";
      std::cerr << "work-precision: " << scene.name << " " << verify::engineName(engine) << " dt " << formatNumber(dt) << ": ";
      if (run.failed) {
        any_failed = true;
        std::cerr << "FAILED after " << run.steps << " steps: " << run.message << "\n";
      } else {
        std::cerr << "error " << formatNumber(error, 4) << ", " << formatNumber(cpu_per_s, 4)
                  << " CPU s per simulated s, " << formatNumber(ns_per_step, 4) << " ns per step (" << steps
                  << " steps, best of " << timing.repetitions << ")"
                  << (run.failures ? ", " + std::to_string(run.failures) + " solver failures" : std::string()) << "\n";
      }
    }
  const fs::path dir = prepareOutputDirectory(opt.out);
  const fs::path csv_path = dir / "work_precision.csv";
  writeFileAtomically(csv_path.string(), csv.str());
  std::cerr << "work-precision: wrote " << csv_path.string() << (any_failed ? " (some runs failed: error nan)" : "")
            << std::endl;
  drawCharts("work-precision", csv_path, dir / "work_precision.png", dir / "work_precision.svg");
  std::cerr << "work-precision: wrote " << (dir / "work_precision.png").string() << ", "
            << (dir / "work_precision.svg").string() << std::endl;
  return 0;
}

namespace {

// ---------------------------------------------------------------------------------------------
// per-step: the cost of one step of each engine at the same dt on several scenes, and their errors

struct PerStepOptions {
  std::string scenes = "ball_drop,block_slide,pendulum_conveyor";
  std::string engine = "all";
  double dt = 1e-3;
  int repeat = 5;
  double min_time = 0.2;
  std::string solver = "lemke";
  std::string bullet_solver = "dantzig";
  double theta = 1.0;
  bool no_locate_impacts = false;
};

int perStep(const PerStepOptions& opt) {
  checkStepOptions("--dt", opt.dt, opt.theta);
  const LcpMethod solver = parseSolverOption(opt.solver);
  const verify::BulletSolver bullet_solver = parseBulletSolverOption(opt.bullet_solver);
  std::vector<EngineKind> engines = parseEngineOption(opt.engine);
  const bool locate = !opt.no_locate_impacts;
  if (opt.repeat < 1) throw UsageError("--repeat: expected a positive count");
  if (!(opt.min_time >= 0) || !std::isfinite(opt.min_time))
    throw UsageError("--min-time: expected a non-negative number of seconds");
  const std::vector<std::string> names = splitCommaList(opt.scenes);
  // All scenes read before the first line of output, a bad one named under its option.
  std::vector<Scene> scenes;
  for (const std::string& name : names) {
    try {
      scenes.push_back(loadScene(name));
      stepCount(scenes.back().duration, opt.dt);
    } catch (const std::exception& e) {
      throw UsageError("--scenes: '" + name + "': " + e.what());
    }
  }
  std::cout << "# saltus bench per-step: dt " << formatNumber(opt.dt) << " s; ns per step = fastest of " << opt.repeat
            << " rounds (each the fastest run of at least " << formatNumber(opt.min_time)
            << " s CPU), the engines interleaved; error as in work-precision; over_saltus = ns per step / saltus'\n";
  for (EngineKind engine : engines)
    std::cout << "# " << describe(engineSetup(engine, opt.dt, opt.theta, solver, bullet_solver, locate)) << "\n";
  std::cout << "scene,engine,ns_per_step,over_saltus,error,failures,note\n";
  const double inf = std::numeric_limits<double>::infinity();
  for (const Scene& scene : scenes) {
    const long steps = stepCount(scene.duration, opt.dt);
    ErrorModel model = makeErrorModel(scene, {opt.dt}, scene.duration, solver);
    const std::size_t n = engines.size();
    std::vector<double> ns(n, inf), error(n, kNaN);
    std::vector<long> failures(n, 0);
    std::vector<std::string> note(n);  // an engine that cannot build the scene: why
    for (std::size_t e = 0; e < n; ++e) {
      const EngineOptions setup = engineSetup(engines[e], opt.dt, opt.theta, solver, bullet_solver, locate);
      try {
        verify::makeEngine(scene, setup);
      } catch (const std::invalid_argument& refused) {
        note[e] = refused.what();
        continue;
      }
      const RecordedRun run = recordRun(scene, setup, steps, model.tracked);
      if (run.failed) throw std::runtime_error(scene.name + ": the " + verify::engineName(setup.kind) + " run failed: " + run.message);
      error[e] = runError(model, run);
      failures[e] = run.failures;
    }
    for (int round = 0; round < opt.repeat; ++round)
      for (std::size_t e = 0; e < n; ++e) {
        if (!note[e].empty()) continue;
        const EngineOptions setup = engineSetup(engines[e], opt.dt, opt.theta, solver, bullet_solver, locate);
        ns[e] = std::min(ns[e], timeRuns(scene, setup, steps, opt.min_time).wall * 1e9 / steps);
      }
    double saltus_ns = kNaN;
    for (std::size_t e = 0; e < n; ++e)
      if (engines[e] == EngineKind::Saltus && note[e].empty()) saltus_ns = ns[e];
    for (std::size_t e = 0; e < n; ++e) {
      const bool ran = note[e].empty();
      std::cout << scene.name << "," << verify::engineName(engines[e]) << "," << (ran ? formatNumber(ns[e], 5) : "") << ","
                << (ran && !std::isnan(saltus_ns) ? formatNumber(ns[e] / saltus_ns, 3) : "") << ","
                << (ran ? formatNumber(error[e], 5) : "") << "," << (ran ? std::to_string(failures[e]) : "") << ","
                << csvField(ran ? "" : "not built: " + note[e]) << std::endl;
    }
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// stability

struct StabilityRun {
  std::string outcome = "ok";
  std::string message;
  long steps = 0;
  double t_end = 0, max_penetration = 0, energy_gain = 0;
};

// One cell of the map: the run recorded, then judged by verify::classifyRun (verify/run_outcome.hpp).
StabilityRun stabilityRun(const Scene& scene, const EngineOptions& setup, long steps, const verify::RunCriteria& criteria) {
  verify::RunRecord record;
  const std::unique_ptr<Engine> sim = verify::makeEngine(scene, setup);
  Engine& stepper = *sim;
  record.addEnergy(stepper.energy());
  try {
    for (long i = 0; i < steps; ++i) {
      stepper.step();
      if (!record.addEnergy(stepper.energy())) {
        record.message = "energy is not finite at t = " + formatNumber(stepper.time()) + " s";
        break;
      }
    }
  } catch (const SimulationError& e) {
    const bool finite = stepper.q().allFinite() && stepper.v().allFinite();
    const std::string what = e.what();
    record.end = !finite ? verify::RunEnd::NotFinite
                 : what.find("LCP") != std::string::npos ? verify::RunEnd::LcpFailure : verify::RunEnd::OtherError;
    record.message = what;
  }
  record.max_penetration = stepper.maxPenetration();
  record.solver_fallbacks = setup.kind == EngineKind::Bullet ? stepper.failures() : 0;
  const verify::RunOutcome judged = verify::classifyRun(record, criteria);
  StabilityRun r;
  r.outcome = judged.outcome;
  r.message = judged.message;
  r.steps = stepper.steps();
  r.t_end = stepper.time();
  r.max_penetration = record.max_penetration;
  r.energy_gain = criteria.conservative ? record.energyDrift() : record.energyGain();
  return r;
}

}  // namespace

int bench::stability(const StabilityOptions& opt) {
  checkStepOptions("--theta", 1.0, opt.theta);
  const LcpMethod solver = parseSolverOption(opt.solver);
  const std::vector<EngineKind> engines = parseEngineOption(opt.engine);
  const verify::BulletSolver bullet_solver = parseBulletSolverOption(opt.bullet_solver);
  const bool locate = !opt.no_locate_impacts;
  std::vector<double> dts = parseNumberList("--dts", opt.dts, true);
  std::sort(dts.begin(), dts.end());
  dts.erase(std::unique(dts.begin(), dts.end()), dts.end());
  if (opt.duration && !(*opt.duration > 0)) throw UsageError("--duration: expected a positive time [s]");
  const std::map<std::string, double> overrides = parseSetOptions(opt.set);
  const Scene base = loadScene(opt.scene, overrides);

  // The grid's parameter axes: those of friction, restitution and mass ratio the scene has.
  const auto axis = [&](const char* name, const char* option, const std::optional<std::string>& given, const char* defaults) {
    std::vector<double> values;
    if (!base.parameters.count(name)) {
      if (given)
        throw UsageError(std::string(option) + ": scene " + base.name + " has no parameter '" + name +
                         "' (its parameters: " + parameterList(base) + ")");
      return values;
    }
    values = parseNumberList(option, given.value_or(defaults), false);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    return values;
  };
  const std::vector<double> frictions = axis("friction", "--frictions", opt.frictions, kDefaultFrictions);
  const std::vector<double> restitutions = axis("restitution", "--restitutions", opt.restitutions, kDefaultRestitutions);
  const std::vector<double> mass_ratios = axis("mass_ratio", "--mass-ratios", opt.mass_ratios, kDefaultMassRatios);
  for (double r : mass_ratios)
    if (!(r > 0)) throw UsageError("--mass-ratios: " + formatNumber(r) + " is not positive");
  for (double e : restitutions)
    if (e > 1) throw UsageError("--restitutions: " + formatNumber(e) + " is not in [0, 1]");
  const bool exempt = isDriven(base);
  verify::RunCriteria criteria;
  criteria.energy_checked = !exempt;
  criteria.conservative = base.contacts.empty() && base.limits.empty() && !exempt;
  criteria.fallbacks_fail = true;  // only Bullet records them
  const double duration = opt.duration.value_or(base.duration);
  checkStepCounts("--dts", dts, duration);
  checkOutputTarget("--out", opt.out, OutputTarget::Folder);

  std::ostringstream csv;
  csv << "# saltus bench stability\n"
      << "# scene: " << base.name << " (" << base.source << "); parameters: " << parameterList(base) << "\n"
      << "# method: ";
  for (std::size_t i = 0; i < engines.size(); ++i)
    csv << (i ? "; " : "") << describe(engineSetup(engines[i], 1e-3, opt.theta, solver, bullet_solver, locate));
  csv << ", duration " << formatNumber(duration) << " s\n"
      << "# grid: dt x " << (frictions.empty() ? "" : "friction x ") << (restitutions.empty() ? "" : "restitution x ")
      << (mass_ratios.empty() ? "" : "mass_ratio x ")
      << "(empty column: the scene has no such parameter)\n"
      << "# outcome: ok | lcp_failure (SimulationError from the LCP solver) | nan (state not finite) | error (other "
         "SimulationError) | solver_fallback (bullet: ok but MLCP solves fell back to sequential impulse) | "
         "penetration (largest penetration > "
      << formatNumber(criteria.penetration_limit) << " m or rad) | "
      << (criteria.conservative ? "drift (no contact, stop or input: energy away from E_0 by more than " +
                                      formatNumber(criteria.drift_tolerance) + " relative to |E_0|, either way)"
                                : "energy_gain (energy above E_0 by more than " + formatNumber(criteria.energy_tolerance) +
                                      " relative to |E_0|" +
                                      (exempt ? "; not checked here: the scene has a moving surface or an input" : "") + ")")
      << "\n"
      << (criteria.conservative ? "# energy_gain: here the drift, the largest |E - E_0| / |E_0|\n" : "")
      << "engine,dt,friction,restitution,mass_ratio,outcome,max_penetration,energy_gain,steps,t_end,message\n";
  std::map<std::string, int> counts;
  const std::vector<double> none{kNaN};
  for (EngineKind engine : engines)
  for (double dt : dts)
    for (double mu : frictions.empty() ? none : frictions)
      for (double e : restitutions.empty() ? none : restitutions)
      for (double ratio : mass_ratios.empty() ? none : mass_ratios) {
        std::map<std::string, double> o = overrides;
        if (!std::isnan(mu)) o["friction"] = mu;
        if (!std::isnan(e)) o["restitution"] = e;
        if (!std::isnan(ratio)) o["mass_ratio"] = ratio;
        const Scene scene = loadScene(opt.scene, o);
        const StabilityRun r = stabilityRun(scene, engineSetup(engine, dt, opt.theta, solver, bullet_solver, locate),
                                            stepCount(duration, dt), criteria);
        ++counts[std::string(verify::engineName(engine)) + " " + r.outcome];
        csv << verify::engineName(engine) << "," << formatNumber(dt, 10) << "," << (std::isnan(mu) ? "" : formatNumber(mu, 10)) << ","
            << (std::isnan(e) ? "" : formatNumber(e, 10)) << "," << (std::isnan(ratio) ? "" : formatNumber(ratio, 10)) << ","
            << r.outcome << ","
            << formatNumber(r.max_penetration, 6) << "," << formatNumber(r.energy_gain, 6) << "," << r.steps << ","
            << formatNumber(r.t_end, 10) << "," << csvField(r.message) << "\n";
      }
  const fs::path dir = prepareOutputDirectory(opt.out);
  const fs::path csv_path = dir / "stability.csv";
  writeFileAtomically(csv_path.string(), csv.str());
  std::string summary;
  for (const auto& [outcome, n] : counts) summary += (summary.empty() ? "" : ", ") + outcome + " " + std::to_string(n);
  std::cerr << "stability: " << base.name << ": " << summary << "; wrote " << csv_path.string() << std::endl;
  drawCharts("stability", csv_path, dir / "stability.png", dir / "stability.svg");
  std::cerr << "stability: wrote " << (dir / "stability.png").string() << ", " << (dir / "stability.svg").string()
            << std::endl;
  return 0;
}

namespace {

void addCommonOptions(CLI::App* app, BenchOptions& opt) {
  app->add_option("SCENE", opt.scene, "Built-in scene name or scenario file path")->required();
  app->add_option("--set", opt.set, "Override a scene parameter: --set name=value (repeatable)")
      ->allow_extra_args(false);
  app->add_option("--theta", opt.theta, "θ of the θ-method, in [0.5, 1]")->capture_default_str();
  app->add_flag("--no-locate-impacts", opt.no_locate_impacts,
                "Saltus: resolve impacts at the start of the step instead of at their located time within it");
  app->add_option("--solver", opt.solver, "LCP solver of the saltus stepper: lemke or pgs")->capture_default_str();
  app->add_option("--engine", opt.engine, "Engine: saltus, bullet (btMultiBodyDynamicsWorld), mujoco, both (saltus and bullet) or all")
      ->capture_default_str();
  app->add_option("--bullet-solver", opt.bullet_solver, "Bullet's solver: dantzig, lemke (MLCP) or si")
      ->capture_default_str();
  app->add_option_function<double>(
      "--duration", [&opt](double d) { opt.duration = d; }, "Simulated time [s] (default: the scene's duration)");
  app->add_option("--out", opt.out, "Output folder (created when missing)")->required();
}


}  // namespace

Command addBenchCommand(CLI::App& saltus) {
  CLI::App* bench = saltus.add_subcommand("bench", "Measure the time-stepper: work-precision and stability sweeps.");
  bench->require_subcommand(1);

  auto wp = std::make_shared<WorkPrecisionOptions>();
  CLI::App* wp_app = bench->add_subcommand(
      "work-precision",
      "Sweep dt: error against the analytic answer (or a reference run at dt_min/16, theta 1/2) vs CPU time per "
      "simulated second. Writes OUT/work_precision.csv, .png, .svg.");
  addCommonOptions(wp_app, *wp);
  wp_app->add_option("--dts", wp->dts, "Time steps, comma-separated [s]")->capture_default_str();
  wp_app->add_option("--min-time", wp->min_time, "CPU seconds to spend timing each dt (fastest run kept)")
      ->capture_default_str();

  auto st = std::make_shared<StabilityOptions>();
  CLI::App* st_app = bench->add_subcommand(
      "stability",
      "Grid over large dt, high friction and high restitution (where the scene has those parameters); each run "
      "ends ok, lcp_failure, nan, energy_gain or penetration. Writes OUT/stability.csv, .png, .svg.");
  addCommonOptions(st_app, *st);
  st_app->add_option("--dts", st->dts, "Time steps, comma-separated [s]")->capture_default_str();
  st_app->add_option_function<std::string>(
      "--frictions", [st](const std::string& s) { st->frictions = s; },
      std::string("Values of the scene's 'friction' parameter (default ") + kDefaultFrictions + ")");
  st_app->add_option_function<std::string>(
      "--restitutions", [st](const std::string& s) { st->restitutions = s; },
      std::string("Values of the scene's 'restitution' parameter (default ") + kDefaultRestitutions + ")");
  st_app->add_option_function<std::string>(
      "--mass-ratios", [st](const std::string& s) { st->mass_ratios = s; },
      std::string("Values of the scene's 'mass_ratio' parameter (default ") + kDefaultMassRatios + ")");

  auto ps = std::make_shared<PerStepOptions>();
  CLI::App* ps_app = bench->add_subcommand(
      "per-step",
      "ns per step of each engine at the same dt on built-in scenes (interleaved, fastest of --repeat rounds), "
      "their ratio to saltus and their errors; a CSV table on standard output.");
  ps_app->add_option("--scenes", ps->scenes, "Built-in scenes, comma-separated")->capture_default_str();
  ps_app->add_option("--engine", ps->engine, "saltus, bullet, mujoco, both (saltus and bullet) or all")->capture_default_str();
  ps_app->add_option("--dt", ps->dt, "Time step [s]")->capture_default_str();
  ps_app->add_option("--repeat", ps->repeat, "Timing rounds (the fastest is kept)")->capture_default_str();
  ps_app->add_option("--min-time", ps->min_time, "CPU seconds per timing (fastest run kept)")->capture_default_str();
  ps_app->add_option("--theta", ps->theta, "θ of the saltus stepper's θ-method, in [0.5, 1]")->capture_default_str();
  ps_app->add_flag("--no-locate-impacts", ps->no_locate_impacts,
                   "Saltus: resolve impacts at the start of the step instead of at their located time within it");
  ps_app->add_option("--solver", ps->solver, "LCP solver of the saltus stepper: lemke or pgs")->capture_default_str();
  ps_app->add_option("--bullet-solver", ps->bullet_solver, "Bullet's solver: dantzig, lemke or si")
      ->capture_default_str();

  auto su = std::make_shared<SummaryOptions>();
  CLI::App* su_app = bench->add_subcommand(
      "summary",
      "Every scene (built-in, or --scenes), every engine that can build it, Saltus at theta 1 and 1/2: the stability map "
      "and the work-precision chart of each in OUT/<scene>/, and OUT/summary.csv and summary.md: per scene and engine "
      "the largest stable step and the cost per step at the step whose error reaches --target.");
  su_app->add_option("--scenes", su->scenes, "all, or built-in scenes comma-separated")->capture_default_str();
  su_app->add_option("--target", su->target, "Error the cost is read at (the largest dt at or below it)")->capture_default_str();
  su_app->add_option("--min-time", su->min_time, "CPU seconds per timing in work-precision")->capture_default_str();
  su_app->add_option("--out", su->out, "Output folder")->required();

  return {bench, [wp, st, ps, su, wp_app, st_app, ps_app, su_app]() -> int {
            if (wp_app->parsed()) return workPrecision(*wp);
            if (st_app->parsed()) return stability(*st);
            if (ps_app->parsed()) return perStep(*ps);
            if (su_app->parsed()) return summary(*su);
            throw UsageError("bench: expected a subcommand: work-precision, stability, per-step or summary");
          }};
}

}  // namespace saltus::cli
