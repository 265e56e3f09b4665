// The runs behind `saltus bench`: see cli/bench_runs.hpp.
#include "cli/bench_runs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "cli/common.hpp"
#include "cli/simulation.hpp"
#include "dynamics/energy.hpp"
#include "timestepper/analytic.hpp"
#include "timestepper/sticking_motion.hpp"

namespace saltus::cli::bench {

using namespace saltus::timestepper;

namespace {
constexpr double kBenchNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

std::string parameterList(const Scene& scene) {
  std::string s;
  for (const auto& [name, value] : scene.parameters) s += (s.empty() ? "" : ", ") + name + "=" + formatNumber(value, 10);
  return s.empty() ? "(none)" : s;
}

double parameter(const Scene& scene, const std::string& name) {
  const auto it = scene.parameters.find(name);
  return it == scene.parameters.end() ? kBenchNaN : it->second;
}

namespace {

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

}  // namespace

StepperOptions stepperOptions(double dt, double theta, LcpMethod solver) {
  StepperOptions o;
  o.dt = dt;
  o.theta = theta;
  o.solver = solver;
  return o;
}

// ---------------------------------------------------------------------------------------------
// engines: the saltus time-stepper, Bullet's btMultiBodyDynamicsWorld (verify/bullet_world.hpp) and MuJoCo
// (verify/mujoco_world.hpp)

std::vector<EngineKind> parseEngineOption(const std::string& value) {
  try {
    return verify::parseEngines(value);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--engine: ") + e.what());
  }
}

verify::BulletSolver parseBulletSolverOption(const std::string& value) {
  try {
    return verify::parseBulletSolver(value);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--bullet-solver: ") + e.what());
  }
}

std::string describe(const EngineOptions& setup) {
  const timestepper::StepperOptions& saltus = setup.saltus;
  const verify::BulletWorldOptions& bullet = setup.bullet;
  if (setup.kind == EngineKind::Saltus)
    return std::string("saltus: theta ") + formatNumber(saltus.theta) + ", solver " + solverName(saltus.solver) +
           (saltus.locate_impacts ? ", impacts located within the step" : ", impacts at the step's start");
  if (setup.kind == EngineKind::Mujoco) {
    const verify::MujocoWorldOptions& m = setup.mujoco;
    return std::string("mujoco: Euler, Newton solver, pyramidal cone, contact spring omega = 1/(") +
           formatNumber(m.timeconst_steps) + " dt), impedance " + formatNumber(m.impedance) +
           ", contact sphere radius " + formatNumber(m.contact_radius) + " m";
  }
  return std::string("bullet: btMultiBodyDynamicsWorld, ") + verify::bulletSolverName(bullet.solver) +
         ", erp2 " + formatNumber(bullet.erp2) + ", restitution threshold " +
         formatNumber(bullet.restitution_threshold) + " m/s, contact sphere radius " +
         formatNumber(bullet.contact_radius) + " m, cfm " + formatNumber(bullet.global_cfm);
}

EngineOptions engineSetup(EngineKind kind, double dt, double theta, LcpMethod solver, verify::BulletSolver bullet_solver,
                          bool locate_impacts) {
  EngineOptions e;
  e.kind = kind;
  e.saltus = stepperOptions(dt, theta, solver);
  e.saltus.locate_impacts = locate_impacts;
  e.bullet.dt = dt;
  e.bullet.solver = bullet_solver;
  e.mujoco.dt = dt;
  return e;
}

RecordedRun recordRun(const Scene& scene, const EngineOptions& setup, long steps, int tracked) {
  const bool keep_bounce = tracked >= 0;
  RecordedRun r;
  const std::unique_ptr<Engine> sim = verify::makeEngine(scene, setup);
  if (keep_bounce) {
    r.z.reserve(static_cast<std::size_t>(steps) + 1);
    r.pn.reserve(static_cast<std::size_t>(steps) + 1);
    r.z.push_back(sim->q()[tracked]);
    r.pn.push_back(0);
  }
  try {
    for (long i = 0; i < steps; ++i) {
      sim->step();
      if (keep_bounce) {
        r.z.push_back(sim->q()[tracked]);
        r.pn.push_back(scene.contacts.empty() ? 0.0 : sim->contact(0).pn);
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

namespace {

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

// Painlevé's rod stopped by an impulse, then pivoting about its stuck end
// (timestepper/sticking_motion.hpp), when the scene is the built-in one (planar base, one contact
// on a horizontal ground) inside Painlevé's region and the end sticks until t_end; otherwise
// nullopt with the reason in `why_not`.
std::optional<ErrorModel> painleveModel(const Scene& scene, double t_end, std::string& why_not) {
  const int ix = coordinateIndex(scene, "base_x"), iz = coordinateIndex(scene, "base_z"),
            ith = coordinateIndex(scene, "base_theta");
  if (!hasParameters(scene, {"friction", "angle", "speed", "half_length"}) || scene.model.nv() != 3 || ix < 0 ||
      iz < 0 || ith < 0 || scene.contacts.size() != 1 || !scene.limits.empty() ||
      !scene.surfaces[scene.contacts[0].surface].normal.isApprox(Eigen::Vector3d::UnitZ()) ||
      std::abs(scene.model.gravity.x()) + std::abs(scene.model.gravity.y()) > 0) {
    why_not = "not the built-in Painleve rod (parameters, coordinates, one contact on a horizontal ground)";
    return std::nullopt;
  }
  const double l = parameter(scene, "half_length"), angle = parameter(scene, "angle"), mu = parameter(scene, "friction");
  const double g = -scene.model.gravity.z();
  auto rod = std::make_shared<exact::PainleveRodMotion>(l, angle, parameter(scene, "speed"), mu, g);
  if (!rod->stopsByImpulse()) {
    why_not = "outside Painleve's region (B = " + formatNumber(rod->paradoxCoefficient(), 4) +
              " > 0): the end slides, no exact motion";
    return std::nullopt;
  }
  const double t_stick = rod->stickEnd(t_end);
  if (t_stick <= t_end) {
    why_not = "the end slips again at t = " + formatNumber(t_stick, 6) + " s, before the runs end";
    return std::nullopt;
  }
  const double x0 = scene.q0[ix], z_ground = scene.surfaces[scene.contacts[0].surface].point.z();
  ErrorModel m;
  m.kind = ErrorModel::Exact;
  m.exact = [rod, ix, iz, ith, x0, z_ground](double t) {
    const Eigen::Matrix<double, 6, 1> s = rod->planarState(t, x0, z_ground);
    Eigen::VectorXd x(6);
    x[ix] = s[0], x[iz] = s[1], x[ith] = s[2], x[3 + ix] = s[3], x[3 + iz] = s[4], x[3 + ith] = s[5];
    return x;
  };
  const Eigen::Vector2d P = rod->impulsePerMass();
  m.description = "|x(T) - x_exact(T)| (Euclidean norm over q and v): the slip stops at t = 0 by the impulse (" +
                  formatNumber(P[0], 6) + ", " + formatNumber(P[1], 6) +
                  ") m/s per unit mass, then the rod pivots about its stuck end (RK4 quadrature), sticking until t = " +
                  formatNumber(t_stick, 6) + " s (timestepper/sticking_motion.hpp)";
  return m;
}

// The pendulum whose tip sticks to the belt (timestepper/sticking_motion.hpp), when the scene has
// that form and sticking holds until t_end; otherwise nullopt with the reason in `why_not`.
std::optional<ErrorModel> beltModel(const Scene& scene, double t_end, std::string& why_not) {
  std::shared_ptr<exact::BeltStickingMotion> belt;
  try {
    belt = std::make_shared<exact::BeltStickingMotion>(scene);
    const double t_stick = belt->stickEnd(t_end);
    if (t_stick <= t_end) {
      why_not = "the tip slips at t = " + formatNumber(t_stick, 6) + " s, before the runs end";
      return std::nullopt;
    }
  } catch (const std::exception& e) {
    why_not = e.what();
    return std::nullopt;
  }
  ErrorModel m;
  m.kind = ErrorModel::Exact;
  m.exact = [belt](double t) { return belt->state(t); };
  m.description = "|x(T) - x_exact(T)| (Euclidean norm over q and v): the tip sticks to the belt from the start, "
                  "its impulse at each belt step and its force in between inside the friction cone until T; "
                  "q(T) from the tip's position on the belt (timestepper/sticking_motion.hpp)";
  return m;
}

}  // namespace

ErrorModel makeErrorModel(const Scene& scene, const std::vector<double>& dts, double duration, LcpMethod solver) {
  ErrorModel m;
  if (scene.name == "ball_drop" && hasParameters(scene, {"height", "restitution"}) && scene.model.nv() == 1 &&
      scene.contacts.size() == 1 && scene.limits.empty()) {
    const double h0 = parameter(scene, "height"), e = parameter(scene, "restitution");
    m.kind = ErrorModel::BallApex;
    m.tracked = 0;
    m.apex_exact = analytic::ballApex(h0, e, 1);
    m.description = "|first apex - e^2 h0| with e^2 h0 = " + formatNumber(m.apex_exact, 8) +
                    " m (apex: highest z between the first and the second impact; elementary: h_k = e^(2k) h0)";
    return m;
  }
  if (scene.name == "rocking_block" && hasParameters(scene, {"half_width", "half_height", "tilt"}) &&
      coordinateIndex(scene, "base_theta") >= 0) {
    const double b = parameter(scene, "half_width"), h = parameter(scene, "half_height");
    const double g = scene.model.gravity.norm();
    const double omega = analytic::rockingImpactRatio(b, h) * analytic::rockingReturnSpeed(b, h, parameter(scene, "tilt"), g);
    m.kind = ErrorModel::RockingTilt;
    m.tracked = coordinateIndex(scene, "base_theta");
    m.apex_exact = analytic::rockingTilt(b, h, omega, g);
    m.description = "|largest tilt between the first and second impact - " + formatNumber(m.apex_exact, 8) +
                    " rad| (Housner: omega after an impact r = 1 - 3/2 sin^2(atan(b/h)) of omega before; the tilt "
                    "from the energy about the pivot)";
    return m;
  }
  if (scene.name == "newtons_cradle" && hasParameters(scene, {"restitution", "spacing", "speed"}) &&
      scene.model.nv() == 3) {
    const double e = parameter(scene, "restitution"), v = parameter(scene, "speed");
    const bool touching = parameter(scene, "spacing") == 0;
    if (touching || e == 1) {
      m.kind = ErrorModel::Velocities;
      const std::vector<double> exact = touching ? analytic::cradleVelocities(e, v) : std::vector<double>{0, 0, v};
      m.v_exact = Eigen::Map<const Eigen::VectorXd>(exact.data(), 3);
      m.description = std::string("|v(T) - v_exact| after the impacts, v_exact = (") + formatNumber(exact[0], 8) + ", " +
                      formatNumber(exact[1], 8) + ", " + formatNumber(exact[2], 8) + ") m/s (" +
                      (touching ? "the balls touching: Newton's law on both contacts at once, the impact LCP"
                                : "the balls apart, e = 1: pairwise impacts pass the velocity along") + ")";
      return m;
    }
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
  if (scene.contacts.empty() && scene.limits.empty() && scene.model.gravity.isZero(0) && scene.tau.isZero(0)) {
    // No external force: energy and the world angular momentum about the origin are conserved
    // (fast_spin; the body's flip times are checked against Landau and Lifshitz in the tests).
    const auto model = std::make_shared<const dynamics::Model<double>>(scene.model);
    const auto invariants = [model](const Eigen::VectorXd& x) {
      dynamics::Data<double> data(*model);
      const int nq = model->nq();
      dynamics::forwardKinematics(*model, data, x.head(nq), x.tail(model->nv()));
      Eigen::Vector4d out;
      out[0] = dynamics::kineticEnergy(*model, data);
      Eigen::Vector3d L = Eigen::Vector3d::Zero();
      for (int i = 0; i < model->nbodies(); ++i) L += data.X_world[i].applyTranspose(model->inertia[i] * data.v[i]).n;
      out.tail<3>() = L;
      return out;
    };
    Eigen::VectorXd x0(scene.q0.size() + scene.v0.size());
    x0 << scene.q0, scene.v0;
    const Eigen::Vector4d start = invariants(x0);
    m.kind = ErrorModel::Invariants;
    m.drift = [invariants, start](const Eigen::VectorXd& x) {
      const Eigen::Vector4d end = invariants(x);
      return std::abs(end[0] - start[0]) / start[0] + (end.tail<3>() - start.tail<3>()).norm() / start.tail<3>().norm();
    };
    m.description = "|E(T) - E(0)| / E(0) + |L(T) - L(0)| / |L(0)|: the relative drift of the kinetic energy and of "
                    "the world angular momentum, both conserved with no gravity, contact or input";
    return m;
  }
  double t_end = duration;  // the latest end time of the runs
  for (double dt : dts) t_end = std::max(t_end, stepCount(duration, dt) * dt);
  std::string no_exact;  // why a scene with an exact motion falls back to the reference run
  if (scene.name == "painleve_rod") {
    if (std::optional<ErrorModel> exact = painleveModel(scene, t_end, no_exact)) return *exact;
  } else if (scene.name == "pendulum_conveyor") {
    if (std::optional<ErrorModel> exact = beltModel(scene, t_end, no_exact)) return *exact;
  }
  if (!no_exact.empty()) std::cerr << "work-precision: " << scene.name << ": " << no_exact << std::endl;
  m.kind = ErrorModel::Reference;
  const double dt_ref = *std::min_element(dts.begin(), dts.end()) / 16;
  std::cerr << "work-precision: " << scene.name << " has no closed form; reference run at dt " << formatNumber(dt_ref)
            << " s (dt_min/16), theta 0.5 ..." << std::endl;
  referenceRun(m, scene, dt_ref, solver, t_end);
  m.description = "no closed form: |x(T) - x_ref(T)| (Euclidean norm over q and v) against a reference run at "
                  "dt_min/16 = " + formatNumber(dt_ref) + " s with theta = 1/2";
  return m;
}

double runError(const ErrorModel& m, const RecordedRun& r) {
  if (r.failed) return kBenchNaN;
  switch (m.kind) {
    case ErrorModel::BallApex:
      return std::abs(analytic::firstApex(r.z, r.pn) - m.apex_exact);
    case ErrorModel::Velocities:
      return (r.x_end.tail(m.v_exact.size()) - m.v_exact).norm();
    case ErrorModel::RockingTilt:
      return std::abs(analytic::rockingFirstTilt(r.z) - m.apex_exact);
    case ErrorModel::Slide:
      return std::abs(r.x_end[m.s_index] - analytic::slidePosition(m.v0, m.mu, m.alpha, m.g, r.t_end));
    case ErrorModel::Exact:
      return (r.x_end - m.exact(r.t_end)).norm();
    case ErrorModel::Invariants:
      return m.drift(r.x_end);
    case ErrorModel::Reference:
      return (r.x_end - referenceAt(m, r.t_end)).norm();
  }
  return kBenchNaN;
}

// Runs `steps` steps repeatedly (at least once, until min_time CPU seconds have been spent) and
// keeps the fastest wall and CPU time of a run. Only stepping is timed.
Timing timeRuns(const Scene& scene, const EngineOptions& setup, long steps, double min_time) {
  Timing timing;
  timing.wall = timing.cpu = std::numeric_limits<double>::infinity();
  double spent = 0;
  do {
    const std::unique_ptr<Engine> sim = verify::makeEngine(scene, setup);
    Engine& stepper = *sim;
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

}  // namespace saltus::cli::bench
