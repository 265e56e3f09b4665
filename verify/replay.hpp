// Replaying an optimised trajectory (collocation/saved_solution.hpp) in a time-stepper: the
// Saltus Moreau–Stewart–Trinkle stepper (timestepper/stepper.hpp) and/or Bullet
// (bullet_world.hpp), from the optimisation's initial state, driven by its inputs, optionally with
// PD tracking of its states. What it measures: how far each engine's motion strays from the
// optimised one (state deviation over time), whether the contact events happen at the same
// times, penetration and energy. `saltus replay` (cli/replay.cpp) writes the result as a report.
//
// The scene: the Problem's scene, with every surface velocity given on the mesh
// (Problem::surface_steps, steps at [element, 0]) turned into a time schedule at the solved mesh
// times, velocity_schedule = {(t_element, v)} with t_element = meshTimes()[element] — the belt of
// pendulum_conveyor steps at the solved time of [6, 0]. Both engines apply a surface's velocity of
// the end of a step, v_surface(t + h), so a step at t_s acts from the first step ending at or
// after t_s.
//
// Inputs, step k over [t_k, t_k + h]: each input u_i acts on coordinate q_i as a generalised
// force, and the stepper holds one force over the step. It gets the mean of the collocation
// polynomial u(t) over the step, (1/h) ∫ u dt, by the P-point Gauss–Legendre rule on each part of
// the step inside one element (exact: u is of degree P − 1 in an element, and jumps only at mesh
// points). The mean gives the step the input's exact impulse ∫ u dt, which is what a
// velocity-level (impulse–momentum) step integrates, for any θ; with θ = ½ it is also the
// second-order choice (the midpoint value differs from the mean by O(h²) ü).
//
// PD feedback (Feedback::Pd), on the actuated coordinates only:
//   τ_i = ū_i + Kp (q*_i(t_k) − q_i) + Kd (v*_i(t_k) − v_i)
// with (q*, v*) the optimised state at the start of the step (the right limit at a velocity
// jump). Unactuated coordinates get no feedback: the replay must not add forces the system does
// not have. Kp [N/m or N·m/rad] and Kd [N·s/m or N·m·s/rad] are per coordinate, not scaled by
// the mass: the defaults (100, 20) are critically damped for a unit mass or inertia (ω = 10 rad/s,
// well resolved by any dt ≤ 1e-2).
//
// Restarts (Restart::Mesh): the replay starts again from the optimised state at every mesh point
// after the first, so each element's motion is checked from its own start and a small error does
// not grow through an unstable motion (a biped balancing on one foot, open loop, strays by metres
// within a second whatever the solution's accuracy: multiple shooting in place of single
// shooting). At mesh time t_n the engine is reset, at the start of the last step k with
// t_k ≤ t_n, to the optimised state at t_k before any jump (Side::Before), so the engine itself
// must produce the impulse at t_n: an impulse in mid-air still shows. The deviation then measures
// one element's worth of error; events are recorded as without restarts. Restart::MeshAfterJumps
// resets to the state after t_n's jump instead (the optimiser's impulse taken as given): the two
// side by side tell an impact the engine resolves differently from an element's smooth motion.
//
// Deviation, after every step at t_k: q − q*(t_k) and v − v*(t_k) per coordinate, with the
// optimised state the collocation polynomials' (CollocationTrajectory::at, Side::After: at a
// velocity jump the right limit). Per coordinate: the maximum |·|, the final value |·| at the
// last step and the RMS over the steps. The tolerance applies to the maximum position deviation
// over all coordinates (metres and radians alike).
//
// Contact events (scene contacts; joint-limit stops are not followed). A contact is closed when
// its gap ≤ gap_threshold. For the optimised trajectory and for each engine, on the same time
// grid (after every step):
//   touchdown   — the contact closes (open → closed);
//   lift-off    — it opens (closed → open);
//   impact      — a velocity jump: in the optimisation, a jump Δq̇ at a mesh point
//                 (CollocationTrajectory::jumps) larger than jump_threshold, put on the contact
//                 with the largest impulse there; in an engine, a step whose velocity change
//                 exceeds jump_threshold while the contact carries an impulse (a run of such steps
//                 is one impact, at its first step), put on the contact with the largest normal
//                 plus tangential impulse;
//   impact without collision — an impact whose contact was closed with no approach velocity
//                 (vn > −approach_threshold) just before it: a tangential (Painlevé) impulse, as
//                 at the belt's step of pendulum_conveyor.
// Each optimised event is matched to the nearest engine event of the same kind and contact
// within match_window; the time differences are reported, and the unmatched events of both.
//
// Penetration: the largest −gap over the steps and contacts, per engine.
// Energy: kinetic + gravitational potential, per engine and of the optimised state, over time.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "collocation/saved_solution.hpp"
#include "scene/scene.hpp"
#include "timestepper/stepper.hpp"
#include "verify/bullet_world.hpp"
#include "verify/engine.hpp"

namespace saltus::verify {

enum class Feedback { None, Pd };
const char* feedbackName(Feedback feedback);  // "none", "pd"
Feedback parseFeedback(const std::string& name);  // throws std::invalid_argument

enum class Restart { None, Mesh, MeshAfterJumps };
const char* restartName(Restart restart);  // "none", "mesh", "mesh-after-jumps"
Restart parseRestart(const std::string& name);  // throws std::invalid_argument

struct ReplayOptions {
  std::vector<EngineKind> engines{EngineKind::Saltus};
  double dt = 1e-4;
  // Saltus stepper: θ = ½ (Moreau's midpoint scheme, second order in free flight). Bullet is
  // semi-implicit Euler (first order) whatever this says.
  double theta = 0.5;
  Feedback feedback = Feedback::None;
  double kp = 100, kd = 20;
  Restart restart = Restart::None;  // Mesh (MeshAfterJumps): from the optimised state at every mesh point (above)
  // On the maximum position deviation [m or rad]; 0: tolerance_speed × dt (1 mm or 1 mrad at
  // the default dt). A replay differs from a feasible solution at first order in dt: an impact
  // or a belt step is resolved up to one step late, shifting the position by up to |Δv| dt, and
  // the semi-implicit schemes are first order through contact. Measured on point_mass_drop
  // (e = 0.5, |Δv| = 2.1 m/s): 6.4e-4, 7.2e-5 and 8.3e-6 m at dt 1e-3, 1e-4 and 1e-5 (Saltus),
  // 1.2e-3, 1.0e-4, 7.0e-6 m (Bullet), so 10 m/s × dt leaves a margin of ~10 for jumps of a
  // few m/s; a wrong input shows up far above it (README, `saltus replay`).
  // A first-order solution (Method::FirstOrder: backward Euler) differs from the exact motion by
  // its own O(h) error; the default tolerance of such a solution adds the travel of one of its
  // steps at its top speed (max |q̇_i| × longest step), which bounds that error: measured on the
  // drops and throws of bench/sweeps/contact_discovery.yaml, the deviations of the feasible
  // first-order solutions were 0.3–0.4 of it, while a missed bounce or a mid-air stop is a
  // height. A given tolerance (> 0) is applied as it is.
  double tolerance = 0;
  double tolerance_speed = 10;  // [m/s or rad/s]
  double resolvedTolerance() const { return tolerance > 0 ? tolerance : tolerance_speed * dt; }

  // Events.
  double gap_threshold = 1e-4;       // [m] a contact is closed when its gap is at most this
  double jump_threshold = 0.05;      // [m/s or rad/s] smallest velocity change counted as an impact
  double approach_threshold = 0.02;  // [m/s] approach speed below which an impact is without collision
  double match_window = 0.01;        // [s] largest time difference of matched events

  // A deliberately wrong input, to check that the tolerance catches it: u is replaced by
  // input_scale · u + input_offset (per input). Default: the optimised input.
  double input_scale = 1.0;
  Eigen::VectorXd input_offset;  // empty: none

  BulletWorldOptions bullet;  // dt is replaced by `dt`
  MujocoWorldOptions mujoco;  // dt is replaced by `dt`
  long max_series = 4000;     // the recorded time series keeps at most about this many samples
};

struct ContactEvent {
  enum Kind { Touchdown, LiftOff, Impact, ImpactWithoutCollision };
  Kind kind;
  int contact = -1;  // scene contact
  double t = 0;
};
const char* eventKindName(ContactEvent::Kind kind);  // "touchdown", "lift-off", "impact", "impact-without-collision"

struct EventMatch {
  ContactEvent optimised;
  bool matched = false;
  ContactEvent replayed;  // when matched
  double dt = 0;          // replayed.t − optimised.t
};

struct CoordinateDeviation {
  std::string coordinate;
  double max_q = 0, final_q = 0, rms_q = 0, t_max_q = 0;
  double max_v = 0, final_v = 0, rms_v = 0;
};

// Samples after every `stride`-th step (and the last).
struct ReplaySeries {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, v, dq, dv;  // state and deviation from the optimised one
  std::vector<double> energy, penetration;    // penetration: max −gap over the contacts (≥ 0)
};

struct EngineReplay {
  EngineKind engine;
  bool completed = false;  // false: the engine failed (message), figures up to the failure
  std::string message;
  long steps = 0;
  std::vector<CoordinateDeviation> coordinates;
  double max_position_deviation = 0, final_position_deviation = 0, rms_position_deviation = 0;
  double max_velocity_deviation = 0, final_velocity_deviation = 0;
  double t_max_position_deviation = 0;
  bool within_tolerance = false;
  double max_penetration = 0;
  double energy_start = 0, energy_end = 0;
  std::vector<ContactEvent> events;
  std::vector<EventMatch> matches;     // one per optimised event
  std::vector<ContactEvent> unmatched;  // replayed events no optimised event matched
  ReplaySeries series;
  // Bullet and MuJoCo: what the engine approximates of the scene.
  std::vector<std::string> approximations;
  // Bullet only.
  long mlcp_fallbacks = 0;
  // MuJoCo only.
  long mujoco_warnings = 0;
  // Saltus only.
  long lcp_failures = 0;
};

struct ReplayResult {
  std::string problem, source, method;
  double end_time = 0;
  long steps = 0;
  int stride = 1;
  std::vector<std::string> coordinates, contacts, inputs;  // names (inputs: their coordinates)
  std::vector<double> mesh_times;
  std::vector<scene::Surface> surfaces;  // with the velocity schedules used in the replay
  std::vector<ContactEvent> optimised_events;
  // The optimised trajectory on the series' time grid.
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q_opt, v_opt, u_applied;  // u_applied: mean input over the step (nominal)
  std::vector<double> energy_opt;
  std::vector<EngineReplay> engines;
  ReplayOptions options;
  double tolerance = 0;          // the one applied: options.resolvedTolerance() + method_allowance
  double method_allowance = 0;   // first order, default tolerance: max |q̇_i| × longest step
  bool withinTolerance() const;  // every engine completed and within tolerance
};

// The Problem's scene with its mesh surface steps placed at the solved mesh times.
scene::Scene replayScene(const collocation::SavedSolution& solution);

// Checks the options (dt > 0 and finite and at most T/10 of the solution, θ in [½, 1], gains ≥ 0,
// tolerance ≥ 0, input_offset size); throws std::invalid_argument naming the field.
void checkReplayOptions(const ReplayOptions& options, const collocation::SavedSolution& solution);

// Replays `solution` in each engine of options.engines. An engine that fails mid-run (an LCP
// failure, a non-finite state) is reported with completed = false; errors in the options throw
// std::invalid_argument; a scene Bullet cannot build throws std::invalid_argument.
ReplayResult replay(const collocation::SavedSolution& solution, const ReplayOptions& options);

}  // namespace saltus::verify
