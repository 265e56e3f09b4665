// The runs behind `saltus bench` (cli/bench.cpp): both engines (verify/engine.hpp) set up from the
// options, untimed runs that record what an error needs, timed runs, and how a run's error is
// measured on each built-in validation scene.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scene/scene.hpp"
#include "timestepper/stepper.hpp"
#include "verify/bullet_world.hpp"
#include "verify/engine.hpp"

namespace saltus::cli::bench {

using scene::Scene;

// ---------------------------------------------------------------------------------------------
// engines: the saltus time-stepper and Bullet's btMultiBodyDynamicsWorld (verify/bullet_world.hpp)

using verify::Engine;
using verify::EngineKind;
using verify::EngineOptions;

// --engine: saltus, bullet or both; UsageError otherwise.
std::vector<EngineKind> parseEngineOption(const std::string& value);
verify::BulletSolver parseBulletSolverOption(const std::string& value);

timestepper::StepperOptions stepperOptions(double dt, double theta, timestepper::LcpMethod solver);

// One engine set up for a run, and the line that describes it in a benchmark's output.
EngineOptions engineSetup(EngineKind kind, double dt, double theta, timestepper::LcpMethod solver,
                          verify::BulletSolver bullet_solver, bool locate_impacts);
std::string describe(const EngineOptions& setup);

// ---------------------------------------------------------------------------------------------
// errors

// The scene's parameters as "name=value, ..."; a parameter's value (NaN when absent).
std::string parameterList(const Scene& scene);
double parameter(const Scene& scene, const std::string& name);

// How a run's error is measured:
//  - BallApex (ball_drop): |first apex − e² h0| (timestepper/analytic.hpp);
//  - RockingTilt (rocking_block): |largest tilt between the first two impacts − Housner's|
//    (timestepper/analytic.hpp);
//  - Slide (block_slide): |s(T) − s_exact(T)|;
//  - Velocities (newtons_cradle, resting balls touching, or apart with e = 1): |v(T) − v_exact|
//    after the impacts (timestepper/analytic.hpp);
//  - Exact (painleve_rod, pendulum_conveyor): |[q; v](T) − exact(T)|, the exact motion of a contact
//    that sticks after an impact without collision (timestepper/sticking_motion.hpp), used when
//    sticking holds until T;
//  - Reference (any other scene, or those two outside the sticking assumption): |[q; v](T) −
//    x_ref(T)| against a saltus run at dt_min/16 with θ = ½.
struct ErrorModel {
  enum Kind { BallApex, RockingTilt, Slide, Velocities, Exact, Invariants, Reference } kind = Reference;
  std::string description;
  int tracked = -1;  // the coordinate a run records after every step (BallApex, RockingTilt), −1: none
  // BallApex: the apex height; RockingTilt: the tilt
  double apex_exact = 0;
  // Slide
  int s_index = -1;
  double v0 = 0, mu = 0, alpha = 0, g = 0;
  // Velocities: v after the impacts
  Eigen::VectorXd v_exact;
  // Exact: [q; v] at time t
  std::function<Eigen::VectorXd(double)> exact;
  // Invariants: the drift of conserved quantities at the end state [q; v]
  std::function<double(const Eigen::VectorXd&)> drift;
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
  std::vector<double> z, pn;     // the tracked coordinate and contact 0's normal impulse after every step
};
// Runs `steps` steps; records coordinate `tracked` (and contact 0's impulse) after each, unless −1.
RecordedRun recordRun(const Scene& scene, const EngineOptions& setup, long steps, int tracked);

// The error model of a scene for runs of `duration` at the time steps `dts` (their end times
// are multiples of dt at or after `duration`); a Reference run or the Exact motion is evaluated
// at every end time. Progress notes on stderr.
ErrorModel makeErrorModel(const Scene& scene, const std::vector<double>& dts, double duration,
                          timestepper::LcpMethod solver);
// NaN for a failed run.
double runError(const ErrorModel& model, const RecordedRun& run);

// ---------------------------------------------------------------------------------------------
// timing

struct Timing {
  double wall = std::numeric_limits<double>::quiet_NaN();  // seconds per run, best of the repetitions
  double cpu = std::numeric_limits<double>::quiet_NaN();
  int repetitions = 0;
};
// Runs `steps` steps repeatedly (at least once, until min_time CPU seconds have been spent) and
// keeps the fastest wall and CPU time of a run. Only stepping is timed.
Timing timeRuns(const Scene& scene, const EngineOptions& setup, long steps, double min_time);

}  // namespace saltus::cli::bench
