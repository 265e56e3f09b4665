// A trajectory-optimisation problem through contact: the scene (model, surfaces, contacts,
// joint-limit stops), the mesh of finite elements, the conditions and the cost. Read from a
// problem file (problem_file.hpp, format in models/problems/README.md) or built in C++ for tasks
// the format does not cover. The transcription (transcription.hpp) turns it into an NLP for one
// of three methods.
//
// Indices are 0-based here: element n ∈ [0, N), point p ∈ [0, P + 1] where p = 0 and p = P + 1
// are the element's mesh points and 1 … P its Legendre–Gauss collocation points (paper §II.C).
// Problem files use the paper's 1-based elements: [6, 0] in a file is element 5, point 0 here.
#pragma once

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scene/scene.hpp"

namespace saltus::collocation {

enum class Method {
  Impulsive,   // the paper's LG-P I: velocity jumps at element boundaries, eqs. (5), (6), (9)
  Continuous,  // LG-P C: continuous velocity, contact only through (10)
  FirstOrder   // Posa, Cantu & Tedrake 2014: backward Euler with complementarity at every step
};
const char* toString(Method m);
Method parseMethod(const std::string& name);  // "impulsive", "continuous", "first-order"; throws std::invalid_argument

constexpr double kInf = std::numeric_limits<double>::infinity();

// What a constraint or a bound applies to.
struct Quantity {
  enum class Kind { Position, Velocity, Input, Gap };
  Kind kind = Kind::Position;
  int index = 0;  // coordinate (Position, Velocity), input (Input) or contact (Gap: scene contacts, then limit stops)
};

// lower ≤ quantity ≤ upper at one point (or at every point when element < 0).
struct PointBound {
  Quantity quantity;
  int element = -1;  // 0-based; −1: every element
  int point = -1;    // 0 … P + 1; −1: every point of the element(s)
  double lower = -kInf, upper = kInf;
  std::string origin;  // where it was given (file:line), for messages
};

// A step of a surface's velocity at a mesh point [element, 0]: the surface moves with `velocity`
// from that point on (the paper's belt steps at [6, 0]). With a variable element length the time
// of a mesh point is not known in advance, so steps are placed on the mesh, not in time.
struct SurfaceStep {
  int element = 0;  // 0-based; the step acts from [element, 0] on
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

struct CostTerms {
  // Weight of the complementarity penalty Σ ε in the task stage (the feasibility stage minimises
  // Σ ε alone).
  double penalty_weight = 1.0;
  // Actuator effort: weight × ∫ Σ u_i² dt by the Gauss quadrature of each element.
  double effort_weight = 0.0;
  // Minimise the maximum of one coordinate over all points: weight × x_m with q_i[n, p] ≤ x_m.
  int max_coordinate = -1;
  double max_weight = 0.0;
  bool hasTask() const { return effort_weight != 0.0 || (max_coordinate >= 0 && max_weight != 0.0); }
};

enum class SeedKind {
  Null,       // zero everywhere (the initial state at [1, 0] by its bounds), h mid-range (the paper's default vector)
  Perturbed,  // null, plus uniform random values in [0, seed_scale] on positions and reactions
  Solution,   // an earlier solution (its variables.csv, saved_solution.hpp), perturbed by seed_scale
  Simulation,  // the time-stepper's motion from the initial state, the mesh on its impacts (simulation_seed.hpp)
  PerturbedSimulation  // the simulation seed plus uniform random values in [0, seed_scale], as `Perturbed`
};

const char* toString(SeedKind k);  // "null", "perturbed", "solution", "simulation", "perturbed-simulation"
// The name of a seed kind; throws std::invalid_argument ("unknown seed 'x' …; expected one of: …").
SeedKind parseSeedKind(const std::string& name);

enum class TotalTime { Free, Equal, AtLeast };

struct Problem;
// A step of a continuation in a problem's parameters (Problem::continuation).
struct ContinuationStep {
  std::map<std::string, double> parameters;  // the step's values; the others are the problem's
  std::shared_ptr<const Problem> problem;    // the problem read with them (loadProblem)
};

struct Problem {
  std::string name;
  std::string description;
  std::string source;  // problem file, or "builtin:<name>"
  std::string scene_file;  // the scenario file of a problem file's `scene:` key (empty: the scene is in the file)
  std::string fingerprint;  // of the files and parameters it was read from (loadProblem); saved with a solution
  scene::Scene scene;  // model, surfaces, contacts, limit stops; q0, v0 = the initial state

  // Mesh (paper §II.C).
  int N = 20;            // finite elements
  int P = 4;             // Legendre–Gauss collocation points per element
  double h_max = 0.02;   // element length bounds [h_min_ratio h_max, h_max]
  double h_min_ratio = 0.1;
  TotalTime total_time_kind = TotalTime::Free;
  double total_time = 0;  // Σ h = T or Σ h ≥ T
  int first_order_steps_per_element = 4;  // the first-order method gets this × N steps

  std::vector<int> inputs;              // actuated coordinates (u_i acts on q_i)
  Eigen::VectorXd input_lower, input_upper;  // per input; default ∓ the joint's effort limit

  // Conditions. The initial state (scene.q0, scene.v0) is imposed at [0, 0] except for the
  // coordinates listed free; everything else is a PointBound.
  std::vector<int> initial_free_q, initial_free_v;
  std::vector<PointBound> bounds;  // final conditions, task constraints, box bounds
  std::vector<PointBound> hints;   // feasibility stage only (a seeding aid, paper §VI)
  // Per surface index, the surface's velocity on the mesh (at rest before the first step); no
  // entry: constant velocity, scene.surfaces[s].velocity(0). A problem file's surface_velocity
  // fills it (and clears that surface's time schedule), and a surface whose schedule is
  // constant and non-zero from t = 0 gets one step at element 0, so from a file no entry means
  // at rest.
  std::map<int, std::vector<SurfaceStep>> surface_steps;

  CostTerms cost;

  // Solve.
  double complementarity_tolerance = 1e-4;  // feasible when every product ≤ this (paper §III)
  bool task_stage = true;                   // run the task stage when the cost has a task term
  SeedKind seed_kind = SeedKind::Simulation;
  double seed_scale = 0.1;
  unsigned random_seed = 1;
  // Further attempts when a solve ends infeasible (a local minimum of the penalty, paper §VI):
  // attempt k starts from the seed perturbed with random_seed + k (a perturbed seed), or from
  // the null seed perturbed with random_seed + k (a null seed).
  int restarts = 2;
  // After an attempt that ends infeasible, up to this many further attempts, each seeded from the
  // time-stepper's motion under the previous attempt's inputs (seedFromResimulation; SolveOptions::
  // resimulations): a chain before the next restart.
  int resimulations = 0;
  // A re-simulation's inputs also track the attempt's motion of their coordinates, with the gains
  // of this natural frequency [rad/s] (trackingFromPoint; 0: open loop, the inputs alone).
  double resimulation_tracking = 30;
  std::string seed_solution;  // directory or trajectory.csv of an earlier solution (SeedKind::Solution)
  std::string seed_solution_origin;  // where it was given (file:line: solve.seed_solution, or --seed-from)
  // An open-loop input schedule that drives a simulation seed (input_schedule.hpp; empty: the
  // inputs at zero), and where it was given (file:line: solve.seed_inputs, or --seed-inputs).
  std::string seed_inputs;
  std::string seed_inputs_origin;
  // Ipopt's Hessian of the Lagrangian: exact (second derivatives by AD) or false: its
  // limited-memory quasi-Newton approximation (no second derivatives, a positive definite
  // matrix: no inertia correction). exact_hessian is the task stage's,
  // feasibility_exact_hessian the feasibility and tightening stages'.
  bool exact_hessian = true;
  bool feasibility_exact_hessian = true;
  bool derivative_check = false;  // Ipopt's derivative checker (second order) before solving
  // A penalty stage of at most this many iterations in place of the feasibility stage's start
  // (collocation/solver.hpp; 0: none): the products in the cost, not as constraints.
  int penalty_iterations = 0;
  // The task stage in the same form (nlp.hpp): the products in its cost, weighted by
  // cost.penalty_weight, not bounded by the tolerance; its result is still its best point with
  // every product within the tolerance.
  bool task_penalty = false;
  // A method's own values of the two above and of cost.penalty_weight (a problem file's
  // solve.impulsive, solve.continuous, solve.first-order), in their place for a solve with that
  // method: adjustedProblem applies them, before the solve's own options. On the biped the
  // penalty form pays for the impulsive method only (models/problems/biped_stop.yaml).
  struct MethodSolve {
    std::optional<int> penalty_iterations;
    std::optional<bool> task_penalty;
    std::optional<double> penalty_weight;
  };
  std::map<Method, MethodSolve> method_solve;
  // Ipopt options by name; the value's type is Ipopt's: numbers are given as text and converted
  // to the option's registered type.
  std::map<std::string, std::string> ipopt_options;
  // The task stage's own options, applied after ipopt_options in that stage only.
  std::map<std::string, std::string> task_ipopt_options;
  std::map<std::string, double> parameters;  // the named parameters in use (after --set)
  // A continuation (homotopy) in the problem's parameters (a problem file's solve.continuation):
  // every seed of a solve with a seed kind other than `solution` is first carried through these
  // problems in turn, a feasibility stage on each (collocation::SolveOptions::feasibility_only)
  // from the previous one's end, the first from the seed with the hints; the solve then starts
  // from the last end, a warm seed with the seed's hints (saltus::optimize). On ollie_simple, strategy
  // 3's first stage at half gravity (the riders' forces kept in newtons) ends nearer the Ollie than
  // at full gravity, where it ends in a local minimum (README, "The Ollie").
  std::vector<ContinuationStep> continuation;
};

// The problem's scene with every surface velocity step on the mesh (Problem::surface_steps, a
// step at [element, 0]) placed in time: element_start[n] is the time of [n, 0] (n = 0 … N − 1, a
// value per problem element). Steps placed so feed a time-stepper (replay, simulation seeds).
scene::Scene sceneAtMeshTimes(const Problem& problem, const std::vector<double>& element_start);

// Changes the mesh to N elements of P collocation points. A condition at the end of the old
// mesh ([N − 1, P + 1]) moves to the new end; any other condition must lie inside the new mesh
// (std::invalid_argument naming where the condition was given).
void remesh(Problem& problem, int N, int P);

// Size limits, checked before anything is allocated: elements (the paper's problems use 25 to 40;
// 10,000 is a transcription of millions of variables), first-order steps per element.
constexpr int kMaxElements = 10000;
constexpr int kMaxStepsPerElement = 1000;

}  // namespace saltus::collocation
