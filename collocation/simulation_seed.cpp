#include "collocation/simulation_seed.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "collocation/interpolation.hpp"
#include "collocation/solution.hpp"
#include "dynamics/dynamics.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::collocation {

namespace {

// The simulation on a uniform grid t_k = k dt: the state after every step and what each contact
// (scene contacts, then limit stops: the transcription's order) did over the step.
struct Simulated {
  double dt = 0;
  std::vector<Eigen::VectorXd> q, v;                       // k = 0 … K
  std::vector<std::vector<timestepper::ContactReport>> c;  // step k → k + 1, k = 0 … K − 1
  std::vector<bool> impact;                                // step k is impulsive
  std::vector<double> impact_time;                         // of an impulsive step: when in it the contact closes
  std::vector<double> transitions;  // times a contact opened, closed without impact, stuck or began to slide
  std::vector<Eigen::VectorXd> u;   // a tracking schedule's inputs over step k (empty: the schedule's own)

  long steps() const { return static_cast<long>(impact.size()); }
  long stepAt(double t) const { return std::clamp(static_cast<long>(std::floor(t / dt)), 0L, steps() - 1); }
  // An impulsive step that ends at t (an impact without collision is placed at its step's end).
  std::optional<long> impulsiveStepEndingAt(double t) const {
    const long k = std::lround(t / dt) - 1;
    if (k >= 0 && k < steps() && impact[k] && std::abs(static_cast<double>(k + 1) * dt - t) < 1e-9 * dt) return k;
    return std::nullopt;
  }
  // The first step of the run of impulsive steps at time t (containing it, or ending at it).
  std::optional<long> impactAt(double t) const {
    long k = stepAt(t);
    if (!impact[k]) {
      const auto e = impulsiveStepEndingAt(t);
      if (!e) return std::nullopt;
      k = *e;
    }
    while (k > 0 && impact[k - 1]) --k;
    return k;
  }
  // The nearest step to k that is not impulsive (forces, accelerations), k itself when it is not.
  long smoothStep(long k) const {
    for (long d = 0; d < steps(); ++d) {
      if (k - d >= 0 && !impact[k - d]) return k - d;
      if (k + d < steps() && !impact[k + d]) return k + d;
    }
    return k;
  }
  // The state at t; inside an impulsive step the state before the impact (Side::Before),
  // carried forward from the step's start with the acceleration of the smooth step before it, or
  // after it, carried back from the step's end with the acceleration of the smooth step after it.
  void state(double t, Side side, Eigen::VectorXd& q_out, Eigen::VectorXd& v_out) const {
    const long k = side == Side::Before ? impulsiveStepEndingAt(t).value_or(stepAt(t)) : stepAt(t);
    if (impact[k]) {
      const long j = side == Side::Before ? std::max(0L, k - 1) : std::min(steps() - 1, k + 1);
      const Eigen::VectorXd a = impact[j] ? Eigen::VectorXd::Zero(q[k].size()) : Eigen::VectorXd((v[j + 1] - v[j]) / dt);
      const long i = side == Side::Before ? k : k + 1;
      const double tau = t - static_cast<double>(i) * dt;  // ≥ 0 before, ≤ 0 after
      q_out = q[i] + tau * v[i] + 0.5 * tau * tau * a;
      v_out = v[i] + tau * a;
      return;
    }
    // Cubic Hermite in q through both states (exact for the quadratic free flight that θ = ½
    // integrates exactly), linear in v.
    const double s = std::clamp(t / dt - static_cast<double>(k), 0.0, 1.0), s2 = s * s, s3 = s2 * s;
    q_out = (2 * s3 - 3 * s2 + 1) * q[k] + (s3 - 2 * s2 + s) * dt * v[k] + (-2 * s3 + 3 * s2) * q[k + 1] +
            (s3 - s2) * dt * v[k + 1];
    v_out = (1 - s) * v[k] + s * v[k + 1];
  }
};

// Each contact's mode after every step (open; closed and sticking; closed and sliding), and the
// times it changes for at least `kPersist` steps. A change within an impulsive step is the
// impact's own and not listed; a slip that stops is placed at its step's end, other changes at
// their step's start.
class ModeTracker {
 public:
  explicit ModeTracker(const scene::Scene& scene) {
    for (const scene::Contact& c : scene.contacts) friction_.push_back(c.friction > 0);
    friction_.resize(scene.contacts.size() + scene.limits.size(), false);
    mode_.assign(friction_.size(), kUnknown);
    candidate_.assign(friction_.size(), kUnknown);
    since_.assign(friction_.size(), 0);
  }
  void update(long k, const std::vector<timestepper::ContactReport>& reports, Simulated& s) {
    for (std::size_t c = 0; c < reports.size(); ++c) {
      const timestepper::ContactReport& r = reports[c];
      const bool closed = r.pn > 0 || r.gap <= 1e-6;
      const char m = !closed ? kOpen : friction_[c] && std::hypot(r.vt1, r.vt2) > 1e-5 ? kSlide : kStick;
      if (mode_[c] == kUnknown) mode_[c] = m;
      if (m == mode_[c]) {
        candidate_[c] = kUnknown;
        continue;
      }
      if (m != candidate_[c]) {
        candidate_[c] = m;
        since_[c] = k;
      }
      if (k - since_[c] + 1 < kPersist) continue;
      const long j = since_[c];
      bool impulsive = false;
      for (long i = std::max(0L, j - 1); i <= std::min(k, j + 1); ++i) impulsive = impulsive || s.impact[i];
      if (!impulsive)
        s.transitions.push_back(static_cast<double>(mode_[c] == kSlide && m == kStick ? j + 1 : j) * s.dt);
      mode_[c] = m;
      candidate_[c] = kUnknown;
    }
  }

 private:
  static constexpr char kUnknown = 0, kOpen = 1, kStick = 2, kSlide = 3;
  static constexpr long kPersist = 5;
  std::vector<bool> friction_;
  std::vector<char> mode_, candidate_;
  std::vector<long> since_;
};

// With a schedule, step k is driven by the scene's constant input plus the schedule's inputs at
// its middle, (k + ½) dt, on the problem's actuated coordinates: a change within a step acts from
// the nearer of its ends, and one on a step's end from that end, whatever the rounding of k dt.
// A tracking schedule adds its feedback on the state at the step's start (its reference at the
// step's middle) and clamps to the inputs' bounds; what it applied is kept (Simulated::u).
Simulated simulate(const scene::Scene& scene, double dt, double duration, const Problem& p,
                   const InputSchedule* schedule = nullptr) {
  timestepper::StepperOptions o;
  o.dt = dt;
  o.theta = 0.5;
  timestepper::TimeStepper stepper(scene, o);
  stepper.reset(scene.q0, scene.v0);
  Simulated s;
  s.dt = dt;
  const long K = std::max(1L, static_cast<long>(std::ceil(duration / dt)));
  s.q.push_back(scene.q0);
  s.v.push_back(scene.v0);
  const double jump = 20 * scene.model.gravity.norm() * dt;
  std::vector<timestepper::ContactReport> start = stepper.contacts();  // before step k
  ModeTracker modes(scene);
  try {
    const int nv = scene.model.nv();
    const Eigen::VectorXd tau_base = scene.tau.size() == nv ? scene.tau : Eigen::VectorXd::Zero(nv);
    Eigen::VectorXd tau(nv), u, q_ref, v_ref;
    const Tracking* tracking = schedule && schedule->tracking ? &*schedule->tracking : nullptr;
    for (long k = 0; k < K; ++k) {
      if (schedule) {
        const double middle = (static_cast<double>(k) + 0.5) * dt;
        u = schedule->at(middle);
        if (tracking) {
          tracking->reference(middle, q_ref, v_ref);
          for (std::size_t i = 0; i < p.inputs.size(); ++i) {
            const auto j = static_cast<Eigen::Index>(i);
            const int c = p.inputs[i];
            u[j] += tracking->kp[j] * (q_ref[j] - stepper.q()[scene.model.positionOf(c)]) +
                    tracking->kd[j] * (v_ref[j] - stepper.v()[c]);
          }
          u = u.cwiseMax(p.input_lower).cwiseMin(p.input_upper);
          s.u.push_back(u);
        }
        tau = tau_base;
        for (std::size_t i = 0; i < p.inputs.size(); ++i) tau[p.inputs[i]] += u[static_cast<Eigen::Index>(i)];
        stepper.setInput(tau);
      }
      stepper.step();
      s.q.push_back(stepper.q());
      s.v.push_back(stepper.v());
      s.c.push_back(stepper.contacts());
      // The contact with the largest impulse; the step is impulsive when the velocity changes by
      // more than finite forces would.
      int strongest = -1;
      double largest = 0;
      for (int c = 0; c < static_cast<int>(stepper.contacts().size()); ++c) {
        const timestepper::ContactReport& r = stepper.contacts()[c];
        const double p = r.pn + std::hypot(r.pt1, r.pt2);
        if (p > largest) largest = p, strongest = c;
      }
      const bool impulsive = strongest >= 0 && (s.v[k + 1] - s.v[k]).cwiseAbs().maxCoeff() > jump;
      s.impact.push_back(impulsive);
      // When the contact closes within the step: its gap at the start over its approach speed
      // (0 for a contact that was closed: an impact without collision).
      // A contact that was closed (an impact without collision, e.g. a belt's step): at the step's
      // end, where a surface's velocity step acts.
      double t_close = static_cast<double>(k + 1) * dt;
      if (impulsive && k > 0 && start[strongest].gap > 0 && start[strongest].vn < 0)
        t_close = static_cast<double>(k) * dt + std::min(dt, start[strongest].gap / -start[strongest].vn);
      s.impact_time.push_back(t_close);
      start = stepper.contacts();
      modes.update(k, stepper.contacts(), s);
    }
  } catch (const timestepper::SimulationError& e) {
    throw std::runtime_error(std::string("simulation seed: the time-stepper failed: ") + e.what());
  }
  return s;
}

// The element lengths that put each impact on the nearest boundary (see the header).
// An impact within 1.5 dt of a surface's step on the mesh is that step's (its time is the mesh's).
std::vector<double> placeMesh(const Problem& p, double h0, std::vector<double> events, const std::vector<double>& starts,
                              double dt, std::vector<double>& placed) {
  for (double& t : events)
    for (const auto& [surface, steps] : p.surface_steps)
      for (const SurfaceStep& s : steps)
        if (std::abs(t - starts[s.element]) < 1.5 * dt) t = starts[s.element];
  const int N = p.N;
  const double h_min = p.h_min_ratio * p.h_max, h_max = p.h_max;
  // Anchors: (boundary index, time), strictly increasing in both.
  std::vector<std::pair<int, double>> anchors = {{0, 0.0}};
  for (double t : events) {
    if (N < 2) break;
    int b = std::clamp(static_cast<int>(std::lround(t / h0)), 1, N - 1);
    const auto [b_prev, t_prev] = anchors.back();
    const double span = t - t_prev;
    auto reachable = [&](int boundary) {  // from the previous anchor with lengths in [h_min, h_max]
      const int steps = boundary - b_prev;
      return boundary > b_prev && boundary <= N - 1 && span >= steps * h_min && span <= steps * h_max;
    };
    // The nearest boundary of the uniform mesh, unless the anchors before have drifted from it
    // (with elements at their longest, h0 = h_max, an event late for its boundary can only take a
    // later one, and so every event after it): then counted from the previous anchor, or the
    // next boundary, or the one before. An event within h0 / 2 of the previous one shares its
    // boundary (left out).
    if (b <= b_prev || !reachable(b)) {
      const int steps = static_cast<int>(std::lround(span / h0));
      if (steps < 1) continue;
      const int r = b_prev + steps;
      b = reachable(r) ? r : reachable(r + 1) ? r + 1 : reachable(r - 1) ? r - 1 : -1;
      if (b < 0) continue;
    }
    anchors.push_back({b, t});
  }
  placed.clear();
  for (std::size_t i = 1; i < anchors.size(); ++i) placed.push_back(anchors[i].second);
  std::vector<double> h(N, h0);
  for (std::size_t i = 0; i + 1 < anchors.size(); ++i) {
    const auto [b0, t0] = anchors[i];
    const auto [b1, t1] = anchors[i + 1];
    for (int n = b0; n < b1; ++n) h[n] = (t1 - t0) / (b1 - b0);
  }
  // After the last impact: the total time's condition.
  const auto [b_last, t_last] = anchors.back();
  double rest = h0;
  if (p.total_time_kind == TotalTime::Equal) rest = (p.total_time - t_last) / (N - b_last);
  if (p.total_time_kind == TotalTime::AtLeast) rest = std::max(h0, (p.total_time - t_last) / (N - b_last));
  for (int n = b_last; n < N; ++n) h[n] = std::clamp(rest, h_min, h_max);
  return h;
}

// The uniform element length the simulation starts from (see the header); a schedule's horizon
// (> 0) in place of the middle of the bounds.
double initialElementLength(const Problem& p, double horizon = 0) {
  const double h_min = p.h_min_ratio * p.h_max, h_max = p.h_max;
  double h0 = horizon > 0 ? horizon / p.N : 0.5 * (h_min + h_max);
  if (p.total_time_kind == TotalTime::Equal) h0 = p.total_time / p.N;
  if (p.total_time_kind == TotalTime::AtLeast) h0 = std::max(h0, p.total_time / p.N);
  return std::clamp(h0, h_min, h_max);
}

}  // namespace

Eigen::VectorXd seedFromSimulation(const Transcription& t, SimulationSeedReport* report, const InputSchedule* schedule) {
  const Problem& p = t.problem();
  const int N = p.N, nv = p.scene.model.nv();
  const double h_max = p.h_max;
  const double h0 = initialElementLength(p, schedule ? schedule->horizon() : 0);
  const double dt = h0 / 40;

  auto starts = [&](const std::vector<double>& h) {
    std::vector<double> s(N + 1, 0.0);
    for (int n = 0; n < N; ++n) s[n + 1] = s[n] + h[n];
    return s;
  };
  // Mesh ↔ simulation: a surface stepping on the mesh steps at its mesh point's time.
  std::vector<double> h(N, h0), placed;
  Simulated sim;
  int iterations = 0;
  for (;;) {
    ++iterations;
    const std::vector<double> simulated_starts = starts(h);
    sim = simulate(sceneAtMeshTimes(p, simulated_starts), dt, N * h_max + dt, p, schedule);
    std::vector<double> events = sim.transitions;
    for (long k = 0; k < sim.steps(); ++k)
      if (sim.impact[k] && (k == 0 || !sim.impact[k - 1])) events.push_back(sim.impact_time[k]);
    std::sort(events.begin(), events.end());
    h = placeMesh(p, h0, events, simulated_starts, dt, placed);
    const std::vector<double> now = starts(h);
    bool moved = false;
    for (const auto& [surface, steps] : p.surface_steps)
      for (const SurfaceStep& s : steps) moved = moved || std::abs(now[s.element] - simulated_starts[s.element]) > 0.5 * dt;
    if (!moved || iterations == 4) break;
  }

  // Resample onto the transcription's points (the first-order method: several steps per element).
  Eigen::VectorXd x = t.nullSeed();
  const int per_element = t.method() == Method::FirstOrder ? p.first_order_steps_per_element : 1;
  const auto& contacts = t.contacts();
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  const int nu = static_cast<int>(p.inputs.size());
  Eigen::VectorXd q, v, q_before, v_before;
  double t0 = 0;
  for (int m = 0; m < t.elements(); ++m) {
    const ElementLayout& L = t.layout()[m];
    const double hm = h[m / per_element] / per_element;
    x[L.h] = hm;
    // The impulsive steps at this boundary (the impulsive [n, 0]).
    const std::optional<long> impact_here = m > 0 ? sim.impactAt(t0) : std::nullopt;
    // Without velocity jumps (continuous, first order) the element that starts at an impact
    // spreads it: the velocity goes from the one before it to the one after over the element,
    // through the impulse as a force over the element's length.
    const bool spread = impact_here && L.points[0].accel_or_jump < 0;
    Eigen::VectorXd jump = Eigen::VectorXd::Zero(nv);
    if (spread) {
      sim.state(t0, Side::Before, q_before, v_before);
      sim.state(t0, Side::After, q, v);
      jump = v - v_before;
    }
    // The impulses of the impact at this boundary, per contact.
    auto impulse = [&](std::size_t c, double& pn, double& pt1, double& pt2) {
      pn = pt1 = pt2 = 0;
      for (long j = impact_here.value_or(sim.steps()); j < sim.steps() && sim.impact[j]; ++j) {
        pn += sim.c[j][c].pn;
        pt1 += sim.c[j][c].pt1;
        pt2 += sim.c[j][c].pt2;
      }
    };
    for (std::size_t pi = 0; pi < L.points.size(); ++pi) {
      const double time = t0 + hm * L.tau[pi];
      const bool start = pi == 0, end = static_cast<int>(pi) == L.end;
      sim.state(time, end ? Side::Before : Side::After, q, v);
      const auto& pt = L.points[pi];
      x.segment(pt.q, nv) = q;
      x.segment(pt.v, nv) = v - (1 - L.tau[pi]) * jump;
      if (pt.u >= 0 && nu > 0) {
        if (!sim.u.empty())
          x.segment(pt.u, nu) = sim.u[static_cast<std::size_t>(sim.stepAt(time))];
        else if (schedule)
          x.segment(pt.u, nu) = schedule->at(time);
        else
          x.segment(pt.u, nu).setZero();
      }
      const long k = sim.smoothStep(sim.stepAt(time));
      if (pt.accel_or_jump >= 0) {
        if (start) {
          sim.state(time, Side::Before, q_before, v_before);
          x.segment(pt.accel_or_jump, nv) = v - v_before;  // Δq̇ at [n, 0]
        } else {
          x.segment(pt.accel_or_jump, nv) = (sim.v[k + 1] - sim.v[k]) / sim.dt + jump / hm;
        }
      }
      dynamics::forwardKinematics(model, data, q);  // the contact frames at this point
      for (std::size_t c = 0; c < contacts.size(); ++c) {
        const auto& C = L.contacts[c];
        if (C.rn[pi] < 0) continue;
        // At an impulsive [n, 0] the impulse of the impact steps there; elsewhere the mean force.
        double pn = 0, pt1 = 0, pt2 = 0;
        if (start) {
          impulse(c, pn, pt1, pt2);
        } else {
          pn = sim.c[k][c].pn / sim.dt;
          pt1 = sim.c[k][c].pt1 / sim.dt;
          pt2 = sim.c[k][c].pt2 / sim.dt;
          if (spread) {
            double Pn, Pt1, Pt2;
            impulse(c, Pn, Pt1, Pt2);
            pn += Pn / hm;
            pt1 += Pt1 / hm;
            pt2 += Pt2 / hm;
          }
        }
        x[C.rn[pi]] = pn;
        const ContactPair& cp = contacts[c];
        if (cp.k() == 0 || cp.isStop()) continue;
        // The stepper reports tangential quantities in the pair's tangent basis (the contact
        // layer's frame at this state).
        const Eigen::Matrix<double, 3, 2> T = contact::planeFrame(cp, data).tangents;
        const Eigen::Matrix3Xd d = contact::frictionDirections(cp, data);
        const Eigen::Vector3d f_t = pt1 * T.col(0) + pt2 * T.col(1);
        const timestepper::ContactReport& r = sim.c[sim.stepAt(time)][c];
        const Eigen::Vector3d v_t = r.vt1 * T.col(0) + r.vt2 * T.col(1);  // the slip
        // The direction d_i closest to a vector.
        auto closest = [&](const Eigen::Vector3d& w) {
          int best = 0;
          for (int i = 1; i < cp.k(); ++i)
            if (d.col(i).dot(w) > d.col(best).dot(w)) best = i;
          return best;
        };
        if (t.method() == Method::FirstOrder) {
          const int i = closest(f_t);  // β: the friction force along d_i
          x[C.tangential[pi] + i] = std::max(0.0, d.col(i).dot(f_t));
        } else if (v_t.norm() > 1e-6) {
          x[C.tangential[pi] + closest(v_t)] = 1;  // sliding (or open): Σα = 1 along the slip (eqs. 11–13)
        } else if (cp.friction * pn > 0) {
          // sticking: the force −μ r_n Σ d_i α_i (eq. 11) is the simulated friction f_t
          const int i = closest(-f_t);
          x[C.tangential[pi] + i] = std::min(1.0, std::max(0.0, -d.col(i).dot(f_t)) / (cp.friction * pn));
        }
      }
    }
    t0 += hm;
  }
  t.makeConsistent(x);
  if (report) {
    report->dt = dt;
    report->events = placed;
    report->mesh_times = starts(h);
    report->iterations = iterations;
  }
  return x;
}

std::vector<HintReach> checkHints(const Transcription& t) {
  const Problem& p = t.problem();
  std::vector<HintReach> out;
  const double h_min = p.h_min_ratio * p.h_max, h_max = p.h_max;
  const double h0 = initialElementLength(p);
  std::vector<double> starts(p.N + 1, 0.0);
  for (int n = 0; n < p.N; ++n) starts[n + 1] = starts[n] + h0;
  std::optional<Simulated> sim;
  for (const PointBound& b : p.hints) {
    // at one point only (a bound on every element or point is a condition, not a contact event)
    if (b.quantity.kind != Quantity::Kind::Gap || b.upper > 1e-6 || b.element < 0 || b.point < 0) continue;
    if (!sim) sim = simulate(sceneAtMeshTimes(p, starts), h0 / 40, p.N * h_max + h0, p);
    HintReach r;
    r.origin = b.origin;
    r.contact = t.contacts().at(b.quantity.index).name;
    r.actuated = !p.inputs.empty();
    r.element = b.element;
    r.point = b.point;
    const double tau = r.point == 0 ? 0.0 : r.point > p.P ? 1.0 : LegendreGauss(p.P).tau[r.point - 1];
    r.earliest = (r.element + tau) * h_min;
    r.latest = (r.element + tau) * h_max;
    for (long k = 0; k < sim->steps(); ++k) {
      const timestepper::ContactReport& c = sim->c[k][b.quantity.index];
      const double time = static_cast<double>(k + 1) * sim->dt;
      if (c.pn > 0 || c.gap <= 1e-6) {
        if (r.closes < 0) r.closes = time;
        if (time >= r.earliest - sim->dt && time <= r.latest + sim->dt) {
          r.reachable = true;
          break;
        }
      }
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace saltus::collocation

namespace saltus::collocation {

InputSchedule scheduleFromInputs(const Transcription& t, const Eigen::VectorXd& x) {
  const Problem& p = t.problem();
  const int m = static_cast<int>(p.inputs.size());
  if (m == 0) throw std::invalid_argument("a schedule from a point's inputs needs a problem with inputs");
  InputSchedule s;
  s.path = "the inputs of the previous attempt";
  double start = 0;
  const auto push = [&](double time, const Eigen::VectorXd& u) {
    if (!s.times.empty() && time <= s.times.back()) return;  // a zero-length interval holds nothing
    s.times.push_back(time);
    s.values.push_back(u.cwiseMax(p.input_lower).cwiseMin(p.input_upper));
  };
  for (const ElementLayout& L : t.layout()) {
    const double h = x[L.h];
    // Each collocation point's inputs from halfway after the previous one (the element's start
    // for the first) to halfway to the next: a zero-order hold centred on the points.
    double previous = -1;
    for (std::size_t c = 0; c < L.points.size(); ++c) {
      if (L.points[c].u < 0) continue;  // the collocation points (the first-order method's steps)
      const double time = start + L.tau[c] * h;
      push(previous < 0 ? start : 0.5 * (previous + time), x.segment(L.points[c].u, m));
      previous = time;
    }
    start += h;
  }
  s.times.push_back(start);  // the horizon: the point's total time
  s.values.push_back(s.values.back());
  return s;
}

Tracking trackingFromPoint(const Transcription& t, const Eigen::VectorXd& x, double omega) {
  const Problem& p = t.problem();
  const auto& model = t.models().model<double>();
  const int m = static_cast<int>(p.inputs.size());
  if (m == 0) throw std::invalid_argument("tracking a point's motion needs a problem with inputs");
  if (!(omega > 0)) throw std::invalid_argument("tracking: expected a natural frequency > 0 rad/s");
  Tracking tr;
  for (const Sample& s : trajectory(t, x)) {
    Eigen::VectorXd q(m), v(m);
    for (int i = 0; i < m; ++i) {
      q[i] = s.q[model.positionOf(p.inputs[i])];
      v[i] = s.v[p.inputs[i]];
    }
    tr.times.push_back(s.t);
    tr.q.push_back(std::move(q));
    tr.v.push_back(std::move(v));
  }
  // Each coordinate a critically damped oscillator of natural frequency ω on its own inertia
  // (the diagonal of M(q0), RBDA §6.2), the rest of the system held still.
  dynamics::Data<double> data(model);
  const Eigen::MatrixXd& M = dynamics::crba(model, data, p.scene.q0);
  tr.kp.resize(m);
  tr.kd.resize(m);
  for (int i = 0; i < m; ++i) {
    const double inertia = M(p.inputs[i], p.inputs[i]);
    tr.kp[i] = inertia * omega * omega;
    tr.kd[i] = 2 * inertia * omega;
  }
  return tr;
}

Eigen::VectorXd seedFromResimulation(const Transcription& t, const Eigen::VectorXd& x, SimulationSeedReport* report,
                                     double tracking) {
  InputSchedule schedule = scheduleFromInputs(t, x);
  if (tracking > 0) schedule.tracking = trackingFromPoint(t, x, tracking);
  return seedFromSimulation(t, report, &schedule);
}

}  // namespace saltus::collocation
