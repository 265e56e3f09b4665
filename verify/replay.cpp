#include "verify/replay.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>

#include "contact/kinematics.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::verify {

using collocation::CollocationTrajectory;
using collocation::SavedSolution;
using collocation::Side;

const char* feedbackName(Feedback feedback) { return feedback == Feedback::None ? "none" : "pd"; }

Feedback parseFeedback(const std::string& name) {
  if (name == "none") return Feedback::None;
  if (name == "pd") return Feedback::Pd;
  throw std::invalid_argument("unknown feedback '" + name + "' (expected none or pd)");
}

const char* restartName(Restart restart) {
  switch (restart) {
    case Restart::None: return "none";
    case Restart::Mesh: return "mesh";
    case Restart::MeshAfterJumps: return "mesh-after-jumps";
  }
  return "?";
}

Restart parseRestart(const std::string& name) {
  for (Restart r : {Restart::None, Restart::Mesh, Restart::MeshAfterJumps})
    if (name == restartName(r)) return r;
  throw std::invalid_argument("expected none, mesh or mesh-after-jumps, got '" + name + "'");
}

const char* eventKindName(ContactEvent::Kind kind) {
  switch (kind) {
    case ContactEvent::Touchdown: return "touchdown";
    case ContactEvent::LiftOff: return "lift-off";
    case ContactEvent::Impact: return "impact";
    case ContactEvent::ImpactWithoutCollision: return "impact-without-collision";
  }
  return "?";
}

bool ReplayResult::withinTolerance() const {
  if (engines.empty()) return false;
  for (const EngineReplay& e : engines)
    if (!e.completed || !e.within_tolerance) return false;
  return true;
}

scene::Scene replayScene(const SavedSolution& solution) {
  const collocation::Problem& problem = *solution.problem;
  const CollocationTrajectory traj = solution.trajectory();
  // Steps count the problem's elements; the first-order method has several steps per element.
  const int per_element = solution.transcription->method() == collocation::Method::FirstOrder
                              ? problem.first_order_steps_per_element
                              : 1;
  std::vector<double> element_start;
  for (int n = 0; n < problem.N; ++n) element_start.push_back(traj.meshTimes().at(static_cast<std::size_t>(n * per_element)));
  return collocation::sceneAtMeshTimes(problem, element_start);
}

void checkReplayOptions(const ReplayOptions& o, const SavedSolution& solution) {
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(o.dt)) throw std::invalid_argument("dt: expected a positive step, got " + std::to_string(o.dt));
  // At least ten steps over the solution: a longer step would replay nothing of it (and the
  // default tolerance, 10 m/s × dt, would grow to accept anything).
  const double T = solution.trajectory().endTime();
  if (o.dt > T / 10)
    throw std::invalid_argument("dt: expected at most a tenth of the solution's duration (T = " + std::to_string(T) +
                                " s), got " + std::to_string(o.dt) + " s");
  if (!(o.theta >= 0.5 && o.theta <= 1.0)) throw std::invalid_argument("theta: expected a value in [0.5, 1]");
  if (!(std::isfinite(o.kp) && o.kp >= 0) || !(std::isfinite(o.kd) && o.kd >= 0))
    throw std::invalid_argument("kp, kd: expected non-negative gains");
  if (!(std::isfinite(o.tolerance) && o.tolerance >= 0) || !positive(o.tolerance_speed))
    throw std::invalid_argument("tolerance: expected a positive number (or 0: tolerance_speed × dt)");
  if (!positive(o.gap_threshold) || !positive(o.jump_threshold) || !positive(o.approach_threshold) ||
      !positive(o.match_window))
    throw std::invalid_argument("event thresholds: expected positive numbers");
  if (!std::isfinite(o.input_scale)) throw std::invalid_argument("input_scale: expected a finite number");
  const int nu = static_cast<int>(solution.problem->inputs.size());
  if (o.input_offset.size() != 0 && o.input_offset.size() != nu)
    throw std::invalid_argument("input_offset: expected " + std::to_string(nu) + " values (one per input), got " +
                                std::to_string(o.input_offset.size()));
  if (o.engines.empty()) throw std::invalid_argument("engines: none given");
  if (o.max_series < 2) throw std::invalid_argument("max_series: expected at least 2");
}

namespace {

// Gaps and gap rates (normal velocities without a belt's motion) of the scene contacts at (q, v),
// from the contact layer.
class ContactKinematics {
 public:
  ContactKinematics(const collocation::Transcription& t)
      : model_(t.problem().scene.model), data_(model_), pairs_(contact::contactPairs(t.problem().scene)),
        nc_(static_cast<int>(t.problem().scene.contacts.size())) {}
  int contacts() const { return nc_; }
  void set(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    dynamics::forwardKinematics(model_, data_, q, v);
    q_ = q;
    v_ = v;
  }
  double gap(int c) const { return contact::gap(pairs_[c], data_, q_.data()); }
  double vn(int c) const { return contact::normalVelocity(pairs_[c], data_, v_.data()); }
  double energy() const { return dynamics::kineticEnergy(model_, data_) + dynamics::potentialEnergy(model_, data_); }

 private:
  const dynamics::Model<double>& model_;
  dynamics::Data<double> data_;
  std::vector<contact::ContactPair> pairs_;
  int nc_;
  Eigen::VectorXd q_, v_;
};

// Mean of the input polynomial over [a, b]: the P-point Gauss–Legendre rule on each part of the
// interval inside one element (exact for the degree-(P − 1) polynomial of an element).
Eigen::VectorXd meanInput(const CollocationTrajectory& traj, const collocation::LegendreGauss& lg, int nu, double a,
                          double b) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(nu);
  if (nu == 0) return sum;
  const std::vector<double>& mesh = traj.meshTimes();
  for (int n = traj.elementAt(a, Side::After); n < traj.elements() && mesh[n] < b; ++n) {
    const double lo = std::max(a, mesh[n]), hi = std::min(b, mesh[n + 1]);
    if (!(hi > lo)) continue;
    const double h = mesh[n + 1] - mesh[n], mid = (lo + hi) / 2, half = (hi - lo) / 2;
    for (int j = 0; j < lg.P; ++j) {
      const double s = std::clamp((mid + half * lg.x[j] - mesh[n]) / h, 0.0, 1.0);
      sum += lg.w[j] * half * traj.atElement(n, s).u;
    }
  }
  return sum / (b - a);
}

// Touchdown and lift-off from gaps on the time grid.
void closingEvents(const std::vector<std::vector<double>>& gaps, const std::vector<double>& t, double threshold,
                   std::vector<ContactEvent>& out) {
  for (std::size_t c = 0; c < gaps.size(); ++c) {
    bool closed = gaps[c][0] <= threshold;
    for (std::size_t k = 1; k < t.size(); ++k) {
      const bool now = gaps[c][k] <= threshold;
      if (now != closed)
        out.push_back({now ? ContactEvent::Touchdown : ContactEvent::LiftOff, static_cast<int>(c), t[k]});
      closed = now;
    }
  }
}

void sortEvents(std::vector<ContactEvent>& events) {
  std::stable_sort(events.begin(), events.end(), [](const ContactEvent& a, const ContactEvent& b) { return a.t < b.t; });
}

// Greedy, in time order: each optimised event takes the nearest unused replayed event of the
// same kind and contact within the window.
void matchEvents(const std::vector<ContactEvent>& optimised, EngineReplay& e, double window) {
  std::vector<bool> used(e.events.size(), false);
  for (const ContactEvent& o : optimised) {
    EventMatch m{o, false, {}, 0};
    int best = -1;
    for (std::size_t i = 0; i < e.events.size(); ++i) {
      const ContactEvent& r = e.events[i];
      if (used[i] || r.kind != o.kind || r.contact != o.contact || std::abs(r.t - o.t) > window) continue;
      if (best < 0 || std::abs(r.t - o.t) < std::abs(e.events[best].t - o.t)) best = static_cast<int>(i);
    }
    if (best >= 0) {
      used[best] = true;
      m.matched = true;
      m.replayed = e.events[best];
      m.dt = m.replayed.t - o.t;
    }
    e.matches.push_back(m);
  }
  for (std::size_t i = 0; i < e.events.size(); ++i)
    if (!used[i]) e.unmatched.push_back(e.events[i]);
}

// The optimised trajectory on the replay's step grid t_k = k dt (k = 0 … steps, the last clamped
// to T): states (right limits at a jump), the mean input over each step, the contacts' gaps.
struct OptimisedGrid {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, v, u;   // u: steps entries
  std::vector<std::vector<double>> gaps;  // per scene contact, per grid time
  // Restart::Mesh: the steps at whose start the engine is reset, with the state (before a jump).
  std::map<long, std::pair<Eigen::VectorXd, Eigen::VectorXd>> restarts;
  long steps() const { return static_cast<long>(t.size()) - 1; }
};

OptimisedGrid optimisedOnGrid(const SavedSolution& solution, const CollocationTrajectory& traj, double dt, long steps,
                              ContactKinematics& kin) {
  const int nu = static_cast<int>(solution.problem->inputs.size());
  const collocation::LegendreGauss& lg = solution.transcription->lg();
  auto timeOf = [&](long k) { return std::min(traj.endTime(), static_cast<double>(k) * dt); };
  OptimisedGrid g;
  g.t.resize(steps + 1);
  g.q.resize(steps + 1);
  g.v.resize(steps + 1);
  g.u.resize(steps);
  g.gaps.assign(kin.contacts(), std::vector<double>(steps + 1));
  for (long k = 0; k <= steps; ++k) {
    g.t[k] = timeOf(k);
    const collocation::TrajectoryPoint p = traj.at(g.t[k], Side::After);
    g.q[k] = p.q;
    g.v[k] = p.v;
    if (k < steps) g.u[k] = meanInput(traj, lg, nu, g.t[k], timeOf(k + 1));
    kin.set(p.q, p.v);
    for (int c = 0; c < kin.contacts(); ++c) g.gaps[c][k] = kin.gap(c);
  }
  return g;
}

// The restarts of Restart::Mesh: at each mesh time t_n after the first, the last step k with
// t_k ≤ t_n, from the optimised state at t_k before a jump; with Restart::MeshAfterJumps, with
// t_n's velocity jump added (the optimiser's impulse, up to one step early).
void addRestarts(OptimisedGrid& g, const CollocationTrajectory& traj, double dt, Restart restart) {
  const std::vector<double>& mesh = traj.meshTimes();
  for (std::size_t n = 1; n + 1 < mesh.size(); ++n) {
    const long k = static_cast<long>(std::floor(mesh[n] / dt * (1 + 1e-12)));
    if (k <= 0 || k >= g.steps()) continue;
    collocation::TrajectoryPoint p = traj.at(g.t[k], Side::Before);
    if (restart == Restart::MeshAfterJumps) p.v += traj.at(mesh[n], Side::After).v - traj.at(mesh[n], Side::Before).v;
    g.restarts[k] = {p.q, p.v};
  }
}

// The optimised events: closings on the grid, impacts from the velocity jumps (put on the scene
// contact with the largest impulse there; a jump whose largest impulse is a limit stop's is not a
// contact event, even where a scene contact carries a trace of one).
std::vector<ContactEvent> optimisedEvents(const SavedSolution& solution, const CollocationTrajectory& traj,
                                          const OptimisedGrid& grid, const ReplayOptions& options,
                                          ContactKinematics& kin) {
  std::vector<ContactEvent> events;
  closingEvents(grid.gaps, grid.t, options.gap_threshold, events);
  const int nc = kin.contacts();
  for (const CollocationTrajectory::Jump& j : traj.jumps(options.jump_threshold)) {
    int contact = -1;
    double largest = 0;
    const collocation::ElementLayout& L = solution.transcription->layout()[j.element];
    for (int c = 0; c < static_cast<int>(L.contacts.size()); ++c) {  // the scene's contacts, then the stops
      const int rn = L.contacts[c].rn.empty() ? -1 : L.contacts[c].rn[0];
      const double p = rn >= 0 ? std::abs(solution.x[rn]) : 0.0;
      if (p > largest) contact = c, largest = p;  // −1 when nothing carries an impulse
    }
    if (contact < 0 || contact >= nc) continue;
    const collocation::TrajectoryPoint before = traj.at(j.t, Side::Before);
    kin.set(before.q, before.v);
    const bool no_approach = kin.gap(contact) <= options.gap_threshold && kin.vn(contact) > -options.approach_threshold;
    events.push_back({no_approach ? ContactEvent::ImpactWithoutCollision : ContactEvent::Impact, contact, j.t});
  }
  sortEvents(events);
  return events;
}

// Deviation from the optimised state, accumulated over the steps, per coordinate.
class DeviationStatistics {
 public:
  explicit DeviationStatistics(int nv)
      : dq_(Eigen::VectorXd::Zero(nv)), dv_(Eigen::VectorXd::Zero(nv)), max_q_(Eigen::VectorXd::Zero(nv)),
        max_v_(Eigen::VectorXd::Zero(nv)), sum_q2_(Eigen::VectorXd::Zero(nv)), sum_v2_(Eigen::VectorXd::Zero(nv)),
        t_max_q_(Eigen::VectorXd::Zero(nv)) {}

  // The deviation after a step ending at t.
  void add(double t, const Eigen::VectorXd& dq, const Eigen::VectorXd& dv) {
    dq_ = dq;
    dv_ = dv;
    for (Eigen::Index i = 0; i < dq.size(); ++i) {
      if (std::abs(dq[i]) > max_q_[i]) max_q_[i] = std::abs(dq[i]), t_max_q_[i] = t;
      max_v_[i] = std::max(max_v_[i], std::abs(dv[i]));
    }
    sum_q2_ += dq.cwiseAbs2();
    sum_v2_ += dv.cwiseAbs2();
    sum_max2_ += dq.cwiseAbs2().maxCoeff();
  }

  // Per coordinate and over all of them, after `steps` steps: maximum, final value, RMS.
  void report(const std::vector<std::string>& coordinates, long steps_done, EngineReplay& E) const {
    const double steps = static_cast<double>(std::max(1L, steps_done));
    for (std::size_t i = 0; i < coordinates.size(); ++i) {
      CoordinateDeviation d;
      d.coordinate = coordinates[i];
      d.max_q = max_q_[i];
      d.t_max_q = t_max_q_[i];
      d.rms_q = std::sqrt(sum_q2_[i] / steps);
      d.max_v = max_v_[i];
      d.rms_v = std::sqrt(sum_v2_[i] / steps);
      d.final_q = std::abs(dq_[i]);
      d.final_v = std::abs(dv_[i]);
      E.coordinates.push_back(d);
      if (d.max_q >= E.max_position_deviation) {
        E.max_position_deviation = d.max_q;
        E.t_max_position_deviation = d.t_max_q;
      }
      E.final_position_deviation = std::max(E.final_position_deviation, d.final_q);
      E.max_velocity_deviation = std::max(E.max_velocity_deviation, d.max_v);
      E.final_velocity_deviation = std::max(E.final_velocity_deviation, d.final_v);
    }
    E.rms_position_deviation = std::sqrt(sum_max2_ / steps);
  }

 private:
  Eigen::VectorXd dq_, dv_;  // of the last step
  Eigen::VectorXd max_q_, max_v_, sum_q2_, sum_v2_, t_max_q_;
  double sum_max2_ = 0;  // Σ_k max_i dq_i²: the RMS of the largest coordinate deviation
};

// One engine's replay: from the optimised initial state, step k driven by the scene's force plus
// the (modified) mean input and the PD term; deviations, events, penetration and the series.
EngineReplay replayIn(EngineKind which, const scene::Scene& scene, const collocation::Problem& problem,
                      const OptimisedGrid& grid, const ReplayOptions& options, const ReplayResult& R,
                      ContactKinematics& kin) {
  const int nv = scene.model.nv();
  const int nu = static_cast<int>(problem.inputs.size());
  const int nc = kin.contacts();
  const long n_steps = grid.steps();
  const Eigen::VectorXd offset = options.input_offset.size() == nu ? options.input_offset : Eigen::VectorXd::Zero(nu);
  const Eigen::VectorXd tau_base = scene.tau.size() == nv ? scene.tau : Eigen::VectorXd::Zero(nv);

  EngineReplay E;
  E.engine = which;
  EngineOptions setup;
  setup.kind = which;
  setup.saltus.dt = options.dt;
  setup.saltus.theta = options.theta;
  setup.bullet = options.bullet;
  setup.bullet.dt = options.dt;
  setup.mujoco = options.mujoco;
  setup.mujoco.dt = options.dt;
  const std::unique_ptr<Engine> engine = makeEngine(scene, setup);
  engine->reset(grid.q[0], grid.v[0], 0.0);
  E.approximations = engine->approximations();
  E.energy_start = engine->energy();

  Eigen::VectorXd tau(nv), v_before(nv);
  DeviationStatistics deviation(nv);
  std::vector<std::vector<double>> gaps(nc, std::vector<double>(n_steps + 1));
  std::vector<double> vn_prev(nc);
  kin.set(grid.q[0], grid.v[0]);
  for (int c = 0; c < nc; ++c) gaps[c][0] = grid.gaps[c][0], vn_prev[c] = kin.vn(c);
  bool in_impact = false;
  E.series.t.push_back(0.0);
  E.series.q.push_back(engine->q());
  E.series.v.push_back(engine->v());
  E.series.dq.push_back(Eigen::VectorXd::Zero(nv));
  E.series.dv.push_back(Eigen::VectorXd::Zero(nv));
  E.series.energy.push_back(E.energy_start);
  E.series.penetration.push_back(0.0);
  long k = 0;
  try {
    for (; k < n_steps; ++k) {
      if (const auto r = grid.restarts.find(k); r != grid.restarts.end()) engine->reset(r->second.first, r->second.second, grid.t[k]);
      tau = tau_base;
      for (int i = 0; i < nu; ++i) {
        const int coord = problem.inputs[i];
        tau[coord] += options.input_scale * grid.u[k][i] + offset[i];
        if (options.feedback == Feedback::Pd)
          tau[coord] += options.kp * (grid.q[k][coord] - engine->q()[coord]) +
                        options.kd * (grid.v[k][coord] - engine->v()[coord]);
      }
      v_before = engine->v();
      engine->step(tau);
      const Eigen::VectorXd& q = engine->q();
      const Eigen::VectorXd& v = engine->v();
      const long k1 = k + 1;
      const Eigen::VectorXd dq = q - grid.q[k1], dv = v - grid.v[k1];
      deviation.add(grid.t[k1], dq, dv);

      // Events and penetration.
      double penetration = 0;
      int hit = -1;
      double largest = 0;
      for (int c = 0; c < nc; ++c) {
        const EngineContact state = engine->contact(c);
        gaps[c][k1] = state.gap;
        penetration = std::max(penetration, -gaps[c][k1]);
        const double p = std::abs(state.pn) + state.pt;
        if (p > 0 && (hit < 0 || p > largest)) hit = c, largest = p;
      }
      E.max_penetration = std::max(E.max_penetration, penetration);
      const bool impact = hit >= 0 && (v - v_before).cwiseAbs().maxCoeff() > options.jump_threshold;
      if (impact && !in_impact) {
        const bool no_approach = gaps[hit][k] <= options.gap_threshold && vn_prev[hit] > -options.approach_threshold;
        E.events.push_back({no_approach ? ContactEvent::ImpactWithoutCollision : ContactEvent::Impact, hit, grid.t[k1]});
      }
      in_impact = impact;
      for (int c = 0; c < nc; ++c) vn_prev[c] = engine->contact(c).vn;

      if (k1 % R.stride == 0 || k1 == n_steps) {
        E.series.t.push_back(grid.t[k1]);
        E.series.q.push_back(q);
        E.series.v.push_back(v);
        E.series.dq.push_back(dq);
        E.series.dv.push_back(dv);
        E.series.energy.push_back(engine->energy());
        E.series.penetration.push_back(std::max(0.0, penetration));
      }
    }
    E.completed = true;
  } catch (const std::exception& e) {
    E.completed = false;
    E.message = std::string(engineName(which)) + " failed at t = " + std::to_string(grid.t[k]) + " s: " + e.what();
  }
  E.steps = k;
  E.energy_end = engine->energy();
  E.max_penetration = std::max(E.max_penetration, engine->maxPenetration());
  (which == EngineKind::Saltus ? E.lcp_failures : which == EngineKind::Bullet ? E.mlcp_fallbacks : E.mujoco_warnings) =
      engine->failures();
  deviation.report(R.coordinates, k, E);
  E.within_tolerance = E.completed && E.max_position_deviation <= R.tolerance;

  const std::vector<double> t_done(grid.t.begin(), grid.t.begin() + k + 1);
  for (auto& g : gaps) g.resize(static_cast<std::size_t>(k) + 1);
  closingEvents(gaps, t_done, options.gap_threshold, E.events);
  sortEvents(E.events);
  matchEvents(R.optimised_events, E, options.match_window);
  return E;
}

}  // namespace

ReplayResult replay(const SavedSolution& solution, const ReplayOptions& options) {
  checkReplayOptions(options, solution);
  const collocation::Problem& problem = *solution.problem;
  const collocation::Transcription& tr = *solution.transcription;
  const CollocationTrajectory traj = solution.trajectory();
  const dynamics::Model<double>& model = problem.scene.model;
  const int nv = model.nv();

  ReplayResult R;
  R.options = options;
  R.tolerance = options.resolvedTolerance();
  R.problem = problem.name;
  R.source = problem.source;
  R.method = collocation::toString(tr.method());
  R.end_time = traj.endTime();
  R.mesh_times = traj.meshTimes();
  for (int i = 0; i < nv; ++i) R.coordinates.push_back(model.coordinate_name[i]);
  for (const scene::Contact& c : problem.scene.contacts) R.contacts.push_back(c.name);
  for (int i : problem.inputs) R.inputs.push_back(model.coordinate_name[i]);
  const scene::Scene scene = replayScene(solution);
  R.surfaces = scene.surfaces;

  // Steps that fit in [0, T] (the optimised trajectory is not defined beyond T); the series
  // keep every stride-th step and the last.
  const long n_steps = std::max(1L, static_cast<long>(std::floor(R.end_time / options.dt * (1 + 1e-12))));
  R.steps = n_steps;
  R.stride = static_cast<int>((n_steps + options.max_series - 1) / options.max_series);
  ContactKinematics kin(tr);
  OptimisedGrid grid = optimisedOnGrid(solution, traj, options.dt, n_steps, kin);
  if (options.restart != Restart::None) addRestarts(grid, traj, options.dt, options.restart);
  for (long k = 0; k <= n_steps; ++k) {
    if (k % R.stride != 0 && k != n_steps) continue;
    R.t.push_back(grid.t[k]);
    R.q_opt.push_back(grid.q[k]);
    R.v_opt.push_back(grid.v[k]);
    kin.set(grid.q[k], grid.v[k]);
    R.energy_opt.push_back(kin.energy());
    R.u_applied.push_back(k < n_steps ? grid.u[k] : grid.u[k - 1]);
  }
  if (tr.method() == collocation::Method::FirstOrder && options.tolerance <= 0) {
    double speed = 0, step = 0;
    for (const Eigen::VectorXd& v : grid.v) speed = std::max(speed, v.cwiseAbs().maxCoeff());
    const std::vector<double> steps = traj.meshTimes();  // a first-order element is one step
    for (std::size_t n = 1; n < steps.size(); ++n) step = std::max(step, steps[n] - steps[n - 1]);
    R.method_allowance = speed * step;
    R.tolerance += R.method_allowance;
  }
  R.optimised_events = optimisedEvents(solution, traj, grid, options, kin);

  for (EngineKind which : options.engines) R.engines.push_back(replayIn(which, scene, problem, grid, options, R, kin));
  return R;
}

}  // namespace saltus::verify
