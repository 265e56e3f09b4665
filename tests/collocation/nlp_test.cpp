// Derivatives of the NLP (collocation/nlp.hpp): the Jacobian of every constraint family and the
// Hessian of the Lagrangian from AD of the local functions, against central finite differences
// of the values, at seeded random points, for each method on both paper problems.
#include "collocation/nlp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "collocation/problem_file.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solver.hpp"
#include "scene/scenario.hpp"
#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace {

// A random point near the seed: every variable moved by up to ±0.3 (h kept inside its bounds).
Eigen::VectorXd randomPoint(const Transcription& t, unsigned seed) {
  Eigen::VectorXd x = t.perturb(t.nullSeed(), 0.1, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  for (int i = 0; i < x.size(); ++i) x[i] += U(rng) * (t.variableNames()[i][0] == 'h' ? 0.01 : 1.0);
  return x;
}

// The largest relative error of an NLP's cost gradient against central differences at x.
double worstGradientError(Nlp& nlp, const Eigen::VectorXd& x) {
  const int n = static_cast<int>(x.size());
  Eigen::VectorXd grad(n);
  nlp.eval_grad_f(n, x.data(), true, grad.data());
  const double step = 1e-6;
  double worst = 0;
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    worst = std::max(worst, std::abs(grad[i] - (nlp.cost(xp) - nlp.cost(xm)) / (2 * step)) / (1 + std::abs(grad[i])));
  }
  return worst;
}

// The family of a constraint row: its name up to the first '.' or '['.
std::string family(const std::string& name) { return name.substr(0, name.find_first_of(".[")); }

void checkDerivatives(const Problem& p, Method method) {
  const Transcription t(p, method);
  Nlp nlp(t, Stage::Task, t.nullSeed());
  const Eigen::VectorXd x = randomPoint(t, 7);
  const Eigen::MatrixXd J = nlp.jacobian(x);
  const double step = 1e-6;
  Eigen::MatrixXd Jfd(t.constraints(), t.variables());
  for (int i = 0; i < t.variables(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    Jfd.col(i) = (nlp.constraints(xp) - nlp.constraints(xm)) / (2 * step);
  }
  std::map<std::string, double> worst;
  for (int r = 0; r < t.constraints(); ++r) {
    const double scale = 1 + J.row(r).cwiseAbs().maxCoeff();
    double& w = worst[family(t.constraintNames()[r])];
    w = std::max(w, (J.row(r) - Jfd.row(r)).cwiseAbs().maxCoeff() / scale);
  }
  EXPECT_GE(worst.size(), 4u);
  for (const auto& [name, err] : worst) EXPECT_LT(err, 1e-6) << toString(method) << ": constraint family " << name;

  // Hessian of L = σ f + λᵀ g against differences of its gradient σ ∇f + Jᵀ λ.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd lambda(t.constraints());
  for (int r = 0; r < lambda.size(); ++r) lambda[r] = U(rng);
  const double sigma = 0.7;
  auto gradient = [&](const Eigen::VectorXd& y) {
    Eigen::VectorXd g(t.variables());
    nlp.eval_grad_f(t.variables(), y.data(), true, g.data());
    return Eigen::VectorXd(sigma * g + nlp.jacobian(y).transpose() * lambda);
  };
  const Eigen::MatrixXd H = nlp.hessian(x, sigma, lambda);
  double worst_h = 0;
  for (int i = 0; i < t.variables(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    const Eigen::VectorXd col = (gradient(xp) - gradient(xm)) / (2 * step);
    worst_h = std::max(worst_h, (H.col(i) - col).cwiseAbs().maxCoeff() / (1 + H.col(i).cwiseAbs().maxCoeff()));
  }
  EXPECT_LT(worst_h, 1e-5) << toString(method) << ": Hessian of the Lagrangian";
  EXPECT_GT(H.cwiseAbs().maxCoeff(), 0.0);
}

TEST(NlpDerivatives, PointMassImpulsive) { checkDerivatives(testing::pointMassDrop(0.5, 0.1, 4, 3), Method::Impulsive); }
TEST(NlpDerivatives, PointMassContinuous) { checkDerivatives(testing::pointMassDrop(0.0, 0.1, 4, 3), Method::Continuous); }
TEST(NlpDerivatives, PointMassFirstOrder) { checkDerivatives(testing::pointMassDrop(0.0, 0.1, 2, 3), Method::FirstOrder); }

Problem smallConveyor() {
  Problem p = testing::pendulumConveyor();
  p.N = 3;
  p.P = 3;
  p.surface_steps[0] = {{1, Eigen::Vector3d(0.5, 0, 0)}};
  p.inputs = {0};  // an actuated shoulder, so the input columns are checked too
  p.cost.effort_weight = 0.3;
  return p;
}
TEST(NlpDerivatives, ConveyorImpulsive) { checkDerivatives(smallConveyor(), Method::Impulsive); }
TEST(NlpDerivatives, ConveyorContinuous) { checkDerivatives(smallConveyor(), Method::Continuous); }
TEST(NlpDerivatives, ConveyorFirstOrder) {
  Problem p = smallConveyor();
  p.N = 1;
  checkDerivatives(p, Method::FirstOrder);
}

// The legged benchmarks on two elements of two points: the planar biped (9 coordinates, two feet
// with friction, 12 joint-limit stops on a floating base, six bounded inputs, minimise_max) and the
// spatial monopod (a free Euler base, one foot with a k = 4 cone, stops on a floating base, effort).
Problem smallLegged(const std::string& name, int N = 2) {
  Problem p = loadProblem(name);
  // The monopod's first leg (y ≤ 0 through [13, 0], x = 2.5 there) does not fit a two-element
  // mesh whose end is the final condition x = y = 2.5: only the conditions at the end are kept.
  std::erase_if(p.bounds, [&](const PointBound& b) { return b.element >= 0 && b.element < p.N - 1; });
  remesh(p, N, 2);
  return p;
}
TEST(NlpDerivatives, BipedStopImpulsive) { checkDerivatives(smallLegged("biped_stop"), Method::Impulsive); }
TEST(NlpDerivatives, BipedStopContinuous) { checkDerivatives(smallLegged("biped_stop"), Method::Continuous); }
// First order: one element of 4 backward-Euler steps (under ASan, two took over 4 minutes).
TEST(NlpDerivatives, BipedStopFirstOrder) { checkDerivatives(smallLegged("biped_stop", 1), Method::FirstOrder); }
TEST(NlpDerivatives, MonopodTurnImpulsive) { checkDerivatives(smallLegged("monopod_turn"), Method::Impulsive); }
TEST(NlpDerivatives, MonopodTurnContinuous) { checkDerivatives(smallLegged("monopod_turn"), Method::Continuous); }
TEST(NlpDerivatives, MonopodTurnFirstOrder) { checkDerivatives(smallLegged("monopod_turn", 1), Method::FirstOrder); }

// A point against a plane on a turning body: the contact frame's derivatives enter every
// contact row (equations of motion, gap, slip, restitution).
TEST(NlpDerivatives, BallOnPaddleImpulsive) { checkDerivatives(testing::ballOnPaddleProblem(0.4, 0.5), Method::Impulsive); }
TEST(NlpDerivatives, BallOnPaddleContinuous) { checkDerivatives(testing::ballOnPaddleProblem(0.0, 0.5), Method::Continuous); }
TEST(NlpDerivatives, BallOnPaddleFirstOrder) {
  checkDerivatives(testing::ballOnPaddleProblem(0.0, 0.5, 1, 3), Method::FirstOrder);
}

// The same with the contact point free along the paddle: its plane coordinates s enter the
// equations of motion (the reaction on the paddle at s), the impulse (6), the slip and the offset
// rows with d±, on t1 alone and on both axes.
TEST(NlpDerivatives, BallOnPaddleFreePointImpulsive) {
  checkDerivatives(testing::ballOnPaddleFreePoint(0.4, 0.5, {0}), Method::Impulsive);
  checkDerivatives(testing::ballOnPaddleFreePoint(0.4, 0.5, {0, 1}, 2, 2), Method::Impulsive);
}
TEST(NlpDerivatives, BallOnPaddleFreePointContinuous) {
  checkDerivatives(testing::ballOnPaddleFreePoint(0.0, 0.5, {0}), Method::Continuous);
}
TEST(NlpDerivatives, BallOnPaddleFreePointFirstOrder) {
  checkDerivatives(testing::ballOnPaddleFreePoint(0.0, 0.5, {0}, 1, 3), Method::FirstOrder);
}

// The restitution balance (9a) in its reduced forms against the two-sided functor on the full
// state at both sides of the boundary: a stop's is linear in four variables, a contact with e = 0
// drops the state before the jump. The biped has both (feet e = 0, twelve stops), here with a
// restitution of 0.3 given to the stops; the ball on the paddle keeps both sides (e = 0.4).
void checkRestitutionForms(const Problem& p, int expected_stops, int expected_one_sided, int expected_two_sided) {
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd x = randomPoint(t, 17);
  const int n = t.models().model<double>().nv();
  int stops = 0, one_sided = 0, two_sided = 0;
  for (int e = 1; e < t.elements(); ++e) {
    const auto& after = t.layout()[e].points[0];
    const auto& prev = t.layout()[e - 1];
    const auto& before = prev.points[prev.end];
    for (std::size_t c = 0; c < t.contacts().size(); ++c) {
      const int bi = t.layout()[e].contacts[c].restitution_block;
      if (bi < 0) continue;
      const Block& b = t.blocks()[bi];
      Eigen::VectorXd local(b.vars.size());
      for (std::size_t j = 0; j < b.vars.size(); ++j) local[j] = x[b.vars[j]];
      double reduced = 0;
      b.f->value(local.data(), &reduced);
      Eigen::VectorXd full(4 * n + 2);
      full << x.segment(after.q, n), x.segment(after.v, n), x.segment(before.q, n), x.segment(before.v, n),
          x[t.layout()[e].contacts[c].a_plus], x[t.layout()[e].contacts[c].a_minus];
      const AdFunction<RestitutionBalance> two_sided_form(RestitutionBalance{&t.models(), &t.contacts()[c], true});
      double expected = 0;
      two_sided_form.value(full.data(), &expected);
      EXPECT_NEAR(reduced, expected, 1e-12 * (1 + std::abs(expected))) << t.constraintNames()[b.row];
      if (t.contacts()[c].isStop()) {
        ++stops;
        EXPECT_TRUE(b.f->linear());
        EXPECT_EQ(b.f->inputs(), 4);
      } else if (t.contacts()[c].restitution == 0) {
        ++one_sided;
        EXPECT_EQ(b.f->inputs(), 2 * n + 2);
      } else {
        ++two_sided;
        EXPECT_EQ(b.f->inputs(), 4 * n + 2);
      }
    }
  }
  EXPECT_EQ(stops, expected_stops);
  EXPECT_EQ(one_sided, expected_one_sided);
  EXPECT_EQ(two_sided, expected_two_sided);
}

TEST(Transcription, RestitutionFormsAgreeWithTheTwoSidedBalance) {
  Problem biped = smallLegged("biped_stop", 3);
  for (auto& stop : biped.scene.limits) stop.restitution = 0.3;
  checkRestitutionForms(biped, 2 * 12, 2 * 2, 0);
  checkRestitutionForms(testing::ballOnPaddleProblem(0.4, 0.5), 0, 0, testing::ballOnPaddleProblem(0.4, 0.5).N - 1);
}

// The penalty Σ w ε of the feasibility stage: w = kMidAirImpulseWeight for an impulse at an open
// contact (impact_gap) and for a free point's impulse away from its point (on_point at [n, 0]),
// 1 for every other product, the continuous method's on_point at the collocation points included.
TEST(Transcription, PenaltyWeightsMidAirImpulsesAndImpulsesOffTheirPoint) {
  for (Method method : {Method::Impulsive, Method::Continuous}) {
    const Problem p = testing::ballOnPaddleFreePoint(method == Method::Impulsive ? 0.4 : 0.0, 0.5, {0}, 3, 2);
    const Transcription t(p, method);
    Nlp nlp(t, Stage::Feasibility, t.nullSeed());
    const Eigen::VectorXd x = t.nullSeed();
    const double base = nlp.cost(x);
    int heavy = 0, on_point = 0;
    for (std::size_t k = 0; k < t.productBlocks().size(); ++k) {
      const std::string& name = t.constraintNames()[t.blocks()[t.productBlocks()[k]].row];
      Eigen::VectorXd y = x;
      y[t.penaltyVariables()[k]] += 1.0;
      const bool impulse_off_point = name.starts_with("on_point.") && name.ends_with(",0]");
      const bool expected_heavy = name.starts_with("impact_gap.") || impulse_off_point;
      EXPECT_NEAR(nlp.cost(y) - base, expected_heavy ? kMidAirImpulseWeight : 1.0, 1e-12) << toString(method) << " " << name;
      heavy += expected_heavy;
      on_point += name.starts_with("on_point.");
    }
    EXPECT_EQ(heavy > 0, method == Method::Impulsive) << toString(method);
    EXPECT_GT(on_point, 0) << toString(method);
  }
}

TEST(Transcription, ContinuousRefusesRestitution) {
  try {
    const Problem bouncing = testing::pointMassDrop(0.5);
    Transcription t(bouncing, Method::Continuous);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("restitution"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'ball'"), std::string::npos) << e.what();
  }
}

TEST(Transcription, FirstOrderGetsFourStepsPerElement) {
  const Problem p = testing::pointMassDrop(0.0);
  const Transcription first_order(p, Method::FirstOrder), lg(p, Method::Impulsive);
  EXPECT_EQ(first_order.elements(), 4 * lg.elements());
  EXPECT_NEAR(first_order.variableUpper()[first_order.layout()[0].h], p.h_max / 4, 1e-15);
}

// A joint stop's gap sign·(q_i − limit) is linear in its coordinate: no gap variable and no
// defining row, y ≥ 0 is the coordinate's bound at every point, a gap bound of the problem's is a
// bound on the coordinate, and the products see the same gap (against contact::gap at a random
// point). The biped's 12 stops on three elements of four points: 12 × 3 × 4 variables fewer than
// one a stop and point, and as many gap rows.
TEST(Transcription, AJointStopsGapIsItsCoordinate) {
  Problem biped = smallLegged("biped_stop", 3);
  const int stop = [&] {  // an upper stop
    const Transcription probe(biped, Method::Impulsive);
    for (std::size_t c = 0; c < probe.contacts().size(); ++c)
      if (probe.contacts()[c].isStop() && probe.contacts()[c].sign < 0) return static_cast<int>(c);
    return -1;
  }();
  ASSERT_GE(stop, 0);
  biped.bounds.push_back(PointBound{Quantity{Quantity::Kind::Gap, stop}, 1, 2, 0.05, 0.25, "test"});
  for (Method method : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    const Transcription t(biped, method);
    int stops = 0, gap_variables = 0, gap_rows = 0;
    for (const auto& name : t.variableNames()) gap_variables += name.starts_with("y.");
    for (const auto& name : t.constraintNames()) gap_rows += name.starts_with("gap");
    int points = 0;
    for (const auto& L : t.layout()) points += static_cast<int>(L.points.size());
    for (const ContactPair& cp : t.contacts()) stops += cp.isStop();
    EXPECT_EQ(stops, 12);
    EXPECT_EQ(gap_variables, (static_cast<int>(t.contacts().size()) - stops) * points) << toString(method);
    EXPECT_EQ(gap_rows, (static_cast<int>(t.contacts().size()) - stops) * points) << toString(method);
    const Eigen::VectorXd x = randomPoint(t, 3);
    auto& data = t.models().data<double>();
    for (int n = 0; n < t.elements(); ++n)
      for (std::size_t p = 0; p < t.layout()[n].points.size(); ++p) {
        const auto& pt = t.layout()[n].points[p];
        dynamics::forwardKinematics(t.models().model<double>(), data, x.segment(pt.q, t.models().model<double>().nv()));
        for (std::size_t c = 0; c < t.contacts().size(); ++c) {
          const ContactPair& cp = t.contacts()[c];
          if (!cp.isStop()) continue;
          EXPECT_EQ(t.layout()[n].contacts[c].y[p], -1);
          EXPECT_NEAR(t.gapValue(x, n, static_cast<int>(c), static_cast<int>(p)), contact::gap(cp, data, x.data() + pt.q), 1e-14);
          const int qi = pt.q + cp.position;
          if (n == 0 && p == 0) continue;  // the initial state
          // the problem's element 1, point 2 (first order: its steps' ends, four steps an element)
          const bool bounded = cp.position == t.contacts()[stop].position &&
                               (method == Method::FirstOrder ? n / 4 == 1 && p == 1 : n == 1 && p == 2);
          if (bounded) {  // 0.05 ≤ limit − q ≤ 0.25
            const double limit = t.contacts()[stop].limit;
            EXPECT_DOUBLE_EQ(t.variableUpper()[qi], limit - 0.05);
            EXPECT_DOUBLE_EQ(t.variableLower()[qi], limit - 0.25);
          } else if (cp.sign > 0) {
            EXPECT_DOUBLE_EQ(t.variableLower()[qi], cp.limit) << t.variableNames()[qi];
          } else {
            EXPECT_DOUBLE_EQ(t.variableUpper()[qi], cp.limit) << t.variableNames()[qi];
          }
        }
      }
    // Each stop's contact product at a collocation point: r_n · Σ_i y[n, i] (first order: y[k+1]).
    const Nlp nlp(t, Stage::Feasibility, x);
    int checked = 0;
    for (int b : t.productBlocks()) {
      const Block& blk = t.blocks()[b];
      const std::string& name = t.constraintNames()[blk.row];
      if (!name.starts_with("contact.")) continue;
      const std::string pair = name.substr(8, name.find('[') - 8);
      const auto it = std::find_if(t.contacts().begin(), t.contacts().end(), [&](const ContactPair& cp) { return cp.name == pair; });
      ASSERT_NE(it, t.contacts().end()) << name;
      if (!it->isStop()) continue;
      const int c = static_cast<int>(it - t.contacts().begin());
      const int n = std::stoi(name.substr(name.find('[') + 1)) - 1;
      const int p = std::stoi(name.substr(name.find(',') + 1));
      double sum = 0;
      if (method == Method::FirstOrder) sum = t.gapValue(x, n, c, p);
      else
        for (std::size_t i = 0; i < t.layout()[n].points.size(); ++i) sum += t.gapValue(x, n, c, static_cast<int>(i));
      Eigen::VectorXd local(blk.vars.size());
      for (std::size_t i = 0; i < blk.vars.size(); ++i) local[i] = x[blk.vars[i]];
      const double product = static_cast<const ComplementarityProduct&>(*blk.f).product(local.data());
      EXPECT_NEAR(product, x[t.layout()[n].contacts[c].rn[p]] * sum, 1e-12 * (1 + std::abs(product))) << name;
      ++checked;
    }
    EXPECT_GT(checked, 12) << toString(method);
  }
}

// A plane fixed in a body is a rectangle: its contact point is kept over it at every point of the
// mesh (point 0 of a later element is the previous end), the row is the point's coordinate in
// the plane and its bounds the extent. Block on the cart's top: s_1 = block_x − cart_x, s_2 = 0.
TEST(Transcription, APointIsKeptOverItsBodysPlane) {
  Problem p;
  p.name = "block_on_cart";
  p.scene = scene::loadScene("block_on_cart", {{"deck", 0.5}});
  p.N = 2;
  p.P = 2;
  p.h_max = 0.1;
  for (const Method method : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    SCOPED_TRACE(toString(method));
    const Transcription t(p, method);
    const int points = method == Method::FirstOrder ? 1 + t.elements() : 1 + p.N * (p.P + 1);
    std::vector<int> rows1, rows2;
    for (int r = 0; r < t.constraints(); ++r) {
      const std::string& name = t.constraintNames()[r];
      if (name.rfind("extent.block_on_deck.1[", 0) == 0) rows1.push_back(r);
      if (name.rfind("extent.block_on_deck.2[", 0) == 0) rows2.push_back(r);
    }
    ASSERT_EQ(static_cast<int>(rows1.size()), points);
    ASSERT_EQ(rows2.size(), rows1.size());
    for (int r : rows1) {
      EXPECT_EQ(t.constraintLower()[r], -0.5);
      EXPECT_EQ(t.constraintUpper()[r], 0.5);
    }
    for (int r : rows2) {
      EXPECT_EQ(t.constraintLower()[r], -0.2);
      EXPECT_EQ(t.constraintUpper()[r], 0.2);
    }

    // At a point with the cart at x = 0.1 and the block at x = 0.7 everywhere: s_1 = 0.6, beyond.
    Eigen::VectorXd x = t.nullSeed();
    for (const ElementLayout& L : t.layout())
      for (const ElementLayout::Point& pt : L.points) {
        x[pt.q + 0] = 0.1;  // cart_x
        x[pt.q + 1] = 0.7;  // block_x
        x[pt.q + 2] = 0.3;  // block_z
      }
    Nlp nlp(t, Stage::Task, t.nullSeed());
    const Eigen::VectorXd g = nlp.constraints(x);
    for (int r : rows1) EXPECT_NEAR(g[r], 0.6, 1e-12) << t.constraintNames()[r];
    for (int r : rows2) EXPECT_NEAR(g[r], 0.0, 1e-12) << t.constraintNames()[r];
  }
  // A world plane has no extent rows.
  const Problem drop_problem = testing::pointMassDrop(0.0);
  const Transcription drop(drop_problem, Method::Impulsive);
  for (const std::string& name : drop.constraintNames()) EXPECT_NE(name.rfind("extent.", 0), 0u) << name;
}

// Among the points at which the constraints are evaluated, the lowest objective within the
// tolerances is kept: a lower objective off the constraints, a higher one on them, and a point
// that is not finite leave it; a lower one on them replaces it.
TEST(Nlp, KeepsTheBestFeasiblePointItEvaluates) {
  Problem p = loadProblem("point_mass_drop");
  p.cost.max_coordinate = 0;  // minimise the largest height x_m
  p.cost.max_weight = 1.0;
  const Transcription t(p, Method::Impulsive);
  SolveOptions o;
  o.warm_seed = true;
  const SolveReport r = solve(t, seedFromSimulation(t), o);
  ASSERT_TRUE(r.feasible) << r.stages.back().status;
  const auto names = t.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, t.variables());
  const double tolerance = p.complementarity_tolerance;

  Nlp nlp(t, Stage::Task, r.x);
  nlp.keepBestFeasible(tolerance, 1e-5);
  EXPECT_FALSE(nlp.hasBestFeasible());
  Eigen::VectorXd higher = r.x;
  higher[x_m] += 0.05;  // x ≤ x_m still holds: feasible, 0.05 worse
  nlp.constraints(higher);
  ASSERT_TRUE(nlp.hasBestFeasible());
  EXPECT_EQ(nlp.bestFeasible(), higher);
  EXPECT_EQ(nlp.bestFeasibleIteration(), 0);  // before Ipopt's first iteration
  nlp.constraints(r.x);  // better and feasible: replaces it
  EXPECT_EQ(nlp.bestFeasible(), r.x);
  EXPECT_NEAR(nlp.bestFeasibleObjective(), nlp.cost(r.x), 1e-15);
  Eigen::VectorXd below = r.x;
  below[x_m] -= 0.05;  // lower objective, but the start is 0.05 above x_m
  nlp.constraints(below);
  EXPECT_EQ(nlp.bestFeasible(), r.x);
  Eigen::VectorXd nan = r.x;
  nan[0] = std::nan("");
  nlp.constraints(nan);
  EXPECT_EQ(nlp.bestFeasible(), r.x);
  nlp.constraints(higher);
  EXPECT_EQ(nlp.bestFeasible(), r.x);

  // Not kept unless asked for.
  Nlp plain(t, Stage::Task, r.x);
  plain.constraints(r.x);
  EXPECT_FALSE(plain.hasBestFeasible());
}

// The task stage fixes every ε at its bound, so that each product row reads A·B ≤ 0.9 × the
// tolerance, and weighs the products themselves in the cost (nlp.hpp): its cost is the task cost
// plus the penalty weight times Σ w A·B whatever the ε, its gradient that of this sum (nothing on
// ε), and a solution's ε are its products.
TEST(Nlp, TheTaskStageBoundsTheProductsAndWeighsThemInTheCost) {
  Problem p = loadProblem("point_mass_drop");
  p.cost.max_coordinate = 0;  // minimise the largest height x_m
  p.cost.max_weight = 1.0;
  p.cost.penalty_weight = 3.0;
  const Transcription t(p, Method::Impulsive);
  ASSERT_GT(t.productBlocks().size(), 10u);
  const auto names = t.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, t.variables());
  Nlp task(t, Stage::Task, t.nullSeed());

  const int n = t.variables(), m = t.constraints();
  Eigen::VectorXd xl(n), xu(n), gl(m), gu(m);
  task.get_bounds_info(n, xl.data(), xu.data(), m, gl.data(), gu.data());
  const double bound = kPenaltyBoundFraction * p.complementarity_tolerance;
  for (int e : t.penaltyVariables()) {
    EXPECT_EQ(xl[e], bound) << names[e];
    EXPECT_EQ(xu[e], bound) << names[e];
  }
  for (int b : t.productBlocks()) EXPECT_EQ(gu[t.blocks()[b].row], 0.0);  // A·B − ε ≤ 0

  // The products, from their factors' variables alone.
  const auto products = [&](const Eigen::VectorXd& x) {
    std::vector<double> ab;
    for (int b : t.productBlocks()) {
      const Block& blk = t.blocks()[b];
      Eigen::VectorXd local(blk.vars.size());
      for (std::size_t i = 0; i < blk.vars.size(); ++i) local[i] = x[blk.vars[i]];
      ab.push_back(static_cast<const ComplementarityProduct&>(*blk.f).product(local.data()));
    }
    return ab;
  };
  Eigen::VectorXd x = randomPoint(t, 5);
  const std::vector<double> ab = products(x);
  double penalty = 0;
  for (std::size_t i = 0; i < ab.size(); ++i) penalty += t.penaltyWeights()[i] * ab[i];
  ASSERT_GT(std::abs(penalty), 1e-3);
  EXPECT_NEAR(task.cost(x), x[x_m] + 3.0 * penalty, 1e-12 * (1 + std::abs(penalty)));
  for (int e : t.penaltyVariables()) x[e] = 5.0;
  EXPECT_NEAR(task.cost(x), x[x_m] + 3.0 * penalty, 1e-12 * (1 + std::abs(penalty)));

  // The gradient against central differences of the cost.
  EXPECT_LT(worstGradientError(task, x), 1e-7);
  Eigen::VectorXd grad(n);
  task.eval_grad_f(n, x.data(), true, grad.data());
  for (int e : t.penaltyVariables()) EXPECT_EQ(grad[e], 0.0) << names[e];

  // A solve's task stage: its ε are its products, each within the bound.
  SolveOptions o;
  o.warm_seed = true;
  const SolveReport r = solve(t, seedFromSimulation(t), o);
  ASSERT_TRUE(r.feasible) << r.stages.back().status;
  ASSERT_EQ(r.stages.back().name, "task");
  const std::vector<double> solved = products(r.x);
  for (std::size_t i = 0; i < solved.size(); ++i) {
    EXPECT_EQ(r.x[t.penaltyVariables()[i]], std::max(0.0, solved[i])) << names[t.penaltyVariables()[i]];
    EXPECT_LE(solved[i], p.complementarity_tolerance);
  }
}

// Derivatives at a point that is not finite are an evaluation error (false), not values for
// MUMPS; at a finite point they are evaluated as usual.
TEST(Nlp, DerivativesThatAreNotFiniteAreAnEvaluationError) {
  const Problem p = loadProblem("point_mass_drop");
  const Transcription t(p, Method::Impulsive);
  Nlp nlp(t, Stage::Feasibility, t.nullSeed());
  Ipopt::Index n = 0, m = 0, nnz_j = 0, nnz_h = 0;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(nlp.get_nlp_info(n, m, nnz_j, nnz_h, style));
  std::vector<double> jac(nnz_j), hess(nnz_h), lambda(m, 0.5);
  Eigen::VectorXd x = randomPoint(t, 4);
  EXPECT_TRUE(nlp.eval_jac_g(n, x.data(), true, m, nnz_j, nullptr, nullptr, jac.data()));
  EXPECT_TRUE(nlp.eval_h(n, x.data(), true, 1.0, m, lambda.data(), true, nnz_h, nullptr, nullptr, hess.data()));
  x[t.layout()[1].points[0].q] = std::nan("");
  EXPECT_FALSE(nlp.eval_jac_g(n, x.data(), true, m, nnz_j, nullptr, nullptr, jac.data()));
  EXPECT_FALSE(nlp.eval_h(n, x.data(), true, 1.0, m, lambda.data(), true, nnz_h, nullptr, nullptr, hess.data()));
}

// The penalty stage: each product A·B leaves the constraints (Ipopt sees the others, in order) and
// enters the cost as Σ w A·B with the feasibility stage's weights; its ε are fixed at 0. The
// Hessian of its Lagrangian is the feasibility stage's with each product row's multiplier at σ·w.
TEST(Nlp, ThePenaltyStageLeavesTheProductsOutAndWeighsThemInTheCost) {
  Problem p = loadProblem("point_mass_drop");
  p.cost.penalty_weight = 3.0;  // the task stage's weight, not this stage's
  const Transcription t(p, Method::Impulsive);
  const std::size_t products = t.productBlocks().size();
  ASSERT_GT(products, 10u);
  Nlp penalty(t, Stage::Penalty, t.nullSeed());
  Ipopt::Index n = 0, m = 0, nnz_j = 0, nnz_h = 0;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(penalty.get_nlp_info(n, m, nnz_j, nnz_h, style));
  ASSERT_EQ(n, t.variables());
  ASSERT_EQ(m, t.constraints() - static_cast<int>(products));

  std::vector<bool> is_product(t.constraints(), false);
  for (int b : t.productBlocks()) is_product[t.blocks()[b].row] = true;
  Eigen::VectorXd xl(n), xu(n), gl(m), gu(m);
  penalty.get_bounds_info(n, xl.data(), xu.data(), m, gl.data(), gu.data());
  std::vector<bool> is_epsilon(n, false);
  for (int e : t.penaltyVariables()) is_epsilon[e] = true;
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(xl[i], is_epsilon[i] ? 0.0 : std::max(-1e19, t.hintedLower()[i])) << t.variableNames()[i];
    EXPECT_EQ(xu[i], is_epsilon[i] ? 0.0 : std::min(1e19, t.hintedUpper()[i])) << t.variableNames()[i];
  }
  for (int i = 0, k = 0; i < t.constraints(); ++i) {
    if (is_product[i]) continue;
    EXPECT_EQ(gl[k], std::max(-1e19, t.constraintLower()[i])) << t.constraintNames()[i];
    EXPECT_EQ(gu[k], std::min(1e19, t.constraintUpper()[i])) << t.constraintNames()[i];
    ++k;
  }

  // Ipopt's constraints are the feasibility stage's without the product rows; the cost is
  // Σ w A·B whatever the ε.
  Nlp feasibility(t, Stage::Feasibility, t.nullSeed());
  Eigen::VectorXd x = randomPoint(t, 3);
  const Eigen::VectorXd g_all = feasibility.constraints(x);
  Eigen::VectorXd g(m);
  penalty.eval_g(n, x.data(), true, m, g.data());
  double penalty_cost = 0;
  for (int i = 0, k = 0; i < t.constraints(); ++i)
    if (!is_product[i]) EXPECT_EQ(g[k++], g_all[i]) << t.constraintNames()[i];
  for (std::size_t i = 0; i < products; ++i) {
    const int row = t.blocks()[t.productBlocks()[i]].row;
    penalty_cost += t.penaltyWeights()[i] * (g_all[row] + x[t.penaltyVariables()[i]]);  // A·B − ε + ε
  }
  ASSERT_GT(std::abs(penalty_cost), 1e-3);
  EXPECT_NEAR(penalty.cost(x), penalty_cost, 1e-12 * (1 + std::abs(penalty_cost)));
  for (int e : t.penaltyVariables()) x[e] = 5.0;
  EXPECT_NEAR(penalty.cost(x), penalty_cost, 1e-12 * (1 + std::abs(penalty_cost)));

  // Its gradient against central differences, and its Jacobian the feasibility stage's rows.
  EXPECT_LT(worstGradientError(penalty, x), 1e-7);
  const Eigen::MatrixXd J = penalty.jacobian(x), J_all = feasibility.jacobian(x);
  for (int i = 0; i < t.constraints(); ++i) {
    if (is_product[i])
      EXPECT_EQ(J.row(i).norm(), 0.0) << t.constraintNames()[i];
    else
      EXPECT_EQ((J.row(i) - J_all.row(i)).norm(), 0.0) << t.constraintNames()[i];
  }
  Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(t.constraints(), -1.0, 2.0), lambda_all = lambda;
  const double sigma = 0.7;
  for (std::size_t i = 0; i < products; ++i) lambda_all[t.blocks()[t.productBlocks()[i]].row] = sigma * t.penaltyWeights()[i];
  const Eigen::MatrixXd H = penalty.hessian(x, sigma, lambda), H_all = feasibility.hessian(x, 0.0, lambda_all);
  EXPECT_LT((H - H_all).norm(), 1e-12 * (1 + H_all.norm()));
  EXPECT_GT(H.norm(), 0.0);

  // With task_penalty the task stage takes this form: the products left out, the cost the task
  // cost (x_m) plus penalty_weight × Σ w A·B.
  p.cost.max_coordinate = 0;
  p.cost.max_weight = 1.0;
  p.task_penalty = true;
  const Transcription tt(p, Method::Impulsive);
  Nlp task(tt, Stage::Task, tt.nullSeed());
  ASSERT_TRUE(task.get_nlp_info(n, m, nnz_j, nnz_h, style));
  EXPECT_EQ(m, tt.constraints() - static_cast<int>(tt.productBlocks().size()));
  const auto names = tt.variableNames();
  const int x_m = static_cast<int>(std::find(names.begin(), names.end(), "x_max") - names.begin());
  ASSERT_LT(x_m, tt.variables());
  Nlp tt_feasibility(tt, Stage::Feasibility, tt.nullSeed());
  Eigen::VectorXd y = randomPoint(tt, 4);
  const Eigen::VectorXd gy = tt_feasibility.constraints(y);
  double weighted = 0;
  for (std::size_t i = 0; i < tt.productBlocks().size(); ++i)
    weighted += tt.penaltyWeights()[i] * (gy[tt.blocks()[tt.productBlocks()[i]].row] + y[tt.penaltyVariables()[i]]);
  EXPECT_NEAR(task.cost(y), y[x_m] + 3.0 * weighted, 1e-12 * (1 + std::abs(weighted)));
  Eigen::VectorXd lower(tt.variables()), upper(tt.variables()), g_lower(m), g_upper(m);
  task.get_bounds_info(tt.variables(), lower.data(), upper.data(), m, g_lower.data(), g_upper.data());
  for (int e : tt.penaltyVariables()) EXPECT_EQ(upper[e], 0.0);
}

}  // namespace
}  // namespace saltus::collocation
