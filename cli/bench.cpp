// saltus bench: measurements of the time-stepper (timestepper/stepper.hpp) on a scene.
//
//   work-precision  sweeps the time step; for each dt the error against the scene's analytic
//                   answer (timestepper/analytic.hpp) or, without a closed form, against a
//                   reference run at dt_min/16 with θ = ½, and the cost (CPU seconds per simulated
//                   second, wall ns per step; stepping only, no I/O). DIR/work_precision.csv and a
//                   log-log chart DIR/work_precision.png/.svg.
//   stability       a grid over large time steps, high friction and high restitution (the scene's
//                   `friction` / `restitution` parameters, where it has them); each run ends ok,
//                   lcp_failure, nan, energy_gain or penetration. DIR/stability.csv and a grid
//                   chart DIR/stability.png/.svg.
//
//   per-step        ns per step of both engines at one dt on several built-in scenes (interleaved
//                   rounds, fastest kept), their ratio and errors; CSV on standard output.
//
// --engine saltus|bullet|both: the saltus time-stepper and/or Bullet's btMultiBodyDynamicsWorld
// built from the same scene (verify/bullet_world.hpp, tuned settings); rows carry an `engine`
// column. Default saltus (Bullet only on request: its runs cost 2.5–8× more per step).
//
// Charts are drawn by scripts/charts.py (python3 + matplotlib); when that fails the command
// says so and exits 1, with the CSV written.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "timestepper/analytic.hpp"
#include "scene/scenario.hpp"
#include "verify/bullet_world.hpp"

namespace saltus::cli {

namespace {

using namespace saltus::timestepper;
using saltus::scene::loadScene;
namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct BenchOptions {
  std::string engine = "saltus";
  std::string bullet_solver = "dantzig";
  std::string scene;
  std::vector<std::string> set;
  std::string solver = "lemke";
  double theta = 1.0;
  bool no_locate_impacts = false;
  std::optional<double> duration;
  std::string out;
};

struct WorkPrecisionOptions : BenchOptions {
  std::string dts = "1e-2,5e-3,2e-3,1e-3,5e-4,2e-4,1e-4";
  double min_time = 0.2;
};

struct StabilityOptions : BenchOptions {
  std::string dts = "1e-3,2e-3,5e-3,1e-2,2e-2,5e-2,1e-1";
  std::optional<std::string> frictions, restitutions;
};

const char* kDefaultFrictions = "0.3,0.6,1,2,5";
const char* kDefaultRestitutions = "0,0.25,0.5,0.75,0.9,1";

std::string parameterList(const Scene& scene) {
  std::string s;
  for (const auto& [name, value] : scene.parameters) s += (s.empty() ? "" : ", ") + name + "=" + formatNumber(value, 10);
  return s.empty() ? "(none)" : s;
}

double parameter(const Scene& scene, const std::string& name) {
  const auto it = scene.parameters.find(name);
  return it == scene.parameters.end() ? kNaN : it->second;
}

bool hasParameters(const Scene& scene, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (!scene.parameters.count(n)) return false;
  return true;
}

int coordinateIndex(const Scene& scene, const std::string& name) {
  const auto& names = scene.model.coordinate_name;
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

StepperOptions stepperOptions(double dt, double theta, LcpMethod solver) {
  StepperOptions o;
  o.dt = dt;
  o.theta = theta;
  o.solver = solver;
  return o;
}

// ---------------------------------------------------------------------------------------------
// engines: the saltus time-stepper and Bullet's btMultiBodyDynamicsWorld (verify/bullet_world.hpp)

enum class Engine { Saltus, Bullet };
const char* engineName(Engine e) { return e == Engine::Saltus ? "saltus" : "bullet"; }

std::vector<Engine> parseEngines(const std::string& value) {
  if (value == "saltus") return {Engine::Saltus};
  if (value == "bullet") return {Engine::Bullet};
  if (value == "both") return {Engine::Saltus, Engine::Bullet};
  throw UsageError("--engine: expected saltus, bullet or both, got '" + value + "'");
}

verify::BulletSolver parseBulletSolverOption(const std::string& value) {
  try {
    return verify::parseBulletSolver(value);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--bullet-solver: ") + e.what());
  }
}

// How one engine is set up for a run: the stepper options (saltus) or the world options (Bullet).
struct EngineSetup {
  Engine engine = Engine::Saltus;
  StepperOptions saltus;
  verify::BulletWorldOptions bullet;
  std::string describe() const {
    if (engine == Engine::Saltus)
      return std::string("saltus: theta ") + formatNumber(saltus.theta) + ", solver " + solverName(saltus.solver) +
             (saltus.locate_impacts ? ", impacts located within the step" : ", impacts at the step's start");
    return std::string("bullet: btMultiBodyDynamicsWorld, ") + verify::bulletSolverName(bullet.solver) +
           ", erp2 " + formatNumber(bullet.erp2) + ", restitution threshold " +
           formatNumber(bullet.restitution_threshold) + " m/s, contact sphere radius " +
           formatNumber(bullet.contact_radius) + " m, cfm " + formatNumber(bullet.global_cfm);
  }
};

EngineSetup engineSetup(Engine engine, double dt, double theta, LcpMethod solver, verify::BulletSolver bullet_solver,
                        bool locate_impacts) {
  EngineSetup e;
  e.engine = engine;
  e.saltus = stepperOptions(dt, theta, solver);
  e.saltus.locate_impacts = locate_impacts;
  e.bullet.dt = dt;
  e.bullet.solver = bullet_solver;
  return e;
}

// The common face of both engines for the bench loops.
class Sim {
 public:
  virtual ~Sim() = default;
  // Throws SimulationError (saltus: LCP failure or non-finite state; Bullet: non-finite state).
  virtual void step() = 0;
  virtual const Eigen::VectorXd& q() const = 0;
  virtual const Eigen::VectorXd& v() const = 0;
  virtual double time() const = 0;
  virtual double energy() = 0;
  virtual double firstContactImpulse() const = 0;
  virtual long steps() const = 0;
  virtual long failures() const = 0;  // LCP failures (saltus) / MLCP fallbacks (Bullet)
  virtual double maxPenetration() const = 0;
};

class SaltusSim final : public Sim {
 public:
  SaltusSim(const Scene& scene, const StepperOptions& o) : s_(scene, o) {}
  void step() override { s_.step(); }
  const Eigen::VectorXd& q() const override { return s_.q(); }
  const Eigen::VectorXd& v() const override { return s_.v(); }
  double time() const override { return s_.time(); }
  double energy() override { return s_.energy(); }
  double firstContactImpulse() const override { return s_.contacts().empty() ? 0.0 : s_.contacts()[0].pn; }
  long steps() const override { return s_.stats().steps; }
  long failures() const override { return s_.stats().lcp_failures; }
  double maxPenetration() const override { return s_.stats().max_penetration; }

 private:
  TimeStepper s_;
};

class BulletSim final : public Sim {
 public:
  BulletSim(const Scene& scene, const verify::BulletWorldOptions& o) : w_(scene, o) {}
  void step() override {
    w_.step();
    if (!w_.q().allFinite() || !w_.v().allFinite())
      throw SimulationError("Bullet: the state is not finite at t = " + formatNumber(w_.time()) + " s", w_.time(), {},
                            kNaN);
  }
  const Eigen::VectorXd& q() const override { return w_.q(); }
  const Eigen::VectorXd& v() const override { return w_.v(); }
  double time() const override { return w_.time(); }
  double energy() override { return w_.energy(); }
  double firstContactImpulse() const override { return w_.contacts().empty() ? 0.0 : w_.contacts()[0].pn; }
  long steps() const override { return w_.stats().steps; }
  long failures() const override { return w_.stats().mlcp_fallbacks; }
  double maxPenetration() const override { return w_.stats().max_penetration; }

 private:
  verify::BulletWorld w_;
};

std::unique_ptr<Sim> makeSim(const Scene& scene, const EngineSetup& e) {
  if (e.engine == Engine::Saltus) return std::make_unique<SaltusSim>(scene, e.saltus);
  return std::make_unique<BulletSim>(scene, e.bullet);
}

fs::path prepareOutputDirectory(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw std::runtime_error(dir + ": cannot create the output folder (" + ec.message() + ")");
  return fs::path(dir);
}

// CSV first (already written), then the charts; stale charts of an earlier run are removed first
// so that a failed chart step leaves none.
void drawCharts(const std::string& kind, const fs::path& csv, const fs::path& png, const fs::path& svg) {
  std::error_code ec;
  fs::remove(png, ec);
  fs::remove(svg, ec);
  runChartScript(kind, csv.string(), png.string(), svg.string());
}

// ---------------------------------------------------------------------------------------------
// work-precision

// How a run's error is measured.
struct ErrorModel {
  enum Kind { BallApex, Slide, Reference } kind = Reference;
  std::string description;
  // BallApex
  double apex_exact = 0;
  // Slide
  int s_index = -1;
  double v0 = 0, mu = 0, alpha = 0, g = 0;
  // Reference: states [q; v] at times t_ref[i]
  std::vector<double> t_ref;
  std::vector<Eigen::VectorXd> x_ref;
};

// One recorded (untimed) run: what the error needs.
struct RecordedRun {
  bool failed = false;
  std::string message;
  long steps = 0, failures = 0;
  double t_end = 0;
  Eigen::VectorXd x_end;         // [q; v] at the end
  std::vector<double> z, pn;     // BallApex: height and normal impulse after every step
};

RecordedRun recordRun(const Scene& scene, const EngineSetup& setup, long steps, bool keep_bounce) {
  RecordedRun r;
  const std::unique_ptr<Sim> sim = makeSim(scene, setup);
  if (keep_bounce) {
    r.z.reserve(static_cast<std::size_t>(steps) + 1);
    r.pn.reserve(static_cast<std::size_t>(steps) + 1);
    r.z.push_back(sim->q()[0]);
    r.pn.push_back(0);
  }
  try {
    for (long i = 0; i < steps; ++i) {
      sim->step();
      if (keep_bounce) {
        r.z.push_back(sim->q()[0]);
        r.pn.push_back(sim->firstContactImpulse());
      }
    }
  } catch (const SimulationError& e) {
    r.failed = true;
    r.message = e.what();
  }
  r.steps = sim->steps();
  r.failures = sim->failures();
  r.t_end = sim->time();
  r.x_end.resize(sim->q().size() + sim->v().size());
  r.x_end << sim->q(), sim->v();
  return r;
}

// The reference trajectory for scenes without a closed form: θ = ½, dt_ref, to t_end.
void referenceRun(ErrorModel& model, const Scene& scene, double dt_ref, LcpMethod solver, double t_end) {
  TimeStepper stepper(scene, stepperOptions(dt_ref, 0.5, solver));
  const long steps = stepCount(t_end, dt_ref) + 1;
  model.t_ref.reserve(static_cast<std::size_t>(steps) + 1);
  model.x_ref.reserve(static_cast<std::size_t>(steps) + 1);
  const auto record = [&] {
    Eigen::VectorXd x(stepper.q().size() + stepper.v().size());
    x << stepper.q(), stepper.v();
    model.t_ref.push_back(stepper.time());
    model.x_ref.push_back(std::move(x));
  };
  record();
  try {
    for (long i = 0; i < steps; ++i) {
      stepper.step();
      record();
    }
  } catch (const SimulationError& e) {
    throw std::runtime_error("the reference run (dt " + formatNumber(dt_ref) + " s, theta 0.5, " +
                             solverName(solver) + ") failed: " + e.what());
  }
}

// Reference state at time t, linear between the reference samples.
Eigen::VectorXd referenceAt(const ErrorModel& model, double t) {
  const auto& ts = model.t_ref;
  const auto it = std::lower_bound(ts.begin(), ts.end(), t);
  if (it == ts.begin()) return model.x_ref.front();
  if (it == ts.end()) return model.x_ref.back();
  const std::size_t i = static_cast<std::size_t>(it - ts.begin());
  const double w = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
  return (1 - w) * model.x_ref[i - 1] + w * model.x_ref[i];
}

ErrorModel makeErrorModel(const Scene& scene, const std::vector<double>& dts, double duration, LcpMethod solver) {
  ErrorModel m;
  if (scene.name == "ball_drop" && hasParameters(scene, {"height", "restitution"}) && scene.model.nv() == 1 &&
      scene.contacts.size() == 1 && scene.limits.empty()) {
    const double h0 = parameter(scene, "height"), e = parameter(scene, "restitution");
    m.kind = ErrorModel::BallApex;
    m.apex_exact = analytic::ballApex(h0, e, 1);
    m.description = "|first apex - e^2 h0| with e^2 h0 = " + formatNumber(m.apex_exact, 8) +
                    " m (apex: highest z between the first and the second impact; shared/reference/facts.md §3)";
    return m;
  }
  if (scene.name == "block_slide" && hasParameters(scene, {"incline", "speed", "friction", "g"}) &&
      coordinateIndex(scene, "s") >= 0) {
    m.kind = ErrorModel::Slide;
    m.s_index = coordinateIndex(scene, "s");
    m.v0 = parameter(scene, "speed");
    m.mu = parameter(scene, "friction");
    m.alpha = parameter(scene, "incline");
    m.g = parameter(scene, "g");
    const double t_stop = analytic::slideStopTime(m.v0, m.mu, m.alpha, m.g);
    if (std::tan(m.alpha) < m.mu)
      m.description = "|s(T) - v0^2/(2 g (mu cos a - sin a))|: the stopping distance " +
                      formatNumber(analytic::slideStopDistance(m.v0, m.mu, m.alpha, m.g), 8) + " m, reached at t = " +
                      formatNumber(t_stop, 6) + " s" +
                      (t_stop > duration ? " (after T: compared with v0 T + a T^2/2 instead)" : "");
    else
      m.description = "|s(T) - (v0 T + a T^2/2)| with a = g (sin a - mu cos a) = " +
                      formatNumber(analytic::slideAcceleration(m.mu, m.alpha, m.g), 8) + " m/s^2 (tan a >= mu)";
    return m;
  }
  m.kind = ErrorModel::Reference;
  const double dt_ref = *std::min_element(dts.begin(), dts.end()) / 16;
  double t_end = duration;
  for (double dt : dts) t_end = std::max(t_end, stepCount(duration, dt) * dt);
  std::cerr << "work-precision: " << scene.name << " has no closed form; reference run at dt " << formatNumber(dt_ref)
            << " s (dt_min/16), theta 0.5 ..." << std::endl;
  referenceRun(m, scene, dt_ref, solver, t_end);
  m.description = "no closed form: |x(T) - x_ref(T)| (Euclidean norm over q and v) against a reference run at "
                  "dt_min/16 = " + formatNumber(dt_ref) + " s with theta = 1/2";
  return m;
}

double runError(const ErrorModel& m, const RecordedRun& r) {
  if (r.failed) return kNaN;
  switch (m.kind) {
    case ErrorModel::BallApex:
      return std::abs(analytic::firstApex(r.z, r.pn) - m.apex_exact);
    case ErrorModel::Slide:
      return std::abs(r.x_end[m.s_index] - analytic::slidePosition(m.v0, m.mu, m.alpha, m.g, r.t_end));
    case ErrorModel::Reference:
      return (r.x_end - referenceAt(m, r.t_end)).norm();
  }
  return kNaN;
}

struct Timing {
  double wall = kNaN, cpu = kNaN;  // seconds per run, best of the repetitions
  int repetitions = 0;
};

// Runs `steps` steps repeatedly (at least once, until min_time CPU seconds have been spent) and
// keeps the fastest wall and CPU time of a run. Only stepping is timed.
Timing timeRuns(const Scene& scene, const EngineSetup& setup, long steps, double min_time) {
  Timing timing;
  timing.wall = timing.cpu = std::numeric_limits<double>::infinity();
  double spent = 0;
  do {
    const std::unique_ptr<Sim> sim = makeSim(scene, setup);
    Sim& stepper = *sim;
    const double cpu0 = cpuSeconds();
    const auto wall0 = std::chrono::steady_clock::now();
    for (long i = 0; i < steps; ++i) stepper.step();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const double cpu = cpuSeconds() - cpu0;
    timing.wall = std::min(timing.wall, wall);
    timing.cpu = std::min(timing.cpu, cpu);
    spent += cpu;
    ++timing.repetitions;
  } while (spent < min_time && timing.repetitions < 1000);
  return timing;
}

int workPrecision(const WorkPrecisionOptions& opt) {
  checkStepOptions("--theta", 1.0, opt.theta);
  const LcpMethod solver = parseSolverOption(opt.solver);
  const std::vector<Engine> engines = parseEngines(opt.engine);
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
  const fs::path dir = prepareOutputDirectory(opt.out);
  ErrorModel model = makeErrorModel(scene, dts, duration, solver);

  std::ostringstream csv;
  csv << "# saltus bench work-precision\n"
      << "# scene: " << scene.name << " (" << scene.source << "); parameters: " << parameterList(scene) << "\n"
      << "# method: ";
  for (std::size_t i = 0; i < engines.size(); ++i)
    csv << (i ? "; " : "") << engineSetup(engines[i], dts[0], opt.theta, solver, bullet_solver, locate).describe();
  csv << ", duration " << formatNumber(duration) << " s\n";
  if (std::find(engines.begin(), engines.end(), Engine::Bullet) != engines.end()) {
    const verify::BulletWorld probe(scene, engineSetup(Engine::Bullet, dts[0], opt.theta, solver, bullet_solver, locate).bullet);
    for (const std::string& a : probe.approximations()) csv << "# bullet approximation: " << a << "\n";
  }
  csv << "# error: " << model.description << "\n"
      << "# timing: stepping only (no I/O), fastest of repeated runs (at least " << formatNumber(opt.min_time)
      << " s CPU per dt); cpu_seconds_per_simulated_second from CLOCK_PROCESS_CPUTIME_ID, ns_per_step from "
         "steady_clock\n"
      << "# solver_failures: saltus LCP failures; bullet MLCP solves that fell back to sequential impulse\n"
      << "engine,dt,error,cpu_seconds_per_simulated_second,ns_per_step,steps,solver_failures\n";
  bool any_failed = false;
  for (Engine engine : engines)
    for (double dt : dts) {
      const EngineSetup setup = engineSetup(engine, dt, opt.theta, solver, bullet_solver, locate);
      const long steps = stepCount(duration, dt);
      const RecordedRun run = recordRun(scene, setup, steps, model.kind == ErrorModel::BallApex);
      const double error = runError(model, run);
      Timing timing;
      if (!run.failed) timing = timeRuns(scene, setup, steps, opt.min_time);
      const double simulated = steps * dt;
      const double cpu_per_s = timing.cpu / simulated, ns_per_step = timing.wall * 1e9 / steps;
      csv << engineName(engine) << "," << formatNumber(dt, 10) << "," << formatNumber(error, 8) << ","
          << formatNumber(cpu_per_s, 6) << "," << formatNumber(ns_per_step, 6) << "," << run.steps << ","
          << run.failures << "\n";
      std::cerr << "work-precision: " << scene.name << " " << engineName(engine) << " dt " << formatNumber(dt) << ": ";
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
  const fs::path csv_path = dir / "work_precision.csv";
  writeFileAtomically(csv_path.string(), csv.str());
  std::cerr << "work-precision: wrote " << csv_path.string() << (any_failed ? " (some runs failed: error nan)" : "")
            << std::endl;
  drawCharts("work-precision", csv_path, dir / "work_precision.png", dir / "work_precision.svg");
  std::cerr << "work-precision: wrote " << (dir / "work_precision.png").string() << ", "
            << (dir / "work_precision.svg").string() << std::endl;
  return 0;
}

// ---------------------------------------------------------------------------------------------
// per-step: the cost of one step of each engine at the same dt on several scenes, and their errors

struct PerStepOptions {
  std::string scenes = "ball_drop,block_slide,pendulum_conveyor";
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
  const bool locate = !opt.no_locate_impacts;
  if (opt.repeat < 1) throw UsageError("--repeat: expected a positive count");
  if (!(opt.min_time >= 0) || !std::isfinite(opt.min_time))
    throw UsageError("--min-time: expected a non-negative number of seconds");
  std::vector<std::string> names;
  for (std::size_t start = 0;;) {
    const std::size_t comma = opt.scenes.find(',', start);
    names.push_back(opt.scenes.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::cout << "# saltus bench per-step: dt " << formatNumber(opt.dt) << " s; ns per step = fastest of " << opt.repeat
            << " rounds (each the fastest run of at least " << formatNumber(opt.min_time)
            << " s CPU), the engines interleaved; error as in work-precision\n"
            << "# saltus: theta " << formatNumber(opt.theta) << ", " << solverName(solver)
            << (opt.no_locate_impacts ? ", impacts at the step's start" : ", impacts located within the step")
            << "; bullet: "
            << verify::bulletSolverName(bullet_solver) << ", tuned settings (verify/bullet_world.hpp)\n"
            << "scene,saltus_ns_per_step,bullet_ns_per_step,bullet_over_saltus,saltus_error,bullet_error,"
               "saltus_failures,bullet_failures\n";
  for (const std::string& name : names) {
    const Scene scene = loadScene(name);
    const long steps = stepCount(scene.duration, opt.dt);
    ErrorModel model = makeErrorModel(scene, {opt.dt}, scene.duration, solver);
    double ns[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    double error[2] = {kNaN, kNaN};
    long failures[2] = {0, 0};
    for (int e = 0; e < 2; ++e) {
      const EngineSetup setup = engineSetup(e ? Engine::Bullet : Engine::Saltus, opt.dt, opt.theta, solver, bullet_solver, locate);
      const RecordedRun run = recordRun(scene, setup, steps, model.kind == ErrorModel::BallApex);
      error[e] = runError(model, run);
      failures[e] = run.failures;
      if (run.failed) throw std::runtime_error(name + ": the " + engineName(setup.engine) + " run failed: " + run.message);
    }
    for (int round = 0; round < opt.repeat; ++round)
      for (int e = 0; e < 2; ++e) {
        const EngineSetup setup = engineSetup(e ? Engine::Bullet : Engine::Saltus, opt.dt, opt.theta, solver, bullet_solver, locate);
        ns[e] = std::min(ns[e], timeRuns(scene, setup, steps, opt.min_time).wall * 1e9 / steps);
      }
    std::cout << scene.name << "," << formatNumber(ns[0], 5) << "," << formatNumber(ns[1], 5) << ","
              << formatNumber(ns[1] / ns[0], 3) << "," << formatNumber(error[0], 5) << "," << formatNumber(error[1], 5)
              << "," << failures[0] << "," << failures[1] << std::endl;
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

constexpr double kEnergyTolerance = 1e-9;    // relative rise of the energy above E_0
constexpr double kPenetrationLimit = 1e-3;   // [m]

StabilityRun stabilityRun(const Scene& scene, const EngineSetup& setup, long steps, bool exempt) {
  StabilityRun r;
  const std::unique_ptr<Sim> sim = makeSim(scene, setup);
  Sim& stepper = *sim;
  const double e0 = stepper.energy();
  const double scale = e0 != 0 ? std::abs(e0) : 1.0;
  try {
    for (long i = 0; i < steps; ++i) {
      stepper.step();
      const double e = stepper.energy();
      if (!std::isfinite(e)) {
        r.outcome = "nan";
        r.message = "energy is not finite at t = " + formatNumber(stepper.time()) + " s";
        break;
      }
      r.energy_gain = std::max(r.energy_gain, (e - e0) / scale);
    }
  } catch (const SimulationError& e) {
    const bool finite = stepper.q().allFinite() && stepper.v().allFinite();
    const std::string what = e.what();
    r.outcome = !finite ? "nan" : what.find("LCP") != std::string::npos ? "lcp_failure" : "error";
    r.message = what;
  }
  r.steps = stepper.steps();
  r.t_end = stepper.time();
  r.max_penetration = stepper.maxPenetration();
  if (r.outcome == "ok") {
    if (r.max_penetration > kPenetrationLimit) {
      r.outcome = "penetration";
      r.message = "largest penetration " + formatNumber(r.max_penetration, 4) + " m";
    } else if (!exempt && r.energy_gain > kEnergyTolerance) {
      r.outcome = "energy_gain";
      r.message = "energy rose above E_0 by " + formatNumber(r.energy_gain, 4) + " (relative)";
    } else if (setup.engine == Engine::Bullet && stepper.failures() > 0) {
      r.outcome = "solver_fallback";
      r.message = std::to_string(stepper.failures()) + " MLCP solves fell back to sequential impulse";
    }
  }
  return r;
}

int stability(const StabilityOptions& opt) {
  checkStepOptions("--theta", 1.0, opt.theta);
  const LcpMethod solver = parseSolverOption(opt.solver);
  const std::vector<Engine> engines = parseEngines(opt.engine);
  const verify::BulletSolver bullet_solver = parseBulletSolverOption(opt.bullet_solver);
  const bool locate = !opt.no_locate_impacts;
  std::vector<double> dts = parseNumberList("--dts", opt.dts, true);
  std::sort(dts.begin(), dts.end());
  dts.erase(std::unique(dts.begin(), dts.end()), dts.end());
  if (opt.duration && !(*opt.duration > 0)) throw UsageError("--duration: expected a positive time [s]");
  const std::map<std::string, double> overrides = parseSetOptions(opt.set);
  const Scene base = loadScene(opt.scene, overrides);

  // The grid's parameter axes: those of friction and restitution the scene has.
  const auto axis = [&](const char* name, const std::optional<std::string>& given, const char* defaults) {
    std::vector<double> values;
    if (!base.parameters.count(name)) {
      if (given)
        throw UsageError(std::string("--") + name + "s: scene " + base.name + " has no parameter '" + name +
                         "' (its parameters: " + parameterList(base) + ")");
      return values;
    }
    values = parseNumberList(std::string("--") + name + "s", given.value_or(defaults), false);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    return values;
  };
  const std::vector<double> frictions = axis("friction", opt.frictions, kDefaultFrictions);
  const std::vector<double> restitutions = axis("restitution", opt.restitutions, kDefaultRestitutions);
  for (double e : restitutions)
    if (e > 1) throw UsageError("--restitutions: " + formatNumber(e) + " is not in [0, 1]");
  const bool exempt = hasMovingSurfaceOrInput(base);
  const fs::path dir = prepareOutputDirectory(opt.out);
  const double duration = opt.duration.value_or(base.duration);

  std::ostringstream csv;
  csv << "# saltus bench stability\n"
      << "# scene: " << base.name << " (" << base.source << "); parameters: " << parameterList(base) << "\n"
      << "# method: ";
  for (std::size_t i = 0; i < engines.size(); ++i)
    csv << (i ? "; " : "") << engineSetup(engines[i], 1e-3, opt.theta, solver, bullet_solver, locate).describe();
  csv << ", duration " << formatNumber(duration) << " s\n"
      << "# grid: dt x " << (frictions.empty() ? "" : "friction x ") << (restitutions.empty() ? "" : "restitution x ")
      << "(empty column: the scene has no such parameter)\n"
      << "# outcome: ok | lcp_failure (SimulationError from the LCP solver) | nan (state not finite) | error (other "
         "SimulationError) | solver_fallback (bullet: ok but MLCP solves fell back to sequential impulse) | "
         "penetration (largest penetration > "
      << formatNumber(kPenetrationLimit) << " m) | energy_gain (energy above E_0 by more than "
      << formatNumber(kEnergyTolerance) << " relative to |E_0|"
      << (exempt ? "; not checked here: the scene has a moving surface or an input" : "") << ")\n"
      << "engine,dt,friction,restitution,outcome,max_penetration,energy_gain,steps,t_end,message\n";
  std::map<std::string, int> counts;
  const std::vector<double> none{kNaN};
  for (Engine engine : engines)
  for (double dt : dts)
    for (double mu : frictions.empty() ? none : frictions)
      for (double e : restitutions.empty() ? none : restitutions) {
        std::map<std::string, double> o = overrides;
        if (!std::isnan(mu)) o["friction"] = mu;
        if (!std::isnan(e)) o["restitution"] = e;
        const Scene scene = loadScene(opt.scene, o);
        const StabilityRun r = stabilityRun(scene, engineSetup(engine, dt, opt.theta, solver, bullet_solver, locate),
                                            stepCount(duration, dt), exempt);
        ++counts[std::string(engineName(engine)) + " " + r.outcome];
        csv << engineName(engine) << "," << formatNumber(dt, 10) << "," << (std::isnan(mu) ? "" : formatNumber(mu, 10)) << ","
            << (std::isnan(e) ? "" : formatNumber(e, 10)) << "," << r.outcome << ","
            << formatNumber(r.max_penetration, 6) << "," << formatNumber(r.energy_gain, 6) << "," << r.steps << ","
            << formatNumber(r.t_end, 10) << "," << csvField(r.message) << "\n";
      }
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

void addCommonOptions(CLI::App* app, BenchOptions& opt) {
  app->add_option("SCENE", opt.scene, "Built-in scene name or scenario file path")->required();
  app->add_option("--set", opt.set, "Override a scene parameter: --set name=value (repeatable)")
      ->allow_extra_args(false);
  app->add_option("--theta", opt.theta, "θ of the θ-method, in [0.5, 1]")->capture_default_str();
  app->add_flag("--no-locate-impacts", opt.no_locate_impacts,
                "Saltus: resolve impacts at the start of the step instead of at their located time within it");
  app->add_option("--solver", opt.solver, "LCP solver of the saltus stepper: lemke or pgs")->capture_default_str();
  app->add_option("--engine", opt.engine, "Engine: saltus, bullet (btMultiBodyDynamicsWorld) or both")
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

  auto ps = std::make_shared<PerStepOptions>();
  CLI::App* ps_app = bench->add_subcommand(
      "per-step",
      "ns per step of saltus and Bullet at the same dt on built-in scenes (interleaved, fastest of --repeat rounds), "
      "their ratio and errors; a CSV table on standard output.");
  ps_app->add_option("--scenes", ps->scenes, "Built-in scenes, comma-separated")->capture_default_str();
  ps_app->add_option("--dt", ps->dt, "Time step [s]")->capture_default_str();
  ps_app->add_option("--repeat", ps->repeat, "Timing rounds (the fastest is kept)")->capture_default_str();
  ps_app->add_option("--min-time", ps->min_time, "CPU seconds per timing (fastest run kept)")->capture_default_str();
  ps_app->add_option("--theta", ps->theta, "θ of the saltus stepper's θ-method, in [0.5, 1]")->capture_default_str();
  ps_app->add_flag("--no-locate-impacts", ps->no_locate_impacts,
                   "Saltus: resolve impacts at the start of the step instead of at their located time within it");
  ps_app->add_option("--solver", ps->solver, "LCP solver of the saltus stepper: lemke or pgs")->capture_default_str();
  ps_app->add_option("--bullet-solver", ps->bullet_solver, "Bullet's solver: dantzig, lemke or si")
      ->capture_default_str();

  return {bench, [wp, st, ps, wp_app, st_app, ps_app]() -> int {
            if (wp_app->parsed()) return workPrecision(*wp);
            if (st_app->parsed()) return stability(*st);
            if (ps_app->parsed()) return perStep(*ps);
            throw UsageError("bench: expected a subcommand: work-precision, stability or per-step");
          }};
}

}  // namespace saltus::cli
