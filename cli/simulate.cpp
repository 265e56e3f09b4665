// saltus simulate SCENE: runs the Moreau–Stewart–Trinkle time-stepper (timestepper/stepper.hpp)
// on a scenario (built-in name or file) and writes the trajectory as CSV
// (scene/trajectory_csv.hpp): a row at t = 0 and one after every step. The file appears
// only when the whole run succeeded. A one-line summary goes to standard error.
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "scene/scenario.hpp"
#include "scene/trajectory_csv.hpp"

namespace saltus::cli {

namespace {

using namespace saltus::timestepper;
using saltus::scene::loadScene;

struct SimulateOptions {
  std::string scene;
  double dt = 1e-3;
  std::optional<double> duration;
  std::vector<std::string> set;
  std::string solver = "lemke";
  double theta = 1.0;
  std::string out;
};

// One trajectory row, kept in memory between the timed stretches of stepping.
struct Sample {
  double t = 0;
  Eigen::VectorXd q, v;
  std::vector<ContactReport> contacts;
};

// A row of the trajectory file: the state and every contact's report (no inputs, no forces).
void writeRow(scene::TrajectoryCsvWriter& writer, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
              const std::vector<ContactReport>& contacts) {
  static const Eigen::VectorXd no_inputs;
  writer.beginRow(t, q, v, no_inputs);
  for (const ContactReport& r : contacts) {
    scene::ContactRow c;
    c.gap = r.gap;
    c.vn = r.vn;
    c.vt = {r.vt1, r.vt2};
    c.pn = r.pn;
    c.pt = {r.pt1, r.pt2};
    writer.contact(c);
  }
  writer.endRow();
}

int simulate(const SimulateOptions& opt) {
  checkStepOptions("--dt", opt.dt, opt.theta);
  if (opt.duration && (!(*opt.duration > 0) || !std::isfinite(*opt.duration)))
    throw UsageError("--duration: expected a positive time [s], got " + formatNumber(*opt.duration));
  const LcpMethod solver = parseSolverOption(opt.solver);
  const std::map<std::string, double> overrides = parseSetOptions(opt.set);

  const Scene scene = loadScene(opt.scene, overrides);
  const double duration = opt.duration.value_or(scene.duration);
  StepperOptions options;
  options.dt = opt.dt;
  options.theta = opt.theta;
  options.solver = solver;
  TimeStepper stepper(scene, options);
  const long steps = stepCount(duration, opt.dt);
  const double e0 = stepper.energy();

  scene::TrajectoryCsvWriter writer(opt.out, scene::trajectoryLayout(scene));
  writeRow(writer, stepper.time(), stepper.q(), stepper.v(), stepper.contacts());

  // Steps in chunks: the clock runs around the stepping only, rows are written between chunks.
  constexpr long kChunk = 1024;
  std::vector<Sample> chunk(static_cast<std::size_t>(std::min(kChunk, steps)),
                            Sample{0, stepper.q(), stepper.v(), stepper.contacts()});
  std::chrono::steady_clock::duration wall{};
  for (long done = 0; done < steps;) {
    const long n = std::min<long>(kChunk, steps - done);
    const auto start = std::chrono::steady_clock::now();
    for (long i = 0; i < n; ++i) {
      stepper.step();
      Sample& s = chunk[static_cast<std::size_t>(i)];
      s.t = stepper.time();
      s.q = stepper.q();
      s.v = stepper.v();
      s.contacts = stepper.contacts();
    }
    wall += std::chrono::steady_clock::now() - start;
    for (long i = 0; i < n; ++i) {
      const Sample& s = chunk[static_cast<std::size_t>(i)];
      writeRow(writer, s.t, s.q, s.v, s.contacts);
    }
    done += n;
  }
  const double e_end = stepper.energy();
  writer.commit();

  const StepperStats& stats = stepper.stats();
  const double wall_s = std::chrono::duration<double>(wall).count();
  std::ostringstream s;
  s << scene.name << ": " << stats.steps << " steps (dt " << formatNumber(opt.dt) << " s to t = "
    << formatNumber(stepper.time()) << " s, theta " << formatNumber(opt.theta) << ", " << solverName(solver)
    << ") in " << formatNumber(wall_s * 1e3, 4) << " ms wall (" << formatNumber(wall_s * 1e6 / stats.steps, 4)
    << " µs per step); LCP failures " << stats.lcp_failures << "; largest penetration "
    << formatNumber(stats.max_penetration, 3) << " m; energy change E_end - E_0 = " << formatNumber(e_end - e0, 4)
    << " J (E_0 = " << formatNumber(e0, 4) << " J"
    << (hasMovingSurfaceOrInput(scene) ? "; input/belt work included" : "") << "); wrote " << opt.out << "\n";
  std::cerr << s.str() << std::flush;
  return 0;
}

}  // namespace

Command addSimulateCommand(CLI::App& saltus) {
  auto opt = std::make_shared<SimulateOptions>();
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
