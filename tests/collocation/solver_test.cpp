// Two-stage solves of the paper's built-in problems (collocation/solver.hpp), asserting the
// physics of the solutions (paper Figs. 3 and 4), and the convergence order of Gauss
// collocation on a smooth problem.
#include "collocation/solver.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solution.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "scene/scenario.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/problems.hpp"
#include "tests/support/rk4.hpp"

namespace saltus::collocation {
namespace {

constexpr double g = 9.81;

struct Solved {
  Problem problem;
  std::unique_ptr<Transcription> t;
  SolveReport report;
  std::vector<Sample> rows;
};

Solved solveBuiltin(const std::string& name, Method method, const std::map<std::string, double>& set = {},
                    unsigned seed = 0, SeedKind kind = SeedKind::Simulation) {
  Solved s;
  s.problem = loadProblem(name, set);
  s.problem.seed_kind = kind;
  if (seed) s.problem.random_seed = seed;
  s.t = std::make_unique<Transcription>(s.problem, method);
  // As saltus optimize: the problem's seed (the simulation's, by default) and restarts.
  const Seeding seeding = makeSeeding(*s.t);
  SolveOptions o;
  o.restarts = seeding.restarts;
  s.report = solve(*s.t, seeding.seed, o);
  s.rows = trajectory(*s.t, s.report.x);
  return s;
}

// The point-mass drop: free flight exact for the polynomial, the impact at an element boundary at
// t = √(2h/g) with v⁺ = −e v⁻, no penetration.
void checkDrop(const Solved& s, double e) {
  ASSERT_TRUE(s.report.feasible) << s.report.stages.back().status << ", largest product " << s.report.largest_product;
  const double h0 = 0.1, t_impact = std::sqrt(2 * h0 / g), v_impact = -std::sqrt(2 * g * h0);
  const double tol = 1e-3;  // complementarity products ≤ 1e-4 leave the contact this loose
  int impact_row = -1;
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    const Sample& r = s.rows[i];
    EXPECT_GT(r.contacts[0].gap, -1e-8) << "penetration at t = " << r.t;
    if (impact_row < 0 && r.contacts[0].pn > 1e-3) impact_row = static_cast<int>(i);
    if (impact_row < 0 && r.t < t_impact - tol) {  // free flight: exact at every point
      // The relaxation A·B ≤ ε leaves forces of up to ε / Σy in flight: at the problem file's
      // Ipopt tol 1e-8 the free fall is exact to 1e-7 m/s (4e-6 at tol 1e-6).
      EXPECT_NEAR(r.q[0], h0 - g * r.t * r.t / 2, 1e-6) << "t = " << r.t;
      EXPECT_NEAR(r.v[0], -g * r.t, 1e-6) << "t = " << r.t;
    }
  }
  ASSERT_GT(impact_row, 0) << "no impulse";
  const Sample& after = s.rows[impact_row];
  const Sample& before = s.rows[impact_row - 1];
  EXPECT_EQ(after.point, 0) << "the impulse acts at a mesh point [n, 0]";
  EXPECT_DOUBLE_EQ(before.t, after.t) << "a velocity jump gives two rows at the same time";
  EXPECT_NEAR(after.t, t_impact, tol);
  EXPECT_NEAR(before.v[0], v_impact, 5 * tol);
  EXPECT_NEAR(after.v[0], -e * before.v[0], 0.01);
  EXPECT_NEAR(after.contacts[0].pn, after.v[0] - before.v[0], 1e-6) << "impulse = m Δv (eq. 6)";
}

TEST(Solver, PointMassDropInelastic) { checkDrop(solveBuiltin("point_mass_drop", Method::Impulsive), 0.0); }

TEST(Solver, PointMassDropHalfElastic) {
  checkDrop(solveBuiltin("point_mass_drop", Method::Impulsive, {{"restitution", 0.5}}, 2), 0.5);
}

// The continuous method cannot land the mass within ε (the force of (10) acts while the gaps of
// its element are not all zero); from the paper's perturbed null seed, with the mass put on the
// ground at [9, 0] in the feasibility stage (a hint), it ends with the shape the paper's Fig. 3
// shows for it.
TEST(Solver, ContinuousSpreadsTheStopOverOneElement) {
  Solved s;
  s.problem = loadProblem("point_mass_drop");
  s.problem.hints.push_back({{Quantity::Kind::Gap, 0}, 8, 0, 0.0, 0.0, "test"});
  s.t = std::make_unique<Transcription>(s.problem, Method::Continuous);
  SolveOptions o;
  o.restarts = s.problem.restarts;
  s.report = solve(
      *s.t, [&](int k) { return Seed{s.t->perturb(s.t->nullSeed(), 0.1, 1 + static_cast<unsigned>(k)), false}; }, o);
  s.rows = trajectory(*s.t, s.report.x);
  // The velocity falls from the impact speed to rest inside one element, with no jump.
  const auto& L = s.t->layout();
  int stops = 0;
  for (const auto& el : L) {
    const double v0 = s.report.x[el.points[0].v], v1 = s.report.x[el.points[el.end].v];
    if (v0 < -1.0 && std::abs(v1) < 0.05) ++stops;
    EXPECT_FALSE(v0 < -1.0 && v1 > 0.05) << "a bounce without restitution";
  }
  EXPECT_EQ(stops, 1);
  for (std::size_t i = 1; i < s.rows.size(); ++i) EXPECT_LT(s.rows[i - 1].t, s.rows[i].t) << "no repeated times";
}

TEST(Solver, PendulumConveyorImpactWithoutCollision) {
  const Solved s = solveBuiltin("pendulum_conveyor", Method::Impulsive);
  ASSERT_TRUE(s.report.feasible) << s.report.stages.back().status << ", largest product " << s.report.largest_product;
  const double mu = 2.0;
  bool impulse = false;
  for (const Sample& r : s.rows) {
    const ContactSample& c = r.contacts[0];
    EXPECT_LT(c.gap, 2e-3) << "the contact opens at t = " << r.t;
    EXPECT_LE(std::abs(c.rt[0]), mu * c.rn + 1e-6) << "outside the friction cone at t = " << r.t;
    if (r.element == 5 && r.point == 0) {  // [6, 0]: the belt steps, a tangential impulse
      EXPECT_GT(std::abs(c.pt[0]), 0.05) << "no tangential impulse at [6, 0]";
      EXPECT_LE(std::abs(c.pt[0]), mu * c.pn + 1e-6);
      impulse = true;
    }
    if (r.element >= 5) {
      EXPECT_NEAR(c.vt[0], 0.0, 2e-3) << "the tip slips on the belt at t = " << r.t;
    }
  }
  EXPECT_TRUE(impulse);
  // Before the belt steps the pendulum rests: the reaction at the tip balances gravity,
  // J_xzᵀ (r_t, r_n) = g(q0) (two equations, two unknowns), to 1 %.
  const dynamics::Model<double>& model = s.problem.scene.model;
  dynamics::Data<double> data(model);
  const Eigen::VectorXd q0 = s.problem.scene.q0;
  const Eigen::VectorXd gravity = dynamics::nonLinearEffects(model, data, q0, Eigen::VectorXd::Zero(2));
  dynamics::forwardKinematics(model, data, q0);
  Eigen::Matrix3Xd J(3, 2);
  const scene::Contact& tip = s.problem.scene.contacts[0];
  dynamics::pointJacobian(model, data, tip.body, tip.p_B, J);
  Eigen::Matrix2d A;
  A << J.row(0), J.row(2);  // x (the belt's t1) and z (its normal)
  const Eigen::Vector2d f = A.transpose().partialPivLu().solve(gravity);  // (r_t along +x, r_n)
  int resting = 0;
  for (const Sample& r : s.rows)
    if (r.element < 5 && r.point >= 1 && r.point <= s.problem.P) {
      EXPECT_NEAR(r.contacts[0].rn, f[1], 0.01 * std::abs(f[1])) << "t = " << r.t;
      EXPECT_NEAR(r.contacts[0].rt[0], f[0], 0.01 * std::abs(f[1])) << "t = " << r.t;
      ++resting;
    }
  EXPECT_EQ(resting, 5 * s.problem.P);
}

// A point mass thrown onto rough ground, without hints, at several parameter values: free flight,
// the landing at t_f = √(2h/g) on an element boundary with the normal impulse m g t_f and the
// tangential impulse the cone allows (or all of the speed), sliding with deceleration μ g to the
// analytic stop, then rest with r_n = m g; friction inside the cone throughout.
TEST(Solver, PointMassThrowLandsSlidesAndStops) {
  struct Case {
    double height, speed, mu;
  };
  for (const Case c : {Case{0.2, 1.5, 0.3}, Case{0.05, 3.0, 0.6}, Case{0.5, 0.5, 1.0}}) {
    const Solved s = solveBuiltin("point_mass_throw", Method::Impulsive,
                                  {{"height", c.height}, {"speed", c.speed}, {"friction", c.mu}});
    ASSERT_TRUE(s.report.feasible) << s.report.stages.back().status << ", largest product " << s.report.largest_product;
    const double t_f = std::sqrt(2 * c.height / g), v_after = std::max(0.0, c.speed - c.mu * g * t_f);
    const double t_stop = t_f + v_after / (c.mu * g);
    int landing = -1;
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
      const Sample& r = s.rows[i];
      const ContactSample& k = r.contacts[0];
      EXPECT_GT(k.gap, -1e-8);
      EXPECT_LE(std::abs(k.rt[0]), c.mu * k.rn + 1e-5) << "outside the cone at t = " << r.t;
      EXPECT_LE(std::abs(k.pt[0]), c.mu * k.pn + 1e-5);
      if (landing < 0 && k.pn > 1e-3) landing = static_cast<int>(i);
    }
    ASSERT_GT(landing, 0) << "no landing impulse";
    const Sample& after = s.rows[landing];
    const Sample& before = s.rows[landing - 1];
    EXPECT_EQ(after.point, 0);
    EXPECT_NEAR(after.t, t_f, 2e-3) << "h = " << c.height;
    EXPECT_NEAR(after.contacts[0].pn, g * t_f, 0.01 * g * t_f);
    EXPECT_NEAR(before.v[0], c.speed, 1e-3);
    EXPECT_NEAR(after.v[0], v_after, 0.01 * c.speed) << "the tangential impulse";
    EXPECT_NEAR(after.v[1], 0, 1e-3) << "inelastic";
    // Sliding, then at rest; the end of the sliding at the analytic stop.
    const double x_stop = c.speed * t_f + v_after * v_after / (2 * c.mu * g);
    for (std::size_t i = landing; i < s.rows.size(); ++i) {
      const Sample& r = s.rows[i];
      if (r.t > t_f + 1e-3 && r.t < t_stop - 0.02 * t_stop) {
        EXPECT_NEAR(r.v[0], v_after - c.mu * g * (r.t - t_f), 0.02 * c.speed) << "sliding at t = " << r.t;
      }
      if (r.t > t_stop + 0.02 * t_stop) {
        EXPECT_NEAR(r.v[0], 0, 1e-3) << "at rest at t = " << r.t;
        EXPECT_NEAR(r.q[0], x_stop, 0.01 * x_stop + 1e-3);
        if (r.point >= 1 && r.point <= s.problem.P) {
          EXPECT_NEAR(r.contacts[0].rn, g, 0.01 * g);
        }
      }
    }
  }
}

// A smooth problem (a pendulum swinging freely, fixed element lengths): the state at the mesh
// points converges at order 2P (Gauss collocation's superconvergence) as N grows.
// Contact between two moving bodies in the optimiser: the block on the pulled cart (scene
// block_on_cart, sliding: F = 30 N > μ g (M + m)), no task but the dynamics, solved by each
// method from its simulation seed. The motion is the analytic one: the block at μ g, the cart at
// (F − μ m g)/M, the block on the deck throughout (0.4 s, before it reaches the deck's end).
// The built-in scene block_on_cart (a block on a cart pulled by 30 N, μ = 0.4) over a fixed horizon.
Problem blockOnCart(double total_time, int P, double h_max, const std::map<std::string, double>& parameters = {}) {
  Problem p;
  p.name = "block_on_cart";
  p.scene = scene::loadScene("block_on_cart", parameters);
  p.N = 8;
  p.P = P;
  p.h_max = h_max;
  p.total_time_kind = TotalTime::Equal;
  p.total_time = total_time;
  return p;
}

TEST(Solver, BlockOnACartSlidesWithTheAnalyticAccelerationsInEveryMethod) {
  const double M = 4, m = 1, mu = 0.4, F = 30;
  const double a_cart = (F - mu * m * g) / M, a_block = mu * g;
  for (const Method method : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    SCOPED_TRACE(toString(method));
    const Problem p = blockOnCart(0.4, 3, 0.05);
    const Transcription t(p, method);
    const Seeding seeding = makeSeeding(t);
    SolveOptions o;
    o.restarts = seeding.restarts;
    const SolveReport report = solve(t, seeding.seed, o);
    ASSERT_TRUE(report.feasible) << report.stages.back().status << ", largest product " << report.largest_product;
    // Collocation is exact for these quadratic motions; backward Euler is first order: its steps
    // lag by about a t h / 2.
    const double h = method == Method::FirstOrder ? 0.4 / (p.N * p.first_order_steps_per_element) : 0.0;
    for (const Sample& r : trajectory(t, report.x)) {
      EXPECT_NEAR(r.q[0], 0.5 * a_cart * r.t * r.t, 1e-4 + a_cart * r.t * h) << "cart at t = " << r.t;
      EXPECT_NEAR(r.q[1], 0.5 * a_block * r.t * r.t, 1e-4 + a_block * r.t * h) << "block at t = " << r.t;
      EXPECT_NEAR(r.q[2], 0.0, 1e-6) << "block height at t = " << r.t;
      if (r.t > 0.01 && r.contacts[0].rn > 0) {  // sliding: on the cone
        EXPECT_NEAR(r.contacts[0].rt[0], mu * r.contacts[0].rn, 1e-3 * m * g) << "friction at t = " << r.t;
      }
    }
  }
}

// Past t = 0.621 s the block of block_on_cart slides off the deck's rear end (models/scenes/
// README.md). The optimiser keeps a point over its plane's rectangle, so it cannot claim contact
// beyond the end: over 0.8 s, with no input to prevent it, the solve is infeasible rather than a
// block carried at deck height past the deck.
TEST(Solver, ABlockThatWouldSlideOffTheDeckIsNotCarriedBeyondIt) {
  const Problem off = blockOnCart(0.8, 2, 0.1);
  const Transcription t(off, Method::Impulsive);
  const SolveReport report = solve(t, makeSeeding(t).seed, SolveOptions{});
  EXPECT_FALSE(report.feasible);
  // The same motion on a deck 10 m long is feasible: the extent is what stops the first solve.
  const Problem long_deck_problem = blockOnCart(0.8, 2, 0.1, {{"deck", 10}});
  const Transcription long_deck(long_deck_problem, Method::Impulsive);
  const SolveReport on_long_deck = solve(long_deck, makeSeeding(long_deck).seed, SolveOptions{});
  EXPECT_TRUE(on_long_deck.feasible) << on_long_deck.stages.back().status;
  // Over 0.4 s it stays on (0.21 m of the 0.5 m behind the centre): feasible, and over the deck.
  const Problem stays_on = blockOnCart(0.4, 2, 0.1);
  const Transcription on(stays_on, Method::Impulsive);
  const SolveReport stays = solve(on, makeSeeding(on).seed, SolveOptions{});
  ASSERT_TRUE(stays.feasible) << stays.stages.back().status;
  for (const Sample& r : trajectory(on, stays.x)) EXPECT_LE(std::abs(r.q[1] - r.q[0]), 0.5 + 1e-9) << "t = " << r.t;
}

// SolveOptions::interrupted, asked at every Ipopt iteration: true stops the solve there, with no
// further stage or attempt, reported as interrupted and not feasible.
TEST(Solver, AnInterruptionStopsTheSolveAtTheNextIteration) {
  const Problem p = testing::pointMassDrop(0.5);
  const Transcription t(p, Method::Impulsive);
  int calls = 0;
  SolveOptions o;
  o.restarts = 3;
  o.interrupted = [&calls] { return ++calls >= 5; };
  const SolveReport report = solve(t, makeSeeding(t).seed, o);
  EXPECT_TRUE(report.interrupted);
  EXPECT_FALSE(report.feasible);
  EXPECT_EQ(calls, 5);
  ASSERT_EQ(report.stages.size(), 1u);
  EXPECT_EQ(report.stages[0].status, "User_Requested_Stop");
  EXPECT_EQ(report.attempts.size(), 1u);
  EXPECT_LE(report.iterations, 5);
  // Never interrupted: the same solve ends feasible.
  o.interrupted = [] { return false; };
  EXPECT_TRUE(solve(t, makeSeeding(t).seed, o).feasible);
}

TEST(Solver, GaussCollocationConvergenceOrder) {
  const dynamics::Model<double> model = testing::pendulumModel({1.0}, {0.5});
  const double T = 0.6, q0 = 1.0;
  const auto [q, v] = testing::rk4Reference(model, Eigen::VectorXd::Constant(1, q0), Eigen::VectorXd::Zero(1),
                                            Eigen::VectorXd::Zero(1), T, 20000);
  for (int P : {1, 2}) {
    std::vector<double> errors;
    for (int N : {4, 8, 16}) {
      Problem p;
      p.scene.model = model;
      p.scene.q0 = Eigen::VectorXd::Constant(1, q0);
      p.scene.v0 = Eigen::VectorXd::Zero(1);
      p.N = N;
      p.P = P;
      p.h_max = T / N;
      p.h_min_ratio = 1.0;  // fixed element lengths
      const Transcription t(p, Method::Impulsive);
      SolveOptions o;
      o.ipopt["tol"] = "1e-12";
      const SolveReport r = solve(t, t.nullSeed(), o);
      ASSERT_TRUE(r.stages[0].succeeded) << r.stages[0].status;
      const auto& end = t.layout().back().points[t.layout().back().end];
      errors.push_back(std::abs(r.x[end.q] - q[0]) + std::abs(r.x[end.v] - v[0]));
    }
    for (std::size_t i = 1; i < errors.size(); ++i) {
      const double order = std::log2(errors[i - 1] / errors[i]);
      EXPECT_NEAR(order, 2.0 * P, 0.35) << "P = " << P << ", errors " << errors[i - 1] << " -> " << errors[i];
    }
  }
}

// Ipopt's own derivative checker on the built-in problems, at a perturbed seed, for every method
// and both stages: first and second derivatives on the point-mass drop, first derivatives on the
// pendulum (Ipopt 3.11's second-order check takes minutes there; nlp_test.cpp checks those
// Hessians against finite differences). The local functions are the same in every element, so
// smaller meshes than the files' keep the checker's n·m·nnz cost down.
TEST(Solver, IpoptDerivativeCheckerPassesOnTheBuiltinProblems) {
  struct Case {
    const char* name;
    int N, P;
    bool second_order;
  };
  for (const Case& c : {Case{"point_mass_drop", 3, 2, true}, Case{"pendulum_conveyor", 6, 2, false}})
    for (Method m : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
      Problem p = loadProblem(c.name);
      p.hints.clear();
      remesh(p, c.N, c.P);
      const Transcription t(p, m);
      const Eigen::VectorXd x = t.perturb(t.nullSeed(), 0.1, 5);
      // The stages share the constraints and differ in the cost: the task stage has every term.
      for (Stage stage : {Stage::Feasibility, Stage::Task}) {
        if (c.second_order && stage == Stage::Feasibility) continue;
        const DerivativeCheckReport r = checkDerivatives(t, stage, x, c.second_order);
        EXPECT_TRUE(r.ran) << c.name << ", " << toString(m) << ": Ipopt's checker gave no summary";
        EXPECT_EQ(r.errors, 0) << c.name << ", " << toString(m) << ":\n" << r.log;
      }
    }
}

// A solve that ends infeasible restarts from the next seed when restarts are allowed, and stops
// at the first feasible attempt; every attempt is reported and the iterations add up.
TEST(Solver, RestartsAfterAnInfeasibleEnd) {
  const Problem p = loadProblem("point_mass_drop", {{"restitution", 0.5}});
  const Transcription t(p, Method::Impulsive);
  SolveOptions o;
  o.restarts = 3;
  std::vector<int> asked;
  const SolveReport r = solve(
      t,
      [&](int k) {
        asked.push_back(k);
        Seed s{seedFromSimulation(t), true};  // solves (PointMassDropHalfElastic)
        if (k == 0) s.x[t.layout()[3].points[1].q] = std::nan("");  // attempt 0 cannot even start
        return s;
      },
      o);
  EXPECT_EQ(asked, (std::vector<int>{0, 1}));
  ASSERT_EQ(r.attempts.size(), 2u);
  EXPECT_FALSE(r.attempts[0].feasible);
  EXPECT_TRUE(r.attempts[1].feasible);
  EXPECT_TRUE(r.feasible);
  EXPECT_EQ(r.iterations, r.attempts[0].iterations + r.attempts[1].iterations);
  EXPECT_LE(r.largest_product, p.complementarity_tolerance);
}

// A feasibility stage that ends just above the tolerance is tightened. The inelastic drop from
// the perturbed simulation seed 5 ends at a local minimum of the penalty with a few small
// impulses while the mass rests (largest product 1.5e-4); the tightening stage, every ε bounded
// by 0.9 × 1e-4 from that point, reaches a solution that lands at the analytic time; without it
// the solve ends infeasible.
// The inelastic drop from the perturbed simulation seed 5: a near miss of the feasibility stage.
Problem nearMissDrop() {
  Problem p = loadProblem("point_mass_drop");
  p.seed_kind = SeedKind::PerturbedSimulation;
  p.random_seed = 5;
  return p;
}

// A solve whose tightening stage (its second) made the drop feasible: it lands at the analytic time.
void expectTightenedDrop(const Transcription& t, const SolveReport& r) {
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[1].name, "tighten");
  EXPECT_TRUE(r.feasible) << r.stages[1].status << ", largest product " << r.largest_product;
  EXPECT_LE(r.largest_product, t.problem().complementarity_tolerance);
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);
}

TEST(Solver, TighteningPullsANearMissUnderTheTolerance) {
  Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions without;
  without.tighten_within = 0;
  const SolveReport near = solve(t, seeding.seed, without);
  ASSERT_FALSE(near.feasible);
  ASSERT_EQ(near.stages.size(), 1u);
  EXPECT_GT(near.largest_product, p.complementarity_tolerance);
  EXPECT_LE(near.largest_product, 10 * p.complementarity_tolerance);

  expectTightenedDrop(t, solve(t, seeding.seed, SolveOptions{}));

  // With a task cost the tightened point is where the task stage starts; without tightening
  // it would start off the constraints (its ε bounded below the near miss's products). With the
  // variable x_m the seed's random draws differ: random seed 1 ends the feasibility stage at the
  // same near miss (1.5e-4).
  p.cost.max_coordinate = 0;
  p.cost.max_weight = 1.0;
  p.random_seed = 1;
  const Transcription task(p, Method::Impulsive);
  const SolveReport c = solve(task, makeSeeding(task).seed, SolveOptions{});
  ASSERT_EQ(c.stages.size(), 3u);
  EXPECT_EQ(c.stages[0].name, "feasibility");
  EXPECT_GT(c.stages[0].largest_product, p.complementarity_tolerance);
  EXPECT_EQ(c.stages[1].name, "tighten");
  EXPECT_EQ(c.stages[2].name, "task");
  EXPECT_LE(c.stages[1].largest_product, p.complementarity_tolerance);
  EXPECT_TRUE(c.converged) << c.stages[2].status << ": " << c.note;
  EXPECT_NEAR(c.objective, 0.1, 1e-3);  // x_m: the drop's start
}

// A feasibility stage stopped by its iteration limit short of the tolerance is tightened too. The
// drop of the test above, allowed 80 iterations (it needs 106), stops at products of 1.6e-4;
// without tightening that is the result, infeasible; with it the tightening stage (its own 80
// iterations) reaches a solution that lands at the analytic time. --tighten-within limits it.
TEST(Solver, AFeasibilityStageStoppedByItsLimitIsTightened) {
  const Problem p = nearMissDrop();
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions o;
  o.ipopt["max_iter"] = "80";
  SolveOptions without = o;
  without.tighten_within = 0;
  const SolveReport stopped = solve(t, seeding.seed, without);
  ASSERT_EQ(stopped.stages.size(), 1u);
  EXPECT_EQ(stopped.stages[0].status, "Maximum_Iterations_Exceeded");
  EXPECT_FALSE(stopped.feasible);
  EXPECT_GT(stopped.largest_product, p.complementarity_tolerance);

  const SolveReport r = solve(t, seeding.seed, o);
  EXPECT_EQ(r.stages[0].status, "Maximum_Iterations_Exceeded");
  expectTightenedDrop(t, r);

  // tighten_within limits it as it does a solved stage: stopped after 10 iterations the products
  // are more than 10 times the tolerance, and with tighten_within = 10 there is no tightening.
  o.ipopt["max_iter"] = "10";
  o.tighten_within = 10;
  const SolveReport early = solve(t, seeding.seed, o);
  ASSERT_EQ(early.stages[0].status, "Maximum_Iterations_Exceeded");
  ASSERT_GT(early.stages[0].largest_product, 10 * p.complementarity_tolerance);
  EXPECT_EQ(early.stages.size(), 1u);
  EXPECT_FALSE(early.feasible);
}

// A task stage stopped by its iteration limit at a feasible point leaves a feasible, not
// converged, solution. The inelastic drop with a task cost (the lowest largest height, x_m): its
// feasibility stage ends at a solution; a task stage allowed no iteration stops at that point
// (Maximum_Iterations_Exceeded) and the result is the drop, feasible and not converged; allowed
// its iterations, the task stage converges.
// A task stage stopped after any number of iterations leaves a feasible point no worse than its
// start (the best feasible point it evaluated, when its end is off the constraints or worse).
// The mechanism itself: Nlp.KeepsTheBestFeasiblePointItEvaluates.
TEST(Solver, ATaskStageStoppedAnywhereKeepsItsBestFeasiblePoint) {
  Problem p = loadProblem("point_mass_drop");
  p.cost.max_coordinate = 0;
  p.cost.max_weight = 1.0;
  const Transcription t(p, Method::Impulsive);
  SolveOptions o;
  o.warm_seed = true;
  // A solution with x_m 0.4 m above the largest height, which the feasibility stage does not
  // lower (it is not in the penalty): the task stage starts from x_m = 0.1 m, the largest height.
  Eigen::VectorXd seed = solve(t, seedFromSimulation(t), o).x;
  const auto names = t.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, t.variables());
  seed[x_m] += 0.4;
  o.task_max_iter = 0;
  const double start = solve(t, seed, o).objective;
  EXPECT_NEAR(start, 0.1, 1e-3);
  int kept = 0;
  double best = start;
  for (int k : {1, 2, 4, 8}) {
    o.task_max_iter = k;
    const SolveReport r = solve(t, seed, o);
    ASSERT_EQ(r.stages.size(), 2u);
    EXPECT_TRUE(r.feasible) << k << " iterations: product " << r.largest_product << ", violation " << r.largest_violation;
    EXPECT_LE(r.objective, start + 1e-12) << k;
    // Checked again from the point itself.
    Nlp nlp(t, Stage::Task, r.x);
    const Eigen::VectorXd g = nlp.constraints(r.x);
    EXPECT_LE(std::max((t.constraintLower() - g).maxCoeff(), (g - t.constraintUpper()).maxCoeff()), o.violation_tolerance) << k;
    EXPECT_NEAR(nlp.cost(r.x), r.objective, 1e-12) << k;
    best = std::min(best, r.objective);
    if (r.stages[1].kept_iteration >= 0) {
      ++kept;
      EXPECT_FALSE(r.converged) << k;
      EXPECT_LE(r.stages[1].kept_iteration, k);
      EXPECT_NE(r.note.find("best feasible point"), std::string::npos) << r.note;
    }
  }
  std::printf("task stage capped at 1, 2, 4, 8 iterations: objective %g from %g, %d kept an earlier point\n", best, start, kept);
  // The drop's first task iterations leave its optimal start for worse or infeasible points.
  EXPECT_GE(kept, 1);
}

TEST(Solver, ATaskStageStoppedAtAFeasiblePointIsFeasibleNotConverged) {
  Problem p = loadProblem("point_mass_drop");
  p.cost.max_coordinate = 0;
  p.cost.max_weight = 1.0;
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd seed = seedFromSimulation(t);
  SolveOptions stopped;
  stopped.warm_seed = true;
  stopped.task_max_iter = 0;
  const SolveReport r = solve(t, seed, stopped);
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_TRUE(r.stages[0].succeeded);
  EXPECT_EQ(r.stages[1].status, "Maximum_Iterations_Exceeded");
  EXPECT_EQ(r.stages[1].iterations, 0);
  EXPECT_TRUE(r.feasible) << "largest product " << r.largest_product << ", violation " << r.largest_violation;
  EXPECT_FALSE(r.converged);
  EXPECT_LE(r.largest_violation, stopped.violation_tolerance);
  Solved s;
  s.report = r;
  s.rows = trajectory(t, r.x);
  checkDrop(s, 0.0);

  SolveOptions full;
  full.warm_seed = true;
  const SolveReport c = solve(t, seed, full);
  ASSERT_EQ(c.stages.size(), 2u);
  EXPECT_TRUE(c.stages[1].succeeded) << c.stages[1].status;
  EXPECT_TRUE(c.feasible);
  EXPECT_TRUE(c.converged);
  // x_m is the largest height: the drop's start, 0.1 m.
  EXPECT_NEAR(c.objective, 0.1, 1e-3);

  // A feasibility stage's point leaves x_m anywhere above the heights: tightened, it is the
  // largest height, and the task objective there is x_m plus the (tiny) weighted penalty.
  Eigen::VectorXd x = r.x;
  const auto names = t.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, t.variables());
  x[x_m] = 7.0;
  t.tightenMaxVariable(x);
  double highest = 0;
  for (const ElementLayout& L : t.layout())
    for (const auto& point : L.points) highest = std::max(highest, x[point.q]);
  EXPECT_DOUBLE_EQ(x[x_m], highest);
  EXPECT_NEAR(x[x_m], 0.1, 1e-9);
  EXPECT_NEAR(Nlp(t, Stage::Task, x).cost(x), 0.1, 1e-3);
}

// The feasibility stage with Ipopt's quasi-Newton Hessian (no second derivatives evaluated) and
// the task stage with the exact one: the same physics as with the exact Hessian throughout.
TEST(Solver, AQuasiNewtonFeasibilityStageAndAnExactTaskStage) {
  Problem p = loadProblem("point_mass_drop");
  p.cost.max_coordinate = 0;  // a task stage: minimise the largest height
  p.cost.max_weight = 1.0;
  for (const bool exact_feasibility : {false, true}) {
    SCOPED_TRACE(exact_feasibility ? "exact" : "limited-memory");
    p.feasibility_exact_hessian = exact_feasibility;
    const Transcription t(p, Method::Impulsive);
    SolveOptions o;
    o.warm_seed = true;
    const SolveReport r = solve(t, seedFromSimulation(t), o);
    ASSERT_GE(r.stages.size(), 2u);
    const StageReport &feasibility = r.stages.front(), &task = r.stages.back();
    EXPECT_EQ(feasibility.exact_hessian, exact_feasibility);
    EXPECT_EQ(feasibility.hessian_evaluations > 0, exact_feasibility) << feasibility.hessian_evaluations;
    EXPECT_TRUE(task.exact_hessian);
    EXPECT_GT(task.hessian_evaluations, 0);
    EXPECT_TRUE(r.converged) << task.status << ", largest product " << r.largest_product;
    EXPECT_NEAR(r.objective, 0.1, 1e-3);  // x_m: the drop's start
    Solved s;
    s.report = r;
    s.rows = trajectory(t, r.x);
    checkDrop(s, 0.0);
  }
}

// Without a task cost a solve that Ipopt solved is converged; a feasibility stage stopped by its
// iteration limit before the products are small is neither feasible nor converged.
TEST(Solver, FeasibleAndConvergedWithoutATaskCost) {
  const Problem p = loadProblem("point_mass_drop");
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd seed = seedFromSimulation(t);
  SolveOptions o;
  o.warm_seed = true;
  const SolveReport r = solve(t, seed, o);
  EXPECT_TRUE(r.feasible);
  EXPECT_TRUE(r.converged);
  SolveOptions cut;
  cut.ipopt["max_iter"] = "1";
  cut.tighten_within = 0;
  const SolveReport n = solve(t, t.nullSeed(), cut);
  EXPECT_EQ(n.stages.back().status, "Maximum_Iterations_Exceeded");
  EXPECT_FALSE(n.feasible) << "largest product " << n.largest_product;
  EXPECT_FALSE(n.converged);
}

}  // namespace
}  // namespace saltus::collocation
