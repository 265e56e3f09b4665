// Two-stage solves of the paper's built-in problems (collocation/solver.hpp), asserting the
// physics of the solutions (paper Figs. 3 and 4), and the convergence order of Gauss
// collocation on a smooth problem.
#include "collocation/solver.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "collocation/nlp.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/seeding.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solution.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "scene/scenario.hpp"
#include "tests/support/drop_checks.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/problems.hpp"
#include "tests/support/rk4.hpp"

namespace saltus::collocation {
namespace {

using testing::checkDrop;
using testing::Solved;

constexpr double g = 9.81;


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
  for (const Sample& r : trajectory(on, stays.x)) {
    EXPECT_LE(std::abs(r.q[1] - r.q[0]), 0.5 + 1e-9) << "t = " << r.t;
    // The trajectory's plane coordinates: the block's place on the deck (the cart's origin, t1 = x).
    EXPECT_NEAR(r.contacts[0].s[0], r.q[1] - r.q[0], 1e-12) << "t = " << r.t;
    EXPECT_EQ(r.contacts[0].s[1], 0.0) << "t = " << r.t;
  }
}

// A contact point free along the deck (ContactPair::free_axes): block_on_cart's block (no force
// on the cart) starts in the air beyond the deck's end (x 0.7 m, the deck ends at 0.5 m; a point
// kept over the rectangle at every mesh point could not start there), 0.2 m up, moving back at
// 2 m/s. It lands at t_l = sqrt(2 · 0.2 / g) at x = 0.7 − 2 t_l; its sliding impact's friction
// impulse μ m g t_l slows it and pushes the cart back (the impulse's opposite), and it slides
// (relative deceleration μ g (1 + m/M)) until both move at the momentum's −2 m / (M + m). The
// contact point s follows the block along the deck from where it lands to where it stops.
TEST(Solver, AFreeContactPointLandsFromBeyondTheDeckAndFollowsTheSlide) {
  const double M = 4, m = 1, mu = 0.4, x0 = 0.7, z0 = 0.2, v0 = -2;
  Problem p = blockOnCart(0.6, 3, 0.1, {{"force", 0}});
  p.N = 12;
  p.scene.contacts.at(0).free_axes = {0};
  p.scene.q0 = Eigen::Vector3d(0, x0, z0);
  p.scene.v0 = Eigen::Vector3d(0, v0, 0);
  const Transcription t(p, Method::Impulsive);
  const Seeding seeding = makeSeeding(t);
  SolveOptions o;
  o.restarts = seeding.restarts;
  const SolveReport report = solve(t, seeding.seed, o);
  ASSERT_TRUE(report.feasible) << report.stages.back().status << ", largest product " << report.largest_product;
  const double t_land = std::sqrt(2 * z0 / g), x_land = x0 + v0 * t_land;
  const double v_block = v0 + mu * g * t_land, v_cart = -mu * m * g * t_land / M;
  const double slide = (v_block - v_cart) * (v_block - v_cart) / (2 * mu * g * (1 + m / M));
  const double s_rest = x_land - slide, v_together = v0 * m / (M + m);
  double s_first = NAN, s_last = NAN;
  for (int n = 0; n < t.elements(); ++n) {
    const ElementLayout& L = t.layout()[n];
    const auto& C = L.contacts[0];
    for (std::size_t k = 0; k < L.points.size(); ++k) {
      if (C.s[k] < 0 || report.x[C.rn[k]] < 1e-6) continue;
      // Loaded: the contact point is the block's place on the deck, to the relaxed
      // complementarity r_n |s − s_A| ≤ tolerance (the vanishing impulses at [n, 0] at rest let
      // it drift by about 1e-6 m); under the block's weight to 1e-6 m.
      const double s = report.x[C.s[k]], rn = report.x[C.rn[k]];
      const double along = report.x[L.points[k].q + 1] - report.x[L.points[k].q];
      EXPECT_LE(rn * std::abs(s - along), p.complementarity_tolerance) << "element " << n + 1 << ", point " << k;
      if (k > 0) {
        EXPECT_NEAR(s, along, 1e-6) << "element " << n + 1 << ", point " << k;
      }
      if (std::isnan(s_first)) s_first = s;
      s_last = s;
    }
  }
  EXPECT_NEAR(s_first, x_land, 2e-3);
  EXPECT_NEAR(s_last, s_rest, 2e-3);
  // The trajectory's plane coordinate (its .s column) is the free point's variable, where the
  // reaction acts, at the points that have one (those with a reaction); elsewhere the block's place
  // on the deck.
  const std::vector<Sample> samples = trajectory(t, report.x);
  int with_variable = 0;
  for (const Sample& r : samples) {
    const int s_index = t.layout()[r.element].contacts[0].s[r.point];
    with_variable += s_index >= 0;
    EXPECT_EQ(r.contacts[0].s[0], s_index >= 0 ? report.x[s_index] : r.q[1] - r.q[0]) << "t = " << r.t;
  }
  EXPECT_GT(with_variable, static_cast<int>(samples.size()) / 2);
  const Sample end = samples.back();
  EXPECT_NEAR(end.v[0], v_together, 1e-6);
  EXPECT_NEAR(end.v[1], v_together, 1e-6);
  EXPECT_NEAR(end.q[1] - end.q[0], s_rest, 2e-3);
  // Without the free point the block is kept over the deck at every mesh point, [1, 0] too,
  // where it starts 0.7 m along a deck that ends at 0.5 m: that row cannot hold.
  Problem fixed = p;
  fixed.scene.contacts.at(0).free_axes.clear();
  const Transcription tf(fixed, Method::Impulsive);
  const std::vector<std::string>& names = tf.constraintNames();
  const auto row = std::find(names.begin(), names.end(), "extent.block_on_deck.1[1,0]") - names.begin();
  ASSERT_LT(row, static_cast<std::ptrdiff_t>(names.size()));
  Nlp nlp(tf, Stage::Task, tf.nullSeed());
  EXPECT_NEAR(nlp.constraints(tf.nullSeed())[row], x0, 1e-12);
  EXPECT_DOUBLE_EQ(tf.constraintUpper()[row], 0.5);
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
  // A contact point free along a turning body's plane: its s in the equations of motion, the
  // slip and the offset rows (first order: the second-order check takes 8 s here and over 10
  // minutes under ASan; NlpDerivatives.BallOnPaddleFreePoint* check the Hessian by differences).
  for (Method m : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    const Problem p = testing::ballOnPaddleFreePoint(m == Method::Impulsive ? 0.4 : 0.0, 0.5, {0}, 2, 2);
    const Transcription t(p, m);
    const DerivativeCheckReport r = checkDerivatives(t, Stage::Task, t.perturb(t.nullSeed(), 0.1, 5), false);
    EXPECT_TRUE(r.ran) << "free point, " << toString(m) << ": Ipopt's checker gave no summary";
    EXPECT_EQ(r.errors, 0) << "free point, " << toString(m) << ":\n" << r.log;
  }
}

// The same solve twice in one process gives the same iterates, bit for bit: MUMPS's ordering
// (SCOTCH) runs on one thread, its random generator reset before every stage (solver.cpp,
// tuneProcessForSolves and resetOrderingRandomness). With a thread per core the monopod's
// iterates came apart in the eighth digit by the sixth iteration, differently at every run;
// without the reset the second solve ended elsewhere. A small problem's ordering shows neither.
TEST(Solver, TheSameSolveTwiceGivesTheSameIteratesBitForBit) {
  Problem p = loadProblem("monopod_turn");
  p.exact_hessian = p.feasibility_exact_hessian = true;
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd x0 = makeSeeding(t).seed(0).x;
  SolveOptions o;
  o.ipopt["max_iter"] = "12";
  o.task_max_iter = 0;
  o.tighten_within = 0;
  const SolveReport first = solve(t, x0, o);
  const SolveReport second = solve(t, x0, o);
  ASSERT_EQ(first.stages.size(), second.stages.size());
  ASSERT_EQ(first.stages[0].iterations, 12) << first.stages[0].status;
  EXPECT_NE(first.x, x0);  // it moved
  EXPECT_TRUE(first.x == second.x) << "largest difference "
                                   << (first.x - second.x).cwiseAbs().maxCoeff();
  EXPECT_EQ(first.stages[0].objective, second.stages[0].objective);
}

}  // namespace
}  // namespace saltus::collocation
