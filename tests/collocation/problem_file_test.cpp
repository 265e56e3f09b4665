// Problem files (collocation/problem_file.hpp) and the method names (problem.hpp): the built-in
// problems with their documented values and --set overrides, every key of the format on a full
// fixture (1-based elements in the file, 0-based in Problem). Bad input: problem_file_errors_test.cpp;
// the solve, ipopt and task_ipopt sections: problem_file_solve_test.cpp.
#include "collocation/problem_file.hpp"

#include <gtest/gtest.h>

#include "saltus/build_paths.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>

#include <unistd.h>

#include "contact/kinematics.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "scene/scenario.hpp"
#include "scene/yaml_reader.hpp"
#include "tests/support/errors.hpp"

namespace saltus::collocation {
namespace {

using scene::ScenarioError;

const std::string kProblemDir = std::string(SALTUS_SOURCE_DIR) + "/models/problems/";
const std::string kDataDir = std::string(SALTUS_SOURCE_DIR) + "/tests/data/problems/";
constexpr double kPi = std::numbers::pi;

// The ScenarioError message of f, or a test failure.
std::string errorOf(const std::function<void()>& f) { return testing::expectedMessageOf<ScenarioError>(f); }

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// The gap of contact i at configuration q.
double gap(const scene::Scene& s, int i, const Eigen::VectorXd& q) {
  dynamics::Data<double> data(s.model);
  dynamics::forwardKinematics(s.model, data, q);
  return contact::gap(contact::contactPairs(s).at(i), data, q.data());
}

// ---------------------------------------------------------------------------------------------
// Method names

TEST(Method, NamesRoundTrip) {
  for (Method m : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) EXPECT_EQ(parseMethod(toString(m)), m);
  EXPECT_STREQ(toString(Method::FirstOrder), "first-order");
}

TEST(Method, UnknownNameListsTheValidOnes) {
  try {
    parseMethod("impulsiv");
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_TRUE(contains(what, "'impulsiv'")) << what;
    EXPECT_TRUE(contains(what, "did you mean 'impulsive'")) << what;
    EXPECT_TRUE(contains(what, "impulsive, continuous, first-order")) << what;
  }
}

// ---------------------------------------------------------------------------------------------
// Built-in problems

TEST(ProblemFile, BuiltinNames) {
  EXPECT_EQ(builtinProblemNames(),
            (std::vector<std::string>{"biped_stop", "monopod_turn", "ollie", "ollie_simple", "pendulum_conveyor", "point_mass_drop",
                                      "point_mass_throw"}));
}

TEST(ProblemFile, PointMassDrop) {
  const Problem p = loadProblem("point_mass_drop");
  EXPECT_EQ(p.name, "point_mass_drop");
  EXPECT_EQ(p.source, "builtin:point_mass_drop");
  EXPECT_EQ(p.scene.source, "builtin:point_mass_drop");
  EXPECT_FALSE(p.description.empty());
  ASSERT_EQ(p.scene.model.nv(), 1);
  EXPECT_EQ(p.scene.model.coordinate_name[0], "z");
  EXPECT_DOUBLE_EQ(p.scene.model.totalMass(), 1.0);
  ASSERT_EQ(p.scene.contacts.size(), 1u);
  EXPECT_EQ(p.scene.contacts[0].name, "ball");
  EXPECT_EQ(p.scene.contacts[0].restitution, 0.0);
  EXPECT_EQ(p.scene.contacts[0].friction, 0.0);
  EXPECT_TRUE(p.scene.limits.empty());
  // Released at rest at the height.
  EXPECT_DOUBLE_EQ(p.scene.q0[0], 0.1);
  EXPECT_DOUBLE_EQ(gap(p.scene, 0, p.scene.q0), 0.1);
  EXPECT_TRUE(p.scene.v0.isZero());
  EXPECT_TRUE(p.initial_free_q.empty() && p.initial_free_v.empty());
  // Mesh: N = 20, P = 4, h_max = 0.02, T ≥ 0.2 > the drop time √(2 h / g) = 0.143 s.
  EXPECT_EQ(p.N, 20);
  EXPECT_EQ(p.P, 4);
  EXPECT_DOUBLE_EQ(p.h_max, 0.02);
  EXPECT_DOUBLE_EQ(p.h_min_ratio, 0.1);
  EXPECT_EQ(p.total_time_kind, TotalTime::AtLeast);
  EXPECT_DOUBLE_EQ(p.total_time, 0.2);
  EXPECT_LT(std::sqrt(2 * 0.1 / 9.81), p.total_time);
  EXPECT_GE(p.N * p.h_max, p.total_time);
  // Penalty only.
  EXPECT_FALSE(p.cost.hasTask());
  EXPECT_DOUBLE_EQ(p.cost.penalty_weight, 1.0);
  EXPECT_TRUE(p.inputs.empty());
  EXPECT_TRUE(p.bounds.empty());
  // No hints; the seed is the time-stepper's motion.
  EXPECT_TRUE(p.hints.empty());
  EXPECT_EQ(p.seed_kind, SeedKind::Simulation);
  EXPECT_TRUE(p.surface_steps.empty());
  EXPECT_EQ(p.parameters, (std::map<std::string, double>{{"height", 0.1}, {"restitution", 0.0}}));
  EXPECT_EQ(p.ipopt_options.at("tol"), "1e-8");
}

TEST(ProblemFile, PointMassDropOverrides) {
  const Problem p = loadProblem("point_mass_drop", {{"restitution", 0.5}, {"height", 0.05}});
  EXPECT_DOUBLE_EQ(p.scene.contacts[0].restitution, 0.5);
  EXPECT_DOUBLE_EQ(p.scene.q0[0], 0.05);
  EXPECT_DOUBLE_EQ(p.parameters.at("restitution"), 0.5);
  EXPECT_DOUBLE_EQ(p.scene.parameters.at("height"), 0.05);
  // The mesh scales with the fall time √(2 h / g): h_max and the horizon with √(h / 0.1).
  EXPECT_NEAR(p.h_max, 0.02 * std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(p.total_time, 0.2 * std::sqrt(0.5), 1e-15);
  // Through the command-line parser.
  const Problem q = loadProblem("point_mass_drop", scene::parseOverrides({"restitution=0.25"}));
  EXPECT_DOUBLE_EQ(q.scene.contacts[0].restitution, 0.25);
}

TEST(ProblemFile, PointMassThrowHorizonHoldsTheAnalyticStop) {
  for (const double mu : {0.1, 0.3, 1.0}) {
    const Problem p = loadProblem("point_mass_throw", {{"friction", mu}, {"speed", 2.0}, {"height", 0.3}});
    ASSERT_EQ(p.scene.model.nv(), 2);
    EXPECT_EQ(p.scene.contacts[0].directions, 2);
    const double g = 9.81, t_fall = std::sqrt(2 * 0.3 / g), v_after = std::max(0.0, 2.0 - mu * g * t_fall);
    const double t_stop = t_fall + v_after / (mu * g);
    EXPECT_NEAR(p.total_time, 1.25 * t_stop, 1e-12) << "mu = " << mu;
    EXPECT_GE(p.N * p.h_max, p.total_time);
    EXPECT_DOUBLE_EQ(p.scene.v0[0], 2.0);
  }
}

TEST(ProblemFile, OverrideOutsideTheValidRangeIsCaught) {
  const std::string what = errorOf([] { loadProblem("point_mass_drop", {{"restitution", 1.5}}); });
  EXPECT_TRUE(contains(what, "point_mass_drop.yaml:")) << what;
  EXPECT_TRUE(contains(what, "contacts[0].restitution")) << what;
  EXPECT_TRUE(contains(what, "[0, 1]")) << what;
}

TEST(ProblemFile, UnknownOverrideListsTheParameters) {
  const std::string what = errorOf([] { loadProblem("pendulum_conveyor", {{"belt_sped", 1.0}}); });
  EXPECT_TRUE(contains(what, kProblemDir + "pendulum_conveyor.yaml:" +
                                 std::to_string(testing::lineOf(kProblemDir + "pendulum_conveyor.yaml", "parameters:")) + ":"))
      << what;
  EXPECT_TRUE(contains(what, "did you mean 'belt_speed'")) << what;
  EXPECT_TRUE(contains(what, "friction, belt_speed, theta1_0, theta2_0")) << what;
}

TEST(ProblemFile, PendulumConveyor) {
  const Problem p = loadProblem("pendulum_conveyor");
  EXPECT_EQ(p.name, "pendulum_conveyor");
  ASSERT_EQ(p.scene.model.nv(), 2);
  EXPECT_EQ(p.scene.model.coordinate_name, (std::vector<std::string>{"theta1", "theta2"}));
  EXPECT_EQ(p.scene.q0, Eigen::Vector2d(0, kPi / 4));
  EXPECT_TRUE(p.scene.v0.isZero());
  ASSERT_EQ(p.scene.contacts.size(), 1u);
  const scene::Contact& tip = p.scene.contacts[0];
  EXPECT_EQ(tip.link, "tip");
  EXPECT_EQ(tip.restitution, 0.0);
  EXPECT_DOUBLE_EQ(tip.friction, 2.0);
  EXPECT_EQ(tip.directions, 2);
  EXPECT_NEAR(gap(p.scene, 0, p.scene.q0), 0.0, 1e-12);  // the tip rests on the belt
  EXPECT_EQ(p.N, 10);
  EXPECT_EQ(p.P, 4);
  EXPECT_DOUBLE_EQ(p.h_max, 0.02);
  EXPECT_EQ(p.total_time_kind, TotalTime::AtLeast);
  EXPECT_DOUBLE_EQ(p.total_time, 0.1);
  EXPECT_FALSE(p.cost.hasTask());
  EXPECT_TRUE(p.bounds.empty());
  // The belt: at rest, then belt_speed along +x from [6, 0] (element 5 here); no time schedule.
  ASSERT_EQ(p.surface_steps.size(), 1u);
  const std::vector<SurfaceStep>& steps = p.surface_steps.at(tip.surface);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(steps[0].element, 0);
  EXPECT_EQ(steps[0].velocity, Eigen::Vector3d::Zero());
  EXPECT_EQ(steps[1].element, 5);
  EXPECT_EQ(steps[1].velocity, Eigen::Vector3d(0.5, 0, 0));
  EXPECT_TRUE(p.scene.surfaces[tip.surface].velocity_schedule.empty());
  EXPECT_EQ(p.parameters, (std::map<std::string, double>{
                              {"friction", 2.0}, {"belt_speed", 0.5}, {"theta1_0", 0.0}, {"theta2_0", kPi / 4}}));
}

TEST(ProblemFile, PendulumConveyorOverrides) {
  const Problem p = loadProblem("pendulum_conveyor", {{"friction", 0.6}, {"belt_speed", 1.5}, {"theta2_0", 0.6}});
  EXPECT_DOUBLE_EQ(p.scene.contacts[0].friction, 0.6);
  EXPECT_EQ(p.surface_steps.at(0)[1].velocity, Eigen::Vector3d(1.5, 0, 0));
  EXPECT_EQ(p.scene.q0, Eigen::Vector2d(0, 0.6));
  EXPECT_NEAR(gap(p.scene, 0, p.scene.q0), 0.0, 1e-12);  // the belt follows the initial angles
}

TEST(ProblemFile, LoadByPathKeepsThePathAsSource) {
  const Problem p = loadProblem(kProblemDir + "point_mass_drop.yaml");
  EXPECT_EQ(p.source, kProblemDir + "point_mass_drop.yaml");
  EXPECT_EQ(p.name, "point_mass_drop");
}

TEST(ProblemFile, ProblemsDirectoryFromTheEnvironment) {
  ASSERT_EQ(setenv("SALTUS_PROBLEMS_DIR", kDataDir.c_str(), 1), 0);
  const std::vector<std::string> names = builtinProblemNames();
  const std::string dir = problemsDirectory();
  const std::string what = errorOf([] { loadProblem("point_mass_drop"); });
  const Problem p = loadProblem("full");
  unsetenv("SALTUS_PROBLEMS_DIR");
  EXPECT_EQ(dir, kDataDir);
  EXPECT_NE(std::find(names.begin(), names.end(), "full"), names.end());
  EXPECT_TRUE(contains(what, "unknown built-in problem 'point_mass_drop'")) << what;
  EXPECT_EQ(p.source, "builtin:full");
  EXPECT_EQ(problemsDirectory(), std::string(SALTUS_SOURCE_DIR) + "/models/problems");
}

TEST(ProblemFile, UnknownBuiltinListsTheBuiltins) {
  const std::string what = errorOf([] { loadProblem("point_mass_dorp"); });
  EXPECT_TRUE(contains(what, "unknown built-in problem 'point_mass_dorp'")) << what;
  EXPECT_TRUE(contains(what, "did you mean 'point_mass_drop'")) << what;
  EXPECT_TRUE(contains(what, "pendulum_conveyor, point_mass_drop")) << what;
}

TEST(ProblemFile, MissingFile) {
  const std::string what = errorOf([] { loadProblem(kDataDir + "no_such_file.yaml"); });
  EXPECT_TRUE(contains(what, kDataDir + "no_such_file.yaml: cannot open the problem file")) << what;
}

TEST(ProblemFile, DefaultsAndTheNullSeed) {
  EXPECT_EQ(Problem{}.penalty_iterations, 0);  // no penalty stage
  EXPECT_TRUE(Problem{}.method_solve.empty());
  EXPECT_FALSE(Problem{}.task_penalty);
  const Problem p = loadProblem(kDataDir + "seed_null.yaml");
  EXPECT_EQ(p.name, "seed_null");
  EXPECT_EQ(p.seed_kind, SeedKind::Null);
  EXPECT_EQ(p.N, 3);
  EXPECT_EQ(p.P, 4);
  EXPECT_EQ(p.total_time_kind, TotalTime::Free);
  EXPECT_TRUE(p.task_stage);
  EXPECT_TRUE(p.exact_hessian);
  EXPECT_TRUE(p.feasibility_exact_hessian);
  EXPECT_TRUE(p.ipopt_options.empty());
  EXPECT_TRUE(p.task_ipopt_options.empty());
  EXPECT_TRUE(p.scene.contacts.empty());
}

// A condition on a range of points (`from`, `to`): the monopod keeps y ≤ 0 from [1, 0] through
// [13, 0], i.e. on the whole of elements 1 to 12 and at the first point of element 13, and nowhere after.
TEST(ProblemFile, ARangeOfPointsCoversWholeElementsAndItsEnds) {
  const Problem p = loadProblem("monopod_turn");
  const int y = p.scene.model.coordinateIndex("base_y");
  std::vector<std::pair<int, int>> at;
  for (const PointBound& b : p.bounds)
    if (b.quantity.kind == Quantity::Kind::Position && b.quantity.index == y && b.upper == 0 && b.lower == -kInf)
      at.emplace_back(b.element, b.point);
  std::vector<std::pair<int, int>> expected;
  for (int n = 0; n < 12; ++n) expected.emplace_back(n, -1);
  expected.emplace_back(12, 0);
  EXPECT_EQ(at, expected);
  // The same range inside one element: single points.
  const std::string path = ::testing::TempDir() + "range_in_one_element.yaml";
  std::ofstream(path) << "model:\n  point_mass: {mass: 1, link: ball, axes: {x: [1, 0, 0]}}\n"
                         "mesh: {N: 4, P: 3, h_max: 0.02}\nconstraints:\n  - {from: [2, 1], to: [2, 3], q: {x: [0, 1]}}\n";
  const Problem one = loadProblem(path);
  ASSERT_EQ(one.bounds.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(one.bounds[k].element, 1);
    EXPECT_EQ(one.bounds[k].point, k + 1);
  }
}

// ---------------------------------------------------------------------------------------------
// Every key, on tests/data/problems/full.yaml

class FullProblem : public ::testing::Test {
 protected:
  const std::string path_ = kDataDir + "full.yaml";
  const Problem p_ = loadProblem(path_);
  int coordinate(const std::string& name) const { return p_.scene.model.coordinateIndex(name); }
  // The bound on `q` at [element, point] (0-based), from p_.bounds or p_.hints.
  const PointBound* find(const std::vector<PointBound>& list, Quantity::Kind kind, int index, int element,
                         int point) const {
    for (const PointBound& b : list)
      if (b.quantity.kind == kind && b.quantity.index == index && b.element == element && b.point == point) return &b;
    ADD_FAILURE() << "no bound on " << static_cast<int>(kind) << " " << index << " at [" << element << ", " << point
                  << "]";
    return nullptr;
  }
};

TEST_F(FullProblem, SceneAndMesh) {
  EXPECT_EQ(p_.name, "full");
  EXPECT_EQ(p_.description, "every problem key");
  EXPECT_EQ(p_.source, path_);
  EXPECT_EQ(p_.scene.limits.size(), 2u);  // rev_lower, rev_upper
  EXPECT_DOUBLE_EQ(p_.scene.q0[coordinate("rev")], 0.5);
  EXPECT_DOUBLE_EQ(p_.scene.v0[coordinate("cont")], 1.0);
  EXPECT_EQ(p_.N, 8);
  EXPECT_EQ(p_.P, 3);
  EXPECT_DOUBLE_EQ(p_.h_max, 0.05);
  EXPECT_DOUBLE_EQ(p_.h_min_ratio, 0.5);
  EXPECT_EQ(p_.total_time_kind, TotalTime::Equal);
  EXPECT_DOUBLE_EQ(p_.total_time, 0.3);
  EXPECT_EQ(p_.first_order_steps_per_element, 2);
}

TEST_F(FullProblem, InputsDefaultToTheEffortLimits) {
  ASSERT_EQ(p_.inputs, (std::vector<int>{coordinate("rev"), coordinate("cont"), coordinate("cont_free")}));
  ASSERT_EQ(p_.input_lower.size(), 3);
  ASSERT_EQ(p_.input_upper.size(), 3);
  EXPECT_EQ(p_.input_lower[0], -30.0);  // rev: effort 30
  EXPECT_EQ(p_.input_upper[0], 30.0);
  EXPECT_EQ(p_.input_lower[1], -2.0);   // cont: lower given, upper from effort 5
  EXPECT_EQ(p_.input_upper[1], 5.0);
  EXPECT_EQ(p_.input_lower[2], -kInf);  // cont_free: no effort limit
  EXPECT_EQ(p_.input_upper[2], 7.0);
}

TEST_F(FullProblem, InitialFreeIsSorted) {
  EXPECT_EQ(p_.initial_free_q, (std::vector<int>{coordinate("cont"), coordinate("pris")}));
  EXPECT_EQ(p_.initial_free_v, (std::vector<int>{coordinate("pris")}));
}

TEST_F(FullProblem, FinalConditionsAtTheLastMeshPoint) {
  using K = Quantity::Kind;
  const int last = p_.N - 1, end = p_.P + 1;  // [N, P + 1] in the file
  const PointBound* q = find(p_.bounds, K::Position, coordinate("pris"), last, end);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->lower, 0.0);
  EXPECT_EQ(q->upper, 0.0);
  EXPECT_EQ(q->origin, path_ + ":" + std::to_string(testing::lineOf(path_, "q: {pris: 0}")));
  const PointBound* v = find(p_.bounds, K::Velocity, coordinate("rev"), last, end);
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->lower, -1.0);
  EXPECT_EQ(v->upper, kInf);  // .inf
  const PointBound* w = find(p_.bounds, K::Velocity, coordinate("cont"), last, end);
  ASSERT_NE(w, nullptr);
  EXPECT_EQ(w->lower, -kInf);  // null
  EXPECT_EQ(w->upper, 2.0);
  const PointBound* g = find(p_.bounds, K::Gap, 0, last, end);
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->upper, 0.1);
}

TEST_F(FullProblem, BoundsAtEveryPoint) {
  const PointBound* q = find(p_.bounds, Quantity::Kind::Position, coordinate("pris"), -1, -1);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->lower, -0.05);
  EXPECT_EQ(q->upper, 0.25);  // the parameter `top`
  const PointBound* u = find(p_.bounds, Quantity::Kind::Input, 1, -1, -1);  // input 1 is cont
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->lower, -1.0);
}

TEST_F(FullProblem, ConstraintsMapOneBasedElementsToZeroBased) {
  // at: [n_mid, 0] with n_mid = 3: element 2 here.
  const PointBound* q = find(p_.bounds, Quantity::Kind::Position, coordinate("rev"), 2, 0);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->lower, 0.2);
  // at: [8, 3] = [N, P]: element 7, point 3. Gap indices: contacts first, then the stops.
  const PointBound* stop = find(p_.bounds, Quantity::Kind::Gap, 1 + 1, 7, 3);  // foot, rev_lower, rev_upper
  ASSERT_NE(stop, nullptr);
  EXPECT_EQ(stop->lower, 0.5);
  EXPECT_EQ(stop->upper, kInf);
  const PointBound* foot = find(p_.bounds, Quantity::Kind::Gap, 0, 7, 3);
  ASSERT_NE(foot, nullptr);
  EXPECT_EQ(foot->upper, 0.0);
  // Hints are kept apart: at [1, 2] is element 0, point 2.
  ASSERT_EQ(p_.hints.size(), 1u);
  const PointBound* h = find(p_.hints, Quantity::Kind::Velocity, coordinate("pris"), 0, 2);
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(h->lower, 0.0);
  EXPECT_EQ(h->upper, kInf);
  EXPECT_EQ(p_.bounds.size(), 4u + 2u + 3u);  // final, bounds, constraints
}

TEST_F(FullProblem, ConstantSurfaceVelocityBecomesAStepAtTheFirstElement) {
  ASSERT_EQ(p_.surface_steps.size(), 1u);
  const std::vector<SurfaceStep>& belt = p_.surface_steps.at(1);
  ASSERT_EQ(belt.size(), 1u);
  EXPECT_EQ(belt[0].element, 0);
  EXPECT_EQ(belt[0].velocity, Eigen::Vector3d(0.2, 0, 0));
}

TEST_F(FullProblem, CostAndParameters) {
  EXPECT_EQ(p_.cost.penalty_weight, 2.0);
  EXPECT_EQ(p_.cost.effort_weight, 0.5);
  EXPECT_EQ(p_.cost.max_coordinate, coordinate("pris"));
  EXPECT_EQ(p_.cost.max_weight, 1.0);
  EXPECT_TRUE(p_.cost.hasTask());
  EXPECT_EQ(p_.parameters, (std::map<std::string, double>{{"n_mid", 3}, {"top", 0.25}}));
}

TEST_F(FullProblem, OverridesReachElementNumbers) {
  const Problem p = loadProblem(path_, {{"n_mid", 5}});
  const PointBound* q = find(p.bounds, Quantity::Kind::Position, coordinate("rev"), 4, 0);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->lower, 0.2);
}

// The full-body Ollie: the biped on the board (scene skateboard_rider) driven by its six joint
// torques within the biped's limits, the paper's mesh, the air constraint and the tail hint.
TEST(ProblemFile, OllieDrivesTheRiderOnTheBoard) {
  const Problem p = loadProblem("ollie");
  const scene::Scene rider = scene::loadScene("skateboard_rider");
  EXPECT_EQ(p.scene_file, std::string(SALTUS_SOURCE_DIR) + "/models/scenes/skateboard_rider.yaml");
  EXPECT_EQ(p.scene.model.coordinate_name, rider.model.coordinate_name);
  EXPECT_EQ(p.scene.q0, rider.q0);
  EXPECT_EQ(p.scene.limits.size(), 12u);  // the biped's hard stops
  EXPECT_EQ(p.N, 40);
  EXPECT_EQ(p.P, 2);
  EXPECT_EQ(p.h_max, 0.02);
  ASSERT_EQ(p.inputs.size(), 9u);
  const auto& names = p.scene.model.coordinate_name;
  for (std::size_t i = 0; i < 6; ++i) {
    const std::string& joint = names[p.inputs[i]];
    const double lower = joint.starts_with("shoulder") ? -60 : joint.starts_with("hip") ? -180 : -150;
    const double upper = joint.starts_with("shoulder") ? 80 : 270;
    EXPECT_EQ(p.input_lower[i], lower) << joint;
    EXPECT_EQ(p.input_upper[i], upper) << joint;
  }
  // The assist on the rider's base: none in the paper's problem, `assist` weights of the rider
  // when set.
  const Problem assisted = loadProblem("ollie", {{"assist", 2}});
  for (std::size_t i = 6; i < 9; ++i) {
    EXPECT_EQ(names[p.inputs[i]], (std::vector<std::string>{"rider_x", "rider_z", "rider_theta"}[i - 6]));
    EXPECT_EQ(p.input_lower[i], 0);
    EXPECT_EQ(p.input_upper[i], 0);
    EXPECT_NEAR(assisted.input_upper[i], 2 * (assisted.scene.model.totalMass() - 2.38) * 9.81, 0.01);  // less the board
    EXPECT_EQ(assisted.input_lower[i], -assisted.input_upper[i]);
  }
  // One axis's bound set alone (a continuation removes the horizontal force first); the other two
  // keep `assist`.
  const Problem no_x = loadProblem("ollie", {{"assist", 2}, {"assist_x", 0}});
  EXPECT_EQ(no_x.input_upper[6], 0);
  EXPECT_EQ(no_x.input_lower[6], 0);
  EXPECT_EQ(no_x.input_upper[7], assisted.input_upper[7]);
  EXPECT_EQ(no_x.input_upper[8], assisted.input_upper[8]);
  EXPECT_NEAR(loadProblem("ollie", {{"assist_theta", 0.5}}).input_upper[8], assisted.input_upper[8] / 4, 1e-9);
  ASSERT_EQ(p.hints.size(), 1u);
  EXPECT_EQ(p.hints[0].element, 9);  // [10, 0], 0-based
  int air = 0;
  for (const PointBound& b : p.bounds)
    if (b.element == 19 && b.point == 0 && b.lower == 0.2) ++air;
  EXPECT_EQ(air, 2);  // both wheels
}

// `scene: skateboard`: the scene from its scenario file, its parameters in the problem's
// expressions, --set reaching the scene's parameters and the problem's own, and the scenario
// file's text in the fingerprint.
TEST(ProblemFile, ASceneFromItsOwnFile) {
  const std::string path = kDataDir + "scene_reference.yaml";
  const Problem p = loadProblem(path);
  const scene::Scene board = scene::loadScene("skateboard");
  EXPECT_EQ(p.name, "board_test");
  EXPECT_EQ(p.scene.model.coordinate_name, board.model.coordinate_name);
  ASSERT_EQ(p.scene.contacts.size(), board.contacts.size());
  EXPECT_EQ(p.scene.contacts[3].free_axes, std::vector<int>{0});
  EXPECT_EQ(p.scene.q0, board.q0);
  EXPECT_EQ(p.scene_file, std::string(SALTUS_SOURCE_DIR) + "/models/scenes/skateboard.yaml");
  ASSERT_EQ(p.inputs.size(), 1u);
  EXPECT_NEAR(p.input_upper[0], 2 * 36.5 * 9.81, 1e-9);  // the problem's `limit`, the scene's rider_mass and g
  EXPECT_EQ(p.parameters.at("limit"), 2);
  EXPECT_EQ(p.parameters.at("friction"), 1.6);
  const Problem set = loadProblem(path, {{"friction", 0.9}, {"limit", 1}, {"rider_mass", 40}});
  EXPECT_EQ(set.scene.contacts[3].friction, 0.9);
  EXPECT_NEAR(set.input_upper[0], 40 * 9.81, 1e-9);
  EXPECT_EQ(set.scene.parameters.at("rider_mass"), 40);
  EXPECT_NE(set.fingerprint, p.fingerprint);
  const std::string what = errorOf([&] { loadProblem(path, {{"frction", 1}}); });
  EXPECT_TRUE(contains(what, "the problem has no parameter 'frction'")) << what;
  EXPECT_TRUE(contains(what, "did you mean 'friction'")) << what;
  // The scenario file is part of the fingerprint: a copy beside the problem, changed.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("saltus_scene_ref_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(std::string(SALTUS_SOURCE_DIR) + "/models/scenes/skateboard.yaml", dir / "board.yaml");
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  text.replace(text.find("scene: skateboard"), 17, "scene: board.yaml");
  std::ofstream(dir / "problem.yaml") << text;
  const std::string before = loadProblem((dir / "problem.yaml").string()).fingerprint;
  std::ofstream(dir / "board.yaml", std::ios::app) << "# changed\n";
  EXPECT_NE(loadProblem((dir / "problem.yaml").string()).fingerprint, before);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace saltus::collocation
