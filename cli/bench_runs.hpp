// The runs behind `saltus bench` (cli/bench.cpp): both engines behind one face, untimed runs that
// record what an error needs, timed runs, and how a run's error is measured on each built-in
// validation scene.
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

namespace saltus::cli::bench {

using scene::Scene;

// ---------------------------------------------------------------------------------------------
// engines: the saltus time-stepper and Bullet's btMultiBodyDynamicsWorld (verify/bullet_world.hpp)

enum class Engine { Saltus, Bullet };
const char* engineName(Engine e);
// "saltus", "bullet" or "both"; UsageError otherwise.
std::vector<Engine> parseEngines(const std::string& value);
verify::BulletSolver parseBulletSolverOption(const std::string& value);

timestepper::StepperOptions stepperOptions(double dt, double theta, timestepper::LcpMethod solver);

// How one engine is set up for a run: the stepper options (saltus) or the world options (Bullet).
struct EngineSetup {
  Engine engine = Engine::Saltus;
  timestepper::StepperOptions saltus;
  verify::BulletWorldOptions bullet;
  std::string describe() const;
};
EngineSetup engineSetup(Engine engine, double dt, double theta, timestepper::LcpMethod solver,
                        verify::BulletSolver bullet_solver, bool locate_impacts);

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
std::unique_ptr<Sim> makeSim(const Scene& scene, const EngineSetup& e);

// ---------------------------------------------------------------------------------------------
// errors

// The scene's parameters as "name=value, ..."; a parameter's value (NaN when absent).
std::string parameterList(const Scene& scene);
double parameter(const Scene& scene, const std::string& name);

// How a run's error is measured:
//  - BallApex (ball_drop): |first apex − e² h0| (timestepper/analytic.hpp);
//  - Slide (block_slide): |s(T) − s_exact(T)|;
//  - Exact (painleve_rod, pendulum_conveyor): |[q; v](T) − exact(T)|, the exact motion of a contact
//    that sticks after an impact without collision (timestepper/sticking_motion.hpp), used when
//    sticking holds until T;
//  - Reference (any other scene, or those two outside the sticking assumption): |[q; v](T) −
//    x_ref(T)| against a saltus run at dt_min/16 with θ = ½.
struct ErrorModel {
  enum Kind { BallApex, Slide, Exact, Reference } kind = Reference;
  std::string description;
  // BallApex
  double apex_exact = 0;
  // Slide
  int s_index = -1;
  double v0 = 0, mu = 0, alpha = 0, g = 0;
  // Exact: [q; v] at time t
  std::function<Eigen::VectorXd(double)> exact;
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
RecordedRun recordRun(const Scene& scene, const EngineSetup& setup, long steps, bool keep_bounce);

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
Timing timeRuns(const Scene& scene, const EngineSetup& setup, long steps, double min_time);

}  // namespace saltus::cli::bench
