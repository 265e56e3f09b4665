// Saltus' library API: what a user scripts, in one header. Load a model, scene or problem (with
// parameter overrides), simulate, optimise, replay, render; each operation returns a result
// object, and writing its files is a separate call. The `saltus` command (cli/) and the Python
// module are thin layers over these functions: they parse their options, call, and print.
//
//   #include "saltus/saltus.hpp"
//   const saltus::scene::Scene scene = saltus::loadScene("ball_drop", {{"restitution", 0.5}});
//   const saltus::Simulation run = saltus::simulate(scene, {.dt = 1e-3});
//   saltus::writeTrajectoryCsv("ball.csv", run);
//
// Errors: bad options throw std::invalid_argument naming the option's field; bad files throw the
// loaders' errors (scene::ScenarioError, collocation::ProblemError, collocation::SolutionError,
// dynamics::ModelError, all std::runtime_error) with file, line and key; a time-stepper failure
// throws timestepper::SimulationError. A solve that ends infeasible is a result (its report says
// so, with Ipopt's status per stage), not an exception.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solution.hpp"
#include "collocation/solver.hpp"
#include "collocation/transcription.hpp"
#include "dynamics/model.hpp"
#include "render/animation.hpp"
#include "render/renderer.hpp"
#include "render/trajectory_source.hpp"
#include "scene/scenario.hpp"
#include "scene/trajectory_csv.hpp"
#include "timestepper/stepper.hpp"
#include "verify/replay.hpp"

namespace saltus {

// Parameter overrides by name: the `--set name=value` of the command line.
using Parameters = std::map<std::string, double>;

// ---------------------------------------------------------------------------------------------
// Loading (the loaders of dynamics/, scene/ and collocation/)

// A URDF model with the given base (fixed, planar or free); throws dynamics::ModelError naming
// the file and element.
dynamics::Model<double> loadModel(const std::string& urdf_path, dynamics::BaseType base);
// A built-in scene (ball_drop, …) or a scenario file; throws scene::ScenarioError.
using scene::loadScene;
// A built-in problem (point_mass_drop, …) or a problem file; throws collocation::ProblemError.
using collocation::loadProblem;

// ---------------------------------------------------------------------------------------------
// Simulation with the Moreau–Stewart–Trinkle time-stepper (timestepper/stepper.hpp)

struct SimulateOptions {
  double dt = 1e-3;       // time step [s]
  double duration = 0;    // simulated time [s]; 0: the scene's
  double theta = 1.0;     // θ-method, in [½, 1] (1: Stewart–Trinkle, ½: Moreau's midpoint)
  timestepper::LcpMethod solver = timestepper::LcpMethod::Lemke;
  long every = 1;         // samples kept: t = 0, after every `every`-th step, and after the last
};

// Steps that cover `duration`: round(duration/dt) when that is within 1e-9 relative of an
// integer, else the next integer up; at least 1. Throws std::invalid_argument when duration/dt
// is not a finite number below 2^53 (a count that would overflow or lose steps).
long stepCount(double duration, double dt);

// Checks the options (dt > 0 and finite, duration ≥ 0 and finite, θ in [½, 1], every ≥ 1); throws
// std::invalid_argument naming the field ("dt: expected …").
void checkSimulateOptions(const SimulateOptions& options);

// The samples a run of `scene` keeps (t = 0, every `every`-th step, the last), and the size of its
// trajectory CSV, estimated before it runs at 16 bytes a value (what "%.12g" numbers average).
long sampleCount(const scene::Scene& scene, const SimulateOptions& options);
double csvBytesEstimate(const scene::Scene& scene, const SimulateOptions& options);
// The memory the in-memory simulate() may take for its arrays [bytes]: above it, it refuses.
constexpr double kMaxSimulationBytes = 4e9;

// A surface moves at some time or an input is non-zero: the scene is driven from outside, and
// its energy is not expected to decrease.
bool isDriven(const scene::Scene& scene);

// One sample of a run: at t = 0 and after every step.
struct SimulationSample {
  double t = 0;
  Eigen::VectorXd q, v;
  std::vector<timestepper::ContactReport> contacts;  // scene contacts, then limit stops
};

// What a run did, without its samples.
struct SimulationSummary {
  std::string scene;
  SimulateOptions options;  // with the duration used
  timestepper::StepperStats stats;
  double end_time = 0;
  double energy_start = 0, energy_end = 0;  // kinetic + potential [J]
  bool driven = false;  // isDriven(scene): input or belt work is in the energy change
  double wall_seconds = 0;  // stepping only (not the consumer of the samples)
};

// Runs the stepper and hands every sample to `sink`, in order, in batches between the timed
// stretches of stepping (memory stays bounded, whatever the duration). Throws
// timestepper::SimulationError when a step fails (its message says at which step and why).
SimulationSummary simulate(const scene::Scene& scene, const SimulateOptions& options,
                           const std::function<void(const SimulationSample&)>& sink);

// A run held in memory: one row per sample, row-major (NumPy's layout).
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
struct ContactHistory {
  std::string name;
  Eigen::VectorXd gap, vn, vt1, vt2;  // [m], [m/s] in the contact frame (vt2 = 0 when planar)
  Eigen::VectorXd pn, pt1, pt2;       // impulses over the step ending at the sample [N s]
  Eigen::VectorXd s1, s2;             // on a body's plane: the point's plane coordinates [m] (else 0)
};
struct Simulation {
  SimulationSummary summary;
  scene::TrajectoryLayout layout;  // coordinate and contact names
  Eigen::VectorXd t;               // [s]
  RowMatrix q, v;                  // samples × coordinates
  std::vector<ContactHistory> contacts;  // the layout's contacts, in order
};
Simulation simulate(const scene::Scene& scene, const SimulateOptions& options);

// The trajectory CSV (scene/trajectory_csv.hpp) of a run in memory, or one row of a streamed run.
void writeTrajectoryCsv(const std::string& path, const Simulation& simulation);
void writeSample(scene::TrajectoryCsvWriter& writer, const SimulationSample& sample);

// ---------------------------------------------------------------------------------------------
// Trajectory optimisation through contact (collocation/)

// A solve's method and its changes to the problem (each unset one leaves the problem's own).
struct OptimizeOptions {
  collocation::Method method = collocation::Method::Impulsive;
  std::optional<int> N, P;                      // elements; collocation points per element (1 … 9)
  std::optional<unsigned> random_seed;          // of the initial guess's perturbation
  std::optional<collocation::SeedKind> seed_kind;  // null, perturbed, simulation, perturbed-simulation
  std::string seed_from;                        // start from an earlier solution (its folder)
  // A two-step solve: first with this method from the seed the other options describe, then
  // this solve from its solution (collocation/saved_solution.hpp's seedFromSolution: states,
  // accelerations and inputs resampled), unperturbed. Another method than `method`; not with
  // seed_from.
  std::optional<collocation::Method> seed_method;
  std::string seed_inputs;                      // an input schedule driving a simulation seed (its CSV)
  std::optional<double> seed_scale;             // size of the random perturbation (≥ 0)
  std::optional<int> restarts;                  // further attempts after an infeasible end (≥ 0)
  std::optional<int> resimulations;             // re-simulated attempts after each infeasible one (≥ 0)
  std::optional<double> resimulation_tracking;  // their inputs' feedback on the attempt's motion [rad/s] (0: none)
  std::optional<bool> exact_hessian;            // every stage's; false: limited-memory
  std::optional<bool> feasibility_exact_hessian;  // the feasibility and tightening stages' (after exact_hessian)
  bool derivative_check = false;                // Ipopt's second-order derivative checker
  std::optional<int> penalty_iterations;        // the penalty stage's iteration cap (0: none; Problem)
  std::optional<bool> task_penalty;             // the task stage with the products in its cost (Problem)
  bool hints = true;                            // false: without the problem's hints (Problem::hints)
  bool continuation = true;                     // false: without the problem's continuation (Problem::continuation)
  // Ipopt's print level and options, tightening, and an interruption check (restarts: above).
  collocation::SolveOptions solve;
};

// The problem with the options' changes: remeshed to N, P; the seed's kind, scale and random
// seed; restarts; the Hessian. Throws std::invalid_argument naming the field ("P: expected an
// order from 1 to 9, got 12"; also for a print level outside 0 … 12).
collocation::Problem adjustedProblem(collocation::Problem problem, const OptimizeOptions& options);

// A stage of a step of the problem's continuation (collocation::Problem::continuation) run for a
// seed: its feasibility stage, a penalty stage before it, or a repeat of it
// (SolveOptions::feasibility_repeats), one report each, in the order they ran.
struct ContinuationStepReport {
  int attempt = 0;  // the solve's attempt whose seed it carried (AttemptReport::attempt)
  int step = 0;     // its index in Problem::continuation
  std::map<std::string, double> parameters;  // the step's values
  collocation::StageReport stage;
  bool kept = true;  // the stage whose end seeded the next step (or the problem's solve)
};

struct OptimizeResult {
  std::shared_ptr<const collocation::Problem> problem_ptr;           // the problem as solved
  std::shared_ptr<const collocation::Transcription> transcription;  // refers to *problem_ptr
  collocation::SolveReport report;
  collocation::SimulationSeedReport simulation_seed;  // a simulation seed's events and mesh
  std::string seed_fallback;  // set when the simulation seed failed and the null seed was used
  double tighten_within = 0;  // the tightening threshold used
  double tighten_factor = 0;  // the tightening continuation's factor used
  int feasibility_repeats = 0;  // the feasibility stage's repeats allowed (SolveOptions)
  std::vector<collocation::Sample> samples;  // the trajectory at every collocation point
  double mean_local_error = 0;
  // An infeasible solve with hints: whether the problem's own motion could meet them.
  std::vector<collocation::HintReach> hints;
  std::string hints_not_checked;  // why they could not be checked
  // The seed_method's solve this one started from (null without one). The report's iterations,
  // wall and evaluation seconds count both solves; its stages are this solve's.
  std::shared_ptr<const OptimizeResult> seed_solve;
  // The continuation's steps, in the order they ran (every attempt's). The report's iterations,
  // wall and evaluation seconds count them; its stages and attempts are the problem's own.
  std::vector<ContinuationStepReport> continuation;

  const collocation::Problem& problem() const { return *problem_ptr; }
  bool feasible() const { return report.feasible; }
};

// Adjusts the problem (adjustedProblem), transcribes it with the method (throws
// std::invalid_argument for what the method cannot represent), seeds it and solves it in two
// stages with Ipopt. A solve stopped by options.solve.interrupted is a result with interrupted set.
OptimizeResult optimize(const collocation::Problem& problem, const OptimizeOptions& options);

// summary.json: the problem, method, mesh, seed, Ipopt's status per stage and attempt, the
// complementarity and timing figures, the hints' reach and the parameters (JSON text).
std::string summaryJson(const OptimizeResult& result);
// Writes DIR/trajectory.csv, DIR/variables.csv (collocation/saved_solution.hpp) and
// DIR/summary.json, each whole or not at all; creates DIR.
void saveSolution(const std::string& dir, const OptimizeResult& result);

// ---------------------------------------------------------------------------------------------
// Replay of an optimised trajectory in the time-stepper and/or Bullet (verify/replay.hpp)

// Replays the solution in DIR (a saveSolution folder).
verify::ReplayResult replay(const std::string& solution_dir, const verify::ReplayOptions& options,
                            bool allow_changed_problem = false);

// Writes OUT/replay.csv (the time series), OUT/replay.json (the report) and, with charts, the
// deviation and energy charts (replay_deviation.png/.svg, replay_energy.png/.svg through
// scripts/charts.py). Returns the chart script's error ("" when drawn or not asked for); the CSV
// and JSON are written regardless, the JSON listing the charts that exist.
std::string writeReplay(const std::string& out_dir, const verify::ReplayResult& result,
                        const std::string& solution_dir, bool charts = true);

// ---------------------------------------------------------------------------------------------
// Rendering (render/)

// A trajectory with the scene it moves in.
struct RenderInput {
  scene::Scene scene;
  std::shared_ptr<const render::TrajectorySource> trajectory;
  std::string problem_changed;  // a solution whose problem changed since the solve: what changed
};
// A saveSolution folder: through the collocation polynomials (a folder without
// variables.csv: its trajectory.csv and the scene named by its summary.json).
// A solution whose problem file changed since the solve is refused (collocation::SolutionError)
// unless `allow_changed_problem`; then RenderInput::problem_changed says what changed.
RenderInput openSolution(const std::string& dir, bool allow_changed_problem = false);
// A trajectory CSV in the scene it was computed in.
RenderInput openTrajectoryCsv(const std::string& csv_path, scene::Scene scene);

struct RenderReport {
  int frames = 0;
  double start_time = 0, end_time = 0;  // of the trajectory [s]
  double seconds = 0;                   // wall time of drawing and encoding
};
// Draws every frame: PNG files frames_dir/frame_00000.png … (when not empty) and an H.264 MP4 at
// video_path (through ffmpeg, when not empty); each file appears only when complete. Warnings
// (a trajectory outside the view, …) go to `warnings`; progress(done, total) after each frame.
RenderReport renderTrajectory(const RenderInput& input, const render::AnimationOptions& options, const std::string& video_path,
                    const std::string& frames_dir, std::ostream& warnings,
                    const std::function<void(int, int)>& progress = {});

// Frames drawn in memory, one at a time: for a user who composes figures or passes frames on
// (the Python module's NumPy images). Holds an off-screen OpenGL context (OSMesa); not copyable.
class FrameRenderer {
 public:
  // Throws std::invalid_argument on bad options, std::runtime_error when OSMesa cannot start.
  FrameRenderer(RenderInput input, const render::AnimationOptions& options, std::ostream& warnings);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  int frames() const;
  double time(int frame) const;  // trajectory time of a frame [s]
  int width() const;
  int height() const;
  // Draws a frame (0 ≤ frame < frames(), else std::out_of_range); returns its pixels, RGB, 8 bits
  // per channel, top row first (height × width × 3), valid until the next draw.
  const std::vector<std::uint8_t>& draw(int frame);

 private:
  RenderInput input_;
  std::unique_ptr<render::Animation> animation_;
  std::unique_ptr<render::Renderer> renderer_;
};

// ---------------------------------------------------------------------------------------------
// Charts (scripts/charts.py through python3)

// Runs `python3 charts.py KIND CSV --png PNG --svg SVG` (the interpreter: $SALTUS_PYTHON when
// set, else /usr/bin/python3 when it exists, else python3 from PATH; MPLBACKEND=Agg; the
// script's standard output goes to standard error). Throws std::runtime_error when the script
// cannot be started or fails.
void drawChart(const std::string& kind, const std::string& csv, const std::string& png, const std::string& svg);
// The command line drawChart runs (interpreter, script, KIND, CSV, --png, PNG, --svg, SVG).
std::vector<std::string> chartCommand(const std::string& kind, const std::string& csv, const std::string& png,
                                      const std::string& svg);
// This process's environment with MPLBACKEND=Agg (matplotlib without a display), for child processes.
std::vector<std::string> chartEnvironment();

}  // namespace saltus
