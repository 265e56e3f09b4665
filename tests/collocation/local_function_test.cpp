// AD of the local functions (collocation/local_function.hpp): the Hessian of λᵀF with the inputs
// a functor declares linear (no outer directions for them) against an analytic Hessian, and, for
// every functor of the transcription (collocation/functions.hpp), against the same functor with
// every input taken as nonlinear: a wrong linearity claim shows as a missing second derivative,
// and a pair a functor computes itself (the EOM's bilinear and q̇ blocks) is checked against the
// nested duals' value.
#include "collocation/local_function.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "collocation/functions.hpp"
#include "collocation/nlp.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/transcription.hpp"
#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace {

// y0 = sin(x0) x2 + x1² x3,  y1 = x0 x1 + 3 x2 − x4: affine in (x2, x3, x4) for fixed x0, x1.
struct Toy {
  bool declare = true;
  int inputs() const { return 5; }
  int outputs() const { return 2; }
  bool nonlinear(int i) const { return !declare || i < 2; }
  template <class S>
  void operator()(const S* x, S* y) const {
    using std::sin;
    y[0] = sin(x[0]) * x[2] + x[1] * x[1] * x[3];
    y[1] = x[0] * x[1] + S(3) * x[2] - x[4];
  }
};

// The functor F with the linearity declaration hidden.
template <class F>
struct AllNonlinear {
  F f;
  int inputs() const { return f.inputs(); }
  int outputs() const { return f.outputs(); }
  template <class S>
  void operator()(const S* x, S* y) const { f(x, y); }
};

Eigen::MatrixXd lowerHessian(const LocalFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& lambda) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Constant(f.inputs(), f.inputs(), 1234.0);  // the upper triangle stays
  f.hessian(x.data(), lambda.data(), H.data());
  return H.triangularView<Eigen::Lower>();
}

TEST(AdFunction, LinearInputsHaveNoOuterDirections) {
  const AdFunction<Toy> declared(Toy{true}), full(Toy{false});
  EXPECT_EQ(full.hessianSweeps(), 5);      // one per input
  EXPECT_EQ(declared.hessianSweeps(), 2);  // x0, x1 only
  const Eigen::VectorXd x = (Eigen::VectorXd(5) << 0.3, -1.2, 0.7, 2.1, -0.4).finished();
  const Eigen::VectorXd lambda = Eigen::Vector2d(0.8, -1.5);
  // Analytic lower triangle of λ0 ∇²y0 + λ1 ∇²y1.
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(5, 5);
  H(0, 0) = -lambda[0] * std::sin(x[0]) * x[2];
  H(1, 1) = 2 * lambda[0] * x[3];
  H(1, 0) = lambda[1];
  H(2, 0) = lambda[0] * std::cos(x[0]);
  H(3, 1) = 2 * lambda[0] * x[1];
  EXPECT_LT((lowerHessian(declared, x, lambda) - H).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((lowerHessian(full, x, lambda) - H).cwiseAbs().maxCoeff(), 1e-14);
  // The pairs within L are written (zero), not left as they were.
  Eigen::MatrixXd raw = Eigen::MatrixXd::Constant(5, 5, 7.0);
  declared.hessian(x.data(), lambda.data(), raw.data());
  EXPECT_EQ(raw(4, 2), 0.0);
  EXPECT_EQ(raw(3, 3), 0.0);
  EXPECT_EQ(raw(2, 4), 7.0);  // upper triangle untouched
}

// Σ_{j≤i} (1 + i + 10 j) x_i x_j over nine inputs, all nonlinear: 45 pairs.
struct Nine {
  int inputs() const { return 9; }
  int outputs() const { return 1; }
  template <class S>
  void operator()(const S* x, S* y) const {
    S s(0);
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j <= i; ++j) s += S(1.0 + i + 10.0 * j) * x[i] * x[j];
    y[0] = s;
  }
};

TEST(AdFunction, SweepsHoldEveryPairOnce) {
  // At least one sweep per input (its diagonal), none over 8 pairs: 45 pairs fit nine.
  const AdFunction<Nine> f(Nine{});
  EXPECT_EQ(f.hessianSweeps(), 9);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(9, -1, 1), lambda = Eigen::VectorXd::Constant(1, 0.5);
  const Eigen::MatrixXd H = lowerHessian(f, x, lambda);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j <= i; ++j) EXPECT_DOUBLE_EQ(H(i, j), 0.5 * (1.0 + i + 10.0 * j) * (i == j ? 2 : 1)) << i << "," << j;
}

// Every AD constraint block of a transcription: declared-linear Hessian = all-nonlinear Hessian,
// with fewer sweeps (Effort, a cost term inside a ScaledFunction, declares nothing).
// A kind named in `no_fewer` may have every input nonlinear in the scene at hand (a point that
// moves with every coordinate): its sweeps are not required to be fewer.
template <class F>
bool compareIfIs(const LocalFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& lambda, std::set<std::string>& seen,
                 const char* name, const std::set<std::string>& no_fewer) {
  const auto* ad = dynamic_cast<const AdFunction<F>*>(&f);
  if (!ad) return false;
  const AdFunction<AllNonlinear<F>> full(AllNonlinear<F>{ad->functor()});
  const Eigen::MatrixXd H = lowerHessian(*ad, x, lambda), Hfull = lowerHessian(full, x, lambda);
  EXPECT_LT((H - Hfull).cwiseAbs().maxCoeff(), 1e-12 * (1 + Hfull.cwiseAbs().maxCoeff())) << name;
  // The pairs left out of the NLP's Hessian structure (hessianPair false) are zero in the
  // all-nonlinear Hessian too; the structure leaves some out.
  int left_out = 0;
  for (int j = 0; j < f.inputs(); ++j)
    for (int i = j; i < f.inputs(); ++i) {
      if (f.hessianPair(i, j)) continue;
      ++left_out;
      EXPECT_LE(std::abs(Hfull(i, j)), 1e-12 * (1 + Hfull.cwiseAbs().maxCoeff())) << name << " (" << i << ", " << j << ")";
    }
  EXPECT_GT(left_out, 0) << name;
  EXPECT_LE(ad->hessianSweeps(), full.hessianSweeps()) << name;
  // The Jacobian: the columns a functor forms itself (the EOM's M(q), −B, −Jᵀ ∂f/∂r) against AD
  // of every column. Every entry is overwritten.
  Eigen::MatrixXd J = Eigen::MatrixXd::Constant(f.outputs(), f.inputs(), 1234.0), Jfull = J;
  ad->jacobian(x.data(), J.data());
  full.jacobian(x.data(), Jfull.data());
  EXPECT_LT((J - Jfull).cwiseAbs().maxCoeff(), 1e-12 * (1 + Jfull.cwiseAbs().maxCoeff())) << name;
  EXPECT_LE(ad->jacobianSweeps(), full.jacobianSweeps()) << name;
  if (seen.insert(name).second && !no_fewer.contains(name)) {
    EXPECT_LT(ad->hessianSweeps(), full.hessianSweeps()) << name;
  }
  return true;
}

void checkDeclaredLinearity(const Problem& p, Method method, int expected_kinds, const std::set<std::string>& no_fewer = {}) {
  const Transcription t(p, method);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  std::set<std::string> seen;
  for (const Block& b : t.blocks()) {
    const LocalFunction& f = *b.f;
    Eigen::VectorXd x(f.inputs()), lambda(f.outputs());
    for (int i = 0; i < x.size(); ++i) x[i] = U(rng);
    for (int r = 0; r < lambda.size(); ++r) lambda[r] = U(rng);
    compareIfIs<EquationOfMotion>(f, x, lambda, seen, "eom", no_fewer) ||
        compareIfIs<GapDefinition>(f, x, lambda, seen, "gap", no_fewer) ||
        compareIfIs<RestitutionBalance>(f, x, lambda, seen, "restitution", no_fewer) ||
        compareIfIs<SlipSlack>(f, x, lambda, seen, "slip", no_fewer) ||
        compareIfIs<Integration>(f, x, lambda, seen, "integration", no_fewer) ||
        compareIfIs<FreePointOffset>(f, x, lambda, seen, "offset", no_fewer) ||
        compareIfIs<PlaneCoordinate>(f, x, lambda, seen, "extent", no_fewer);
  }
  EXPECT_EQ(static_cast<int>(seen.size()), expected_kinds) << toString(method);
}

Problem conveyorWithInput() {
  Problem p = testing::pendulumConveyor();
  p.N = 2;
  p.P = 2;
  p.inputs = {0};
  p.cost.effort_weight = 0.3;
  return p;
}

TEST(AdFunction, DeclaredLinearInputsConveyor) {
  checkDeclaredLinearity(conveyorWithInput(), Method::Impulsive, 5);   // eom, gap, restitution, slip, integration
  checkDeclaredLinearity(conveyorWithInput(), Method::FirstOrder, 4);  // no restitution
}
TEST(AdFunction, DeclaredLinearInputsPointMass) {
  checkDeclaredLinearity(testing::pointMassDrop(0.5, 0.1, 2, 2), Method::Impulsive, 4);  // eom, gap, restitution, integration
}

// A free contact point: its s in the equations of motion (pairs the EOM writes itself, from
// first-order passes) and the slip, and the offset rows; free on t1 alone, the paddle's extent
// along t2 is an extent row (PlaneCoordinate), whose point moves with every coordinate here.
TEST(AdFunction, DeclaredLinearInputsFreePoint) {
  for (const std::vector<int>& axes : {std::vector<int>{0}, std::vector<int>{0, 1}}) {
    const int extent = axes.size() == 1 ? 1 : 0;
    checkDeclaredLinearity(testing::ballOnPaddleFreePoint(0.4, 0.5, axes, 2, 2), Method::Impulsive, 6 + extent, {"extent"});
    checkDeclaredLinearity(testing::ballOnPaddleFreePoint(0.0, 0.5, axes, 2, 2), Method::FirstOrder, 5 + extent, {"extent"});
  }
}

// The Ollie of the point-mass riders: the feet free along the deck (offset rows) and kept over
// its width (extent rows), each foot moving with the board's three coordinates and its own two,
// not the other foot's.
TEST(AdFunction, DeclaredLinearInputsOllie) {
  Problem p = loadProblem("ollie_simple");
  std::erase_if(p.bounds, [&](const PointBound& b) { return b.element >= 0 && b.element < p.N - 1; });
  p.hints.clear();  // at [10, 0]: off a mesh of two elements
  remesh(p, 2, 2);
  checkDeclaredLinearity(p, Method::Impulsive, 7);  // eom, gap, restitution, slip, integration, offset, extent
  // The feet's reactions act at their plane coordinates s, where the Jacobian depends on no
  // world translation (ContactPair::reaction_jacobian_with): the equations of motion depend on
  // the board's angle alone among the q, and each is one sweep of AD columns (the feet's s) at a jump.
  const Transcription t(p, Method::Impulsive);
  const auto& model = t.models().model<double>();
  int eoms = 0;
  for (const Block& b : t.blocks())
    if (const auto* eom = dynamic_cast<const AdFunction<EquationOfMotion>*>(b.f.get())) {
      ++eoms;
      for (int k = 0; k < model.nv(); ++k)
        EXPECT_EQ(eom->functor().dependsOn(k), !dynamics::isWorldTranslation(model, k)) << k;
      if (!eom->functor().with_dynamics) { EXPECT_EQ(eom->jacobianSweeps(), 1); }
    }
  EXPECT_GT(eoms, 0);
}

// The legged problems: the blocks skip the coordinates a contact does not move with (the biped's
// arms for a foot, the other leg; ContactPair::moves_with) and the stops are linear.
TEST(AdFunction, DeclaredLinearInputsLegged) {
  for (const char* name : {"biped_stop", "monopod_turn"}) {
    Problem p = loadProblem(name);
    std::erase_if(p.bounds, [&](const PointBound& b) { return b.element >= 0 && b.element < p.N - 1; });
    remesh(p, 2, 2);
    checkDeclaredLinearity(p, Method::Impulsive, 5);  // eom, gap, restitution (feet), slip, integration
    // The EOM's Jacobian without AD sweeps of its own: RNEA's derivatives for q and q̇, the
    // reactions' pass over the q a foot's Jacobian depends on (jacobianColumns; checked against
    // AD of every column in checkDeclaredLinearity), none of them a world translation (the
    // base's x and z, or x, y and z).
    const Transcription t(p, Method::Impulsive);
    const auto& model = t.models().model<double>();
    int n = 0;
    for (int k = 0; k < model.nv(); ++k) n += !dynamics::isWorldTranslation(model, k);
    EXPECT_EQ(model.nv() - n, model.base == dynamics::BaseType::Free ? 3 : 2) << name;
    int eoms = 0;
    for (const Block& b : t.blocks())
      if (const auto* eom = dynamic_cast<const AdFunction<EquationOfMotion>*>(b.f.get())) {
        ++eoms;
        EXPECT_EQ(eom->jacobianSweeps(), 0) << name;
        int reaction_columns = 0;
        for (int k = 0; k < model.nv(); ++k) {
          reaction_columns += eom->functor().inReactions(k);
          if (dynamics::isWorldTranslation(model, k)) { EXPECT_FALSE(eom->functor().inReactions(k)) << name << " " << k; }
        }
        EXPECT_GT(reaction_columns, 0) << name;
      }
    EXPECT_GT(eoms, 0) << name;
  }
}

// y = sin(x0) x1² + x0 x2 + 5 x2 x3: the sweeps compute the pairs within (x0, x1), the functor
// writes (x2, x0) and (x3, x2) itself; x3 is affine. Two sweeps of at most two inner directions:
// the chunk-of-4 duals.
struct Supplied {
  int inputs() const { return 4; }
  int outputs() const { return 1; }
  bool nonlinear(int i) const { return i < 3; }
  bool pairByAd(int i, int) const { return i < 2; }
  bool pairSupplied(int i, int j) const { return (i == 2 && j == 0) || (i == 3 && j == 2); }
  void addHessian(const double*, const double* lambda, double* H) const {
    H[2 + 0 * 4] += lambda[0];
    H[3 + 2 * 4] += 5 * lambda[0];
  }
  template <class S>
  void operator()(const S* x, S* y) const {
    using std::sin;
    y[0] = sin(x[0]) * x[1] * x[1] + x[0] * x[2] + S(5) * x[2] * x[3];
  }
};

TEST(AdFunction, SuppliedPairsAndSmallChunks) {
  const AdFunction<Supplied> f(Supplied{});
  EXPECT_EQ(f.hessianSweeps(), 2);
  EXPECT_TRUE(f.smallSweeps());
  const Eigen::VectorXd x = (Eigen::VectorXd(4) << 0.4, -0.9, 1.3, 0.6).finished();
  const Eigen::VectorXd lambda = Eigen::VectorXd::Constant(1, -0.7);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(4, 4);
  H(0, 0) = -lambda[0] * std::sin(x[0]) * x[1] * x[1];
  H(1, 0) = 2 * lambda[0] * std::cos(x[0]) * x[1];
  H(1, 1) = 2 * lambda[0] * std::sin(x[0]);
  H(2, 0) = lambda[0];
  H(3, 2) = 5 * lambda[0];
  EXPECT_LT((lowerHessian(f, x, lambda) - H).cwiseAbs().maxCoeff(), 1e-14);
  // Every pair of the lower triangle is written (the left-out ones zero), the upper one is not.
  Eigen::MatrixXd raw = Eigen::MatrixXd::Constant(4, 4, 7.0);
  f.hessian(x.data(), lambda.data(), raw.data());
  EXPECT_EQ(raw(2, 2), 0.0);
  EXPECT_EQ(raw(3, 0), 0.0);
  EXPECT_EQ(raw(0, 3), 7.0);
  // The Hessian's structure: the swept pairs and the supplied ones, no others.
  for (int j = 0; j < 4; ++j)
    for (int i = j; i < 4; ++i)
      EXPECT_EQ(f.hessianPair(i, j), i < 2 || (i == 2 && j == 0) || (i == 3 && j == 2)) << i << ", " << j;
}

// The effort h Σ_j b_j Σ_i u_i[j]²: its declared pairs (the diagonal of u, and h with each u)
// against the all-nonlinear Hessian, with one sweep for each u instead of one per input pair row.
TEST(AdFunction, EffortPairs) {
  const Effort effort{Eigen::Vector3d(0.2, 0.5, 0.3), 2};
  const AdFunction<Effort> f(effort);
  const AdFunction<AllNonlinear<Effort>> full(AllNonlinear<Effort>{effort});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd x(f.inputs());
  for (int i = 0; i < x.size(); ++i) x[i] = U(rng);
  const Eigen::VectorXd lambda = Eigen::VectorXd::Constant(1, 0.8);
  const Eigen::MatrixXd H = lowerHessian(f, x, lambda);
  EXPECT_LT((H - lowerHessian(full, x, lambda)).cwiseAbs().maxCoeff(), 1e-14);
  for (int i = 1; i < f.inputs(); ++i) {
    const double b = effort.b[(i - 1) / effort.nu];
    EXPECT_NEAR(H(i, i), 2 * lambda[0] * x[0] * b, 1e-14);
    EXPECT_NEAR(H(i, 0), 2 * lambda[0] * b * x[i], 1e-14);
  }
  for (int j = 0; j < f.inputs(); ++j)
    for (int i = j; i < f.inputs(); ++i) EXPECT_EQ(f.hessianPair(i, j), i > 0 && (i == j || j == 0)) << i << ", " << j;
  EXPECT_LT(f.hessianSweeps(), full.hessianSweeps());
}

// The pendulum's blocks: the EOM's nested duals only over q (one sweep per coordinate, chunks of
// 4), the slip and restitution functions over q too, integration without sweeps. Their Hessians
// against the all-nonlinear chunk-of-8 route are checked in DeclaredLinearInputsConveyor.
TEST(AdFunction, ConveyorSweeps) {
  const Problem problem = conveyorWithInput();
  const Transcription t(problem, Method::Impulsive);
  std::set<std::string> seen;
  for (const Block& b : t.blocks()) {
    if (const auto* eom = dynamic_cast<const AdFunction<EquationOfMotion>*>(b.f.get())) {
      EXPECT_EQ(eom->hessianSweeps(), 2);  // nv = 2, with and without dynamics
      EXPECT_TRUE(eom->smallSweeps());
      seen.insert(eom->functor().with_dynamics ? "eom" : "impulsive eom");
    } else if (const auto* slip = dynamic_cast<const AdFunction<SlipSlack>*>(b.f.get())) {
      EXPECT_EQ(slip->hessianSweeps(), 2);
      EXPECT_TRUE(slip->smallSweeps());
      seen.insert("slip");
    } else if (const auto* res = dynamic_cast<const AdFunction<RestitutionBalance>*>(b.f.get())) {
      EXPECT_EQ(res->hessianSweeps(), res->functor().before ? 4 : 2);  // one q per side
      EXPECT_TRUE(res->smallSweeps());
      seen.insert("restitution");
    } else if (const auto* in = dynamic_cast<const AdFunction<Integration>*>(b.f.get())) {
      EXPECT_EQ(in->hessianSweeps(), 0);
      seen.insert("integration");
    }
  }
  EXPECT_EQ(seen.size(), 5u);
}

// The NLP's Hessian of the Lagrangian with multipliers on one EOM block only is that block's
// local Hessian scattered to its variables; with every multiplier and σ zero it is zero.
TEST(NlpHessian, OneBlockAndZeroMultipliers) {
  const Problem p = conveyorWithInput();
  const Transcription t(p, Method::Impulsive);
  Nlp nlp(t, Stage::Feasibility, t.nullSeed());
  Eigen::VectorXd x = t.perturb(t.nullSeed(), 0.2, 3);
  EXPECT_EQ(nlp.hessian(x, 0.0, Eigen::VectorXd::Zero(t.constraints())).cwiseAbs().maxCoeff(), 0.0);
  int index = -1;
  for (std::size_t i = 0; i < t.blocks().size(); ++i)
    if (dynamic_cast<const AdFunction<EquationOfMotion>*>(t.blocks()[i].f.get()) && t.blocks()[i].row >= 0)
      index = static_cast<int>(i);
  ASSERT_GE(index, 0);
  const Block& b = t.blocks()[index];
  const int n = b.f->inputs();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(t.constraints()), local_l(b.f->outputs()), local_x(n);
  for (int r = 0; r < b.f->outputs(); ++r) lambda[b.row + r] = local_l[r] = 0.5 + r;
  for (int i = 0; i < n; ++i) local_x[i] = x[b.vars[i]];
  const Eigen::MatrixXd Hl = lowerHessian(*b.f, local_x, local_l);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(t.variables(), t.variables());
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) {
      expected(b.vars[i], b.vars[j]) += Hl(i, j);
      if (i != j) expected(b.vars[j], b.vars[i]) += Hl(i, j);
    }
  const Eigen::MatrixXd H = nlp.hessian(x, 0.0, lambda);  // feasibility stage: the penalty is linear
  EXPECT_LT((H - expected).cwiseAbs().maxCoeff(), 1e-13 * (1 + expected.cwiseAbs().maxCoeff()));
  EXPECT_GT(expected.cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace saltus::collocation
