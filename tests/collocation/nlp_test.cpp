// The NLP (collocation/nlp.hpp): the Jacobian of every constraint family and the Hessian of the
// Lagrangian from AD of the local functions against central finite differences of the values, at
// seeded random points, for each method on both paper problems; the best feasible point kept, and
// the products weighed in the cost of the penalty and task stages.
#include "collocation/nlp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "collocation/problem_file.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solver.hpp"
#include "tests/support/problems.hpp"
#include "tests/support/transcription_points.hpp"

namespace saltus::collocation {
namespace {

using testing::randomPoint;
using testing::smallLegged;

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

TEST(NlpDerivatives, BipedStopImpulsive) { checkDerivatives(smallLegged("biped_stop"), Method::Impulsive); }
TEST(NlpDerivatives, BipedStopContinuous) { checkDerivatives(smallLegged("biped_stop"), Method::Continuous); }
// First order: one element of 4 backward-Euler steps (under ASan, two took over 4 minutes).
TEST(NlpDerivatives, BipedStopFirstOrder) { checkDerivatives(smallLegged("biped_stop", 1), Method::FirstOrder); }
TEST(NlpDerivatives, MonopodTurnImpulsive) { checkDerivatives(smallLegged("monopod_turn"), Method::Impulsive); }
TEST(NlpDerivatives, MonopodTurnContinuous) { checkDerivatives(smallLegged("monopod_turn"), Method::Continuous); }
TEST(NlpDerivatives, MonopodTurnFirstOrder) { checkDerivatives(smallLegged("monopod_turn", 1), Method::FirstOrder); }

// The Ollie of the point-mass riders: each foot free along the deck, a contact between two trees
// whose riders' translations move the foot against the turning deck (pairs a world plane does
// not have), and the board's tail and wheels on the ground.
TEST(NlpDerivatives, OllieSimpleImpulsive) {
  Problem p = loadProblem("ollie_simple");
  std::erase_if(p.bounds, [&](const PointBound& b) { return b.element >= 0 && b.element < p.N - 1; });
  p.hints.clear();  // at [10, 0]: off a mesh of two elements
  remesh(p, 2, 2);
  checkDerivatives(p, Method::Impulsive);
}

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
// On the pendulum, whose Jacobian and Hessian depend on the angles (a point mass's would not:
// its one coordinate is a world translation, which the Hessian does not read).
TEST(Nlp, DerivativesThatAreNotFiniteAreAnEvaluationError) {
  const Problem p = loadProblem("pendulum_conveyor");
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
    if (!is_product[i]) { EXPECT_EQ(g[k++], g_all[i]) << t.constraintNames()[i]; }
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
