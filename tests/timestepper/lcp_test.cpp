// Lemke and PGS against Siconos Numerics (lcp_lexicolemke, lcp_pgs) on random P-matrix LCPs and
// Stewart–Trinkle contact LCPs (also badly scaled ones); degenerate LCPs, one on which Lemke
// without the lexicographic rule cycles; infeasibility; no heap allocation per solve; edge cases.
#include "timestepper/lcp.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tests/support/contact_lcp.hpp"
#include "tests/support/heap_counter.hpp"

namespace saltus::timestepper {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

using testing::ContactLcp;
using testing::randomContactLcp;
using testing::randomMatrix;
using testing::randomVector;
using testing::SiconosSolution;
using testing::siconosSolve;

// M = A Aᵀ + I (symmetric positive definite), plus B − Bᵀ when not symmetric: positive definite,
// hence a P-matrix, so the LCP has exactly one solution.
MatrixXd randomPMatrix(std::mt19937& rng, int n, bool symmetric) {
  const MatrixXd A = randomMatrix(rng, n, n, 1.0 / std::sqrt(n));
  MatrixXd M = A * A.transpose() + MatrixXd::Identity(n, n);
  if (!symmetric) {
    const MatrixXd B = randomMatrix(rng, n, n, 1.0 / std::sqrt(n));
    M += B - B.transpose();
  }
  return M;
}

struct Solution {
  LcpResult result;
  VectorXd z, w;
};

Solution lemke(LcpSolver& solver, const MatrixXd& M, const VectorXd& q, int max_pivots = 0) {
  Solution s{{}, VectorXd::Zero(q.size()), VectorXd::Zero(q.size())};
  s.result = solver.solveLemke(M, q, s.z, s.w, max_pivots);
  return s;
}

Solution pgs(LcpSolver& solver, const MatrixXd& M, const VectorXd& q, int max_iterations, double tolerance) {
  Solution s{{}, VectorXd::Zero(q.size()), VectorXd::Zero(q.size())};
  s.result = solver.solvePgs(M, q, s.z, s.w, max_iterations, tolerance);
  return s;
}

// Lemke's method as in many textbook codes: full tableau, ratio ties go to z0, else to the
// smallest row index; no lexicographic rule. Reports whether it revisited a basis.
struct PlainLemkeRun {
  bool solved = false, cycled = false;
  int pivots = 0;
};

PlainLemkeRun plainLemke(const MatrixXd& M, const VectorXd& q, int max_pivots) {
  const int n = static_cast<int>(q.size()), z0 = 2 * n;
  MatrixXd T(n, 2 * n + 2);  // [I  −M  −1  q]
  T << MatrixXd::Identity(n, n), -M, -VectorXd::Ones(n), q;
  std::vector<int> basis(n);
  for (int i = 0; i < n; ++i) basis[i] = i;
  const auto pivot = [&](int r, int c) {
    T.row(r) /= T(r, c);
    for (int i = 0; i < n; ++i)
      if (i != r) T.row(i) -= T(i, c) * T.row(r);
  };
  PlainLemkeRun run;
  int r = 0;
  for (int i = 0; i < n; ++i)
    if (q[i] <= q[r]) r = i;
  pivot(r, z0);
  int leaving = basis[r];
  basis[r] = z0;
  run.pivots = 1;
  std::set<std::pair<std::vector<int>, int>> seen;
  while (run.pivots < max_pivots) {
    const int entering = leaving < n ? leaving + n : leaving - n;
    if (!seen.insert({basis, entering}).second) {
      run.cycled = true;
      return run;
    }
    r = -1;
    double best = INFINITY;
    for (int i = 0; i < n; ++i) {
      if (T(i, entering) <= 1e-12) continue;
      const double ratio = T(i, 2 * n + 1) / T(i, entering);
      if (ratio < best - 1e-12 || (std::abs(ratio - best) <= 1e-12 && basis[i] == z0)) {
        best = ratio;
        r = i;
      }
    }
    if (r < 0) return run;
    pivot(r, entering);
    leaving = basis[r];
    basis[r] = entering;
    ++run.pivots;
    if (leaving == z0) {
      run.solved = true;
      return run;
    }
  }
  return run;
}

TEST(Lcp, ResidualMeasuresComplementarityAndSign) {
  const MatrixXd M = MatrixXd::Identity(2, 2);
  const VectorXd q = (VectorXd(2) << -1, 2).finished();
  EXPECT_EQ(lcpResidual(M, q, (VectorXd(2) << 1, 0).finished()), 0.0);        // w = (0, 2)
  EXPECT_EQ(lcpResidual(M, q, (VectorXd(2) << 0, 0).finished()), 2.0);        // w_1 = −1
  EXPECT_EQ(lcpResidual(M, q, (VectorXd(2) << 3, 0).finished()), 2.0);        // z_1 w_1 = 3·2
  EXPECT_EQ(lcpResidual(M, q, (VectorXd(2) << 1, -0.5).finished()), 1.0);     // z_2 = −0.5, w_2 = 1.5
  EXPECT_THROW(lcpResidual(M, q, VectorXd::Zero(3)), std::invalid_argument);
}

TEST(Lemke, MatchesSiconosOnRandomPMatrices) {
  std::mt19937 rng(101);
  LcpSolver solver(80);
  for (int n : {1, 2, 3, 5, 8, 13, 20, 40, 80}) {
    for (bool symmetric : {true, false}) {
      for (int trial = 0; trial < 4; ++trial) {
        const MatrixXd M = randomPMatrix(rng, n, symmetric);
        const VectorXd q = randomVector(rng, n);
        const Solution s = lemke(solver, M, q);
        ASSERT_EQ(s.result.status, LcpStatus::Solved) << "n " << n << " symmetric " << symmetric;
        EXPECT_LE(s.result.residual, 1e-10);
        EXPECT_LE(lcpResidual(M, q, s.z), 1e-10) << "n " << n << " symmetric " << symmetric;
        EXPECT_LE((s.w - (M * s.z + q)).cwiseAbs().maxCoeff(), 1e-12);
        const SiconosSolution reference = siconosSolve(SICONOS_LCP_LEMKE, M, q);
        ASSERT_EQ(reference.info, 0);
        EXPECT_LE((s.z - reference.z).cwiseAbs().maxCoeff(), 1e-9 * (1 + s.z.cwiseAbs().maxCoeff()))
            << "n " << n << " symmetric " << symmetric;
      }
    }
  }
}

TEST(Pgs, ConvergesOnSymmetricPositiveDefiniteAndMatchesLemkeAndSiconos) {
  std::mt19937 rng(102);
  LcpSolver solver(40);
  for (int n : {1, 2, 5, 10, 20, 40}) {
    for (int trial = 0; trial < 4; ++trial) {
      const MatrixXd M = randomPMatrix(rng, n, true);
      const VectorXd q = randomVector(rng, n);
      const Solution exact = lemke(solver, M, q);
      ASSERT_EQ(exact.result.status, LcpStatus::Solved);
      const Solution s = pgs(solver, M, q, 10000, 1e-10);
      ASSERT_EQ(s.result.status, LcpStatus::Solved) << "n " << n << ", residual " << s.result.residual;
      EXPECT_LE(lcpResidual(M, q, s.z), 1e-8);
      EXPECT_LE((s.z - exact.z).cwiseAbs().maxCoeff(), 1e-8) << "n " << n;
      const SiconosSolution reference = siconosSolve(SICONOS_LCP_PGS, M, q, 10000, 1e-12);
      ASSERT_EQ(reference.info, 0);
      EXPECT_LE((s.z - reference.z).cwiseAbs().maxCoeff(), 1e-8) << "n " << n;
    }
  }
}

TEST(Pgs, WarmStartAtTheSolutionNeedsNoSweep) {
  std::mt19937 rng(103);
  LcpSolver solver(10);
  const MatrixXd M = randomPMatrix(rng, 10, true);
  const VectorXd q = randomVector(rng, 10);
  const Solution exact = lemke(solver, M, q);
  VectorXd z = exact.z, w(10);
  const LcpResult r = solver.solvePgs(M, q, z, w, 100, 1e-10);
  EXPECT_EQ(r.status, LcpStatus::Solved);
  EXPECT_EQ(r.iterations, 0);
  // A cold start on the same problem does sweep.
  z.setZero();
  EXPECT_GT(solver.solvePgs(M, q, z, w, 100, 1e-10).iterations, 0);
}

TEST(Lemke, SolvesContactLcpsAndCrossChecksWithSiconos) {
  std::mt19937 rng(104);
  LcpSolver solver(200);
  struct Shape {
    int nv, contacts, directions;
  };
  // Planar point, a box on the ground (more friction rows than velocities), a robot with a few
  // feet, many contacts on a small system. Opposite friction directions make D A Dᵀ singular.
  const Shape shapes[] = {{3, 1, 2}, {3, 2, 2}, {6, 4, 4}, {12, 2, 4}, {18, 4, 4}, {18, 6, 8}, {6, 8, 4}, {30, 20, 8}};
  int problems = 0, siconos_solutions = 0, siconos_false_success = 0;
  for (const Shape& shape : shapes) {
    for (int trial = 0; trial < 20; ++trial) {
      const ContactLcp lcp = randomContactLcp(rng, shape.nv, shape.contacts, shape.directions);
      const int n = static_cast<int>(lcp.q.size());
      ASSERT_EQ(lcp.M.diagonal().tail(shape.contacts).cwiseAbs().maxCoeff(), 0.0);  // λ rows: zero diagonal
      ASSERT_GT((lcp.M - lcp.M.transpose()).cwiseAbs().maxCoeff(), 0.1);           // not symmetric
      const Solution s = lemke(solver, lcp.M, lcp.q);
      ASSERT_EQ(s.result.status, LcpStatus::Solved)
          << "nv " << shape.nv << " contacts " << shape.contacts << " k " << shape.directions << " trial " << trial;
      EXPECT_LT(s.result.residual, 1e-9);
      EXPECT_LT(lcpResidual(lcp.M, lcp.q, s.z), 1e-9) << "n " << n << " trial " << trial;
      // Siconos on the same problem. Solutions need not be unique (β along a face of the
      // friction cone), so each is judged by how well it satisfies the LCP.
      const SiconosSolution reference = siconosSolve(SICONOS_LCP_LEMKE, lcp.M, lcp.q);
      const double reference_residual = lcpResidual(lcp.M, lcp.q, reference.z);
      ++problems;
      if (reference.info == 0 && reference_residual < 1e-7) ++siconos_solutions;
      if (reference.info == 0 && !(reference_residual < 1e-7)) ++siconos_false_success;
    }
  }
  // Siconos' lexicolemke takes any positive pivot (no tolerance) and reports success without
  // checking; on these rank-deficient problems it sometimes pivots on round-off and returns
  // info 0 with a z that is far from a solution. It must still solve a good share of them for
  // the comparison to mean something.
  EXPECT_GE(siconos_solutions, problems / 2);
  std::printf("[ contact ] %d contact LCPs: Saltus solved all; Siconos lcp_lexicolemke returned a solution on %d, "
              "info 0 with residual >= 1e-7 on %d\n",
              problems, siconos_solutions, siconos_false_success);
}

// Warm start: from the solution of a neighbouring problem (the time-stepper's previous step) the
// guessed basis is usually right, and the answer is the cold one where the solution is unique;
// from a wrong guess Lemke still solves the problem.
TEST(Lemke, WarmStartFromANeighbouringSolution) {
  std::mt19937 rng(111);
  LcpSolver solver(60);
  int problems = 0, no_pivot = 0;
  for (int n : {1, 2, 4, 8, 20}) {
    for (int trial = 0; trial < 20; ++trial) {
      const MatrixXd M = randomPMatrix(rng, n, trial % 2 == 0);  // P-matrix: one solution
      const VectorXd q = randomVector(rng, n);
      const VectorXd q_next = q + randomVector(rng, n, 1e-4);
      const Solution cold = lemke(solver, M, q_next);
      ASSERT_EQ(cold.result.status, LcpStatus::Solved);
      VectorXd z = lemke(solver, M, q).z, w(n);  // the guess
      const LcpResult warm = solver.solveLemkeWarm(M, q_next, z, w);
      ASSERT_EQ(warm.status, LcpStatus::Solved) << "n " << n << " trial " << trial;
      EXPECT_LT((z - cold.z).cwiseAbs().maxCoeff(), 1e-9 * (1 + cold.z.cwiseAbs().maxCoeff())) << "n " << n;
      EXPECT_LT(lcpResidual(M, q_next, z), 1e-9);
      ++problems;
      no_pivot += warm.iterations == 0;
    }
  }
  EXPECT_GE(no_pivot, problems * 3 / 4);  // a small change of q rarely changes the basis
  // Contact LCPs (solutions not unique): warm from the own solution needs no pivot; from a
  // wrong guess (every z_i > 0, or a random positive set) the result is still a solution.
  int contact_no_pivot = 0, contact_problems = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const ContactLcp lcp = randomContactLcp(rng, 6, 2, 4);
    const int n = static_cast<int>(lcp.q.size());
    const Solution cold = lemke(solver, lcp.M, lcp.q);
    ASSERT_EQ(cold.result.status, LcpStatus::Solved);
    VectorXd z = cold.z, w(n);
    LcpResult warm = solver.solveLemkeWarm(lcp.M, lcp.q, z, w);
    ASSERT_EQ(warm.status, LcpStatus::Solved);
    EXPECT_LT(lcpResidual(lcp.M, lcp.q, z), 1e-9);
    ++contact_problems;
    contact_no_pivot += warm.iterations == 0;
    for (int guess = 0; guess < 2; ++guess) {
      z = guess == 0 ? VectorXd::Ones(n) : VectorXd(randomVector(rng, n).cwiseMax(0.0));
      warm = solver.solveLemkeWarm(lcp.M, lcp.q, z, w);
      ASSERT_EQ(warm.status, LcpStatus::Solved) << "trial " << trial << " guess " << guess;
      EXPECT_LT(lcpResidual(lcp.M, lcp.q, z), 1e-9);
      EXPECT_LT((w - (lcp.M * z + lcp.q)).cwiseAbs().maxCoeff(), 1e-9);
    }
  }
  // Random contact LCPs often have degenerate solutions (a sticking contact: λ = 0 with w_λ = 0;
  // β on a facet of the cone), where the set z_i > 0 alone leaves M̂_PP singular and Lemke runs.
  EXPECT_GE(contact_no_pivot, contact_problems / 3);
  // A trivial problem (q ≥ 0) gives z = 0 whatever the guess.
  VectorXd z = VectorXd::Ones(3), w(3);
  const LcpResult trivial = solver.solveLemkeWarm(MatrixXd::Identity(3, 3), VectorXd::Ones(3), z, w);
  EXPECT_EQ(trivial.status, LcpStatus::Solved);
  EXPECT_EQ(z, VectorXd::Zero(3));
}

TEST(Lemke, SolvesBadlyScaledContactLcps) {
  // Inverse masses from 1e-3 to 1e3 against the dimensionless friction-cone rows, and
  // velocities from 1e-3 to 1e3: the equilibration keeps one round-off scale for all rows.
  std::mt19937 rng(111);
  std::uniform_real_distribution<double> exponent(-3, 3);
  std::uniform_int_distribution<int> velocities(1, 30), contacts(1, 12), half_directions(1, 4);
  LcpSolver solver(200);
  for (int trial = 0; trial < 400; ++trial) {
    const int m = contacts(rng), k = 2 * half_directions(rng);
    ContactLcp lcp = randomContactLcp(rng, velocities(rng), m, k);
    lcp.M.topLeftCorner(m * (k + 1), m * (k + 1)) *= std::pow(10.0, exponent(rng));
    lcp.q *= std::pow(10.0, exponent(rng));
    const Solution s = lemke(solver, lcp.M, lcp.q);
    ASSERT_EQ(s.result.status, LcpStatus::Solved) << "trial " << trial << ": " << toString(s.result.status);
    // Residual relative to the magnitudes in w = M z + q.
    const VectorXd magnitude = lcp.q.cwiseAbs() + lcp.M.cwiseAbs() * s.z;
    EXPECT_LT(s.result.residual, 1e-9 * magnitude.maxCoeff()) << "trial " << trial;
  }
}

TEST(Pgs, IsHonestOnContactLcps) {
  // PGS is approximate on the friction LCP: whatever it returns, the status must agree with
  // the residual it reports, and the residual with the z it returns.
  std::mt19937 rng(105);
  LcpSolver solver(60);
  int converged = 0, problems = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const ContactLcp lcp = randomContactLcp(rng, 6 + trial % 7, 1 + trial % 4, 4);
    const Solution s = pgs(solver, lcp.M, lcp.q, 2000, 1e-8);
    ++problems;
    ASSERT_TRUE(s.result.status == LcpStatus::Solved || s.result.status == LcpStatus::NotConverged);
    EXPECT_NEAR(s.result.residual, lcpResidual(lcp.M, lcp.q, s.z), 1e-12 * (1 + s.result.residual));
    EXPECT_EQ(s.result.status == LcpStatus::Solved, s.result.residual <= 1e-8);
    if (s.result.status == LcpStatus::Solved) ++converged;
  }
  // With the λ rows frozen instead (no step for M_ii = 0) PGS converges on almost none of these.
  EXPECT_GE(converged, problems * 3 / 4);
  std::printf("[ contact ] PGS (2000 sweeps, tolerance 1e-8) converged on %d of %d contact LCPs\n", converged,
              problems);
}

TEST(Lemke, LexicographicRuleAvoidsCyclingOnADegenerateLcp) {
  // M ≥ 0 with positive diagonal is strictly copositive, so LCP(q, M) has a solution and Lemke's
  // method reaches one. All q_i are equal and every ratio test ties at 0 after the first pivot.
  const MatrixXd M = (MatrixXd(4, 4) << 1, 0, 2, 2, 0, 1, 2, 2, 2, 0, 1, 0, 1, 1, 2, 1).finished();
  const VectorXd q = -VectorXd::Ones(4);
  const PlainLemkeRun plain = plainLemke(M, q, 100);
  EXPECT_TRUE(plain.cycled) << "plain Lemke: " << plain.pivots << " pivots, solved " << plain.solved;
  EXPECT_FALSE(plain.solved);
  LcpSolver solver(4);
  const Solution s = lemke(solver, M, q);
  EXPECT_EQ(s.result.status, LcpStatus::Solved);
  EXPECT_LE(s.result.iterations, 10);
  EXPECT_LE(lcpResidual(M, q, s.z), 1e-14);
  const SiconosSolution reference = siconosSolve(SICONOS_LCP_LEMKE, M, q);
  EXPECT_EQ(reference.info, 0);
  EXPECT_LE(lcpResidual(M, q, reference.z), 1e-14);
}

TEST(Lemke, DegenerateLcpsWithRepeatedRowsAreSolved) {
  // Ties by construction: runs of identical rows of M and repeated entries of q, so many ratio
  // tests tie. M ≥ 0 with a positive diagonal (each run's row is ≥ 1 over the run's columns)
  // is strictly copositive: a solution exists and Lemke's method must reach it.
  std::mt19937 rng(106);
  std::uniform_int_distribution<int> small(0, 2), run_length(1, 3);
  LcpSolver solver(12);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 3 + trial % 10;
    MatrixXd M(n, n);
    for (int i = 0; i < n;) {
      const int run = std::min(run_length(rng), n - i);
      for (int j = 0; j < n; ++j) M(i, j) = small(rng) + (j >= i && j < i + run ? 1 : 0);
      for (int r = 1; r < run; ++r) M.row(i + r) = M.row(i);
      i += run;
    }
    VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = -small(rng);
    const Solution s = lemke(solver, M, q);
    ASSERT_EQ(s.result.status, LcpStatus::Solved) << "trial " << trial << "\nM\n" << M << "\nq " << q.transpose();
    EXPECT_LE(lcpResidual(M, q, s.z), 1e-12) << "trial " << trial;
  }
}

TEST(Lemke, InfeasibleLcpsEndOnASecondaryRay) {
  LcpSolver solver(2);
  {
    // w = −z − 1 < 0 for every z ≥ 0.
    const MatrixXd M = MatrixXd::Constant(1, 1, -1.0);
    const VectorXd q = VectorXd::Constant(1, -1.0);
    const Solution s = lemke(solver, M, q);
    EXPECT_EQ(s.result.status, LcpStatus::RayTermination) << toString(s.result.status);
    EXPECT_GE(s.result.residual, 1.0);
  }
  {
    // M skew-symmetric (copositive-plus): w_2 = −z_1 − 1 < 0, infeasible.
    const MatrixXd M = (MatrixXd(2, 2) << 0, 1, -1, 0).finished();
    const VectorXd q = -VectorXd::Ones(2);
    const Solution s = lemke(solver, M, q);
    EXPECT_EQ(s.result.status, LcpStatus::RayTermination) << toString(s.result.status);
    EXPECT_GE(s.result.residual, 1.0);
  }
  {
    // M = 0 with a negative q_i.
    const MatrixXd M = MatrixXd::Zero(2, 2);
    const VectorXd q = (VectorXd(2) << 1, -2).finished();
    const Solution s = lemke(solver, M, q);
    EXPECT_EQ(s.result.status, LcpStatus::RayTermination) << toString(s.result.status);
    EXPECT_GE(s.result.residual, 2.0);
  }
}

// A contact LCP of the monopod's simulation seed (one foot, k = 4, μ = 0.6; rows p_n, β_1..4, λ):
// the foot sticks, and the lateral friction rows carry round-off, q = ∓5.5e-12 m/s against terms
// of up to 21 m/s. Pivoting treats such entries as zeros, so the basis leaves w of that size;
// it is a solution (of an LCP perturbed at round-off) and must be accepted. A real lateral slip
// of 1e-6 m/s in the same LCP is pivoted on and stopped by the friction.
TEST(Lemke, AcceptsRoundOffInAFrictionRowOfAStickingContact) {
  const double e = 1.15626917618962e-11, f = 2.32011995863909e-11;
  const MatrixXd M = (MatrixXd(6, 6) << 0.488752197086101, 1.59046126132941, -e, -1.59046126132941, e, 0,  //
                      1.59046126132941, 8.0204362186736, -f, -8.0204362186736, f, 1,                      //
                      -e, -f, 3.6395256780623, f, -3.6395256780623, 1,                                    //
                      -1.59046126132941, -8.0204362186736, f, 8.0204362186736, -f, 1,                     //
                      e, f, -3.6395256780623, -f, 3.6395256780623, 1,                                     //
                      0.6, -1, -1, -1, -1, 0)
                         .finished();
  VectorXd q = (VectorXd(6) << -0.126394401586447, 0.92819931874574, -5.53584469352666e-12, -0.92819931874574,
                5.5357310218942e-12, 0)
                   .finished();
  LcpSolver solver(6);
  const auto check = [&](const Solution& s, double tolerance) {
    ASSERT_EQ(s.result.status, LcpStatus::Solved) << toString(s.result.status);
    const VectorXd w = M * s.z + q;
    for (int i = 0; i < 6; ++i) {
      EXPECT_GE(s.z[i], 0.0) << i;
      EXPECT_GE(w[i], -tolerance) << i;
      EXPECT_LE(std::min(s.z[i], std::abs(w[i])), tolerance) << i;
    }
    EXPECT_LE(s.z[1] + s.z[2] + s.z[3] + s.z[4], 0.6 * s.z[0] + tolerance) << "inside the cone";
  };
  const Solution stuck = lemke(solver, M, q);
  check(stuck, 1e-9 * 21);
  EXPECT_GT(stuck.z[0], 0.0);
  EXPECT_GT(stuck.z[5] + (M * stuck.z + q)[5], 0.0);

  q[2] = -1e-6, q[4] = 1e-6;  // a lateral slip: friction answers on row 2
  const Solution slip = lemke(solver, M, q);
  check(slip, 1e-12);
  EXPECT_GT(slip.z[2], 0.0);
}

TEST(Lemke, StopsAtThePivotLimit) {
  std::mt19937 rng(107);
  LcpSolver solver(20);
  const MatrixXd M = randomPMatrix(rng, 20, false);
  const VectorXd q = -VectorXd::Ones(20) - randomVector(rng, 20, 0.1).cwiseAbs();  // every z_i > 0: ≥ 21 pivots
  const Solution full = lemke(solver, M, q);
  ASSERT_EQ(full.result.status, LcpStatus::Solved);
  ASSERT_GT(full.result.iterations, 5);
  const Solution capped = lemke(solver, M, q, 5);
  EXPECT_EQ(capped.result.status, LcpStatus::IterationLimit);
  EXPECT_EQ(capped.result.iterations, 5);
  EXPECT_GT(capped.result.residual, 1e-3);
  // The acceptance check refuses the partial basis and names the row furthest outside it, with
  // its w_i = (M z + q)_i and the allowance there; a solution names none.
  EXPECT_EQ(full.result.rejected_row, -1);
  const int r = capped.result.rejected_row;
  ASSERT_GE(r, 0);
  ASSERT_LT(r, 20);
  const VectorXd w = M * capped.z + q;
  EXPECT_NEAR(capped.result.rejected_w, w[r], 1e-12 * (1 + std::abs(w[r])));
  EXPECT_GT(capped.result.rejected_allowance, 0.0);
  EXPECT_GT(capped.z[r] > 0 ? std::abs(w[r]) : -w[r], capped.result.rejected_allowance);
}

TEST(Lcp, SolvesAllocateNothing) {
  std::mt19937 rng(108);
  const ContactLcp contact = randomContactLcp(rng, 12, 4, 4);  // n = 24
  const MatrixXd P = randomPMatrix(rng, 30, false);
  const MatrixXd S = randomPMatrix(rng, 30, true);
  const VectorXd q = randomVector(rng, 30);
  const VectorXd q_small = randomVector(rng, 5);
  VectorXd z(30), w(30), z24(24), w24(24), z5(5), w5(5);
  LcpSolver solver(40);

  // The counter sees Eigen's allocations and operator new.
  long before = saltus::testing::heapAllocations();
  {
    VectorXd probe = VectorXd::Zero(16);
    asm volatile("" : : "g"(probe.data()) : "memory");  // keeps the allocation from being elided
  }
  if (saltus::testing::mallocCounted()) {
    EXPECT_GT(saltus::testing::heapAllocations() - before, 0);
  }
  before = saltus::testing::heapAllocations();
  int* probe = new int(1);
  asm volatile("" : : "g"(probe) : "memory");
  delete probe;
  EXPECT_GT(saltus::testing::heapAllocations() - before, 0);

  before = saltus::testing::heapAllocations();
  const LcpResult contact_result = solver.solveLemke(contact.M, contact.q, z24, w24);
  const LcpResult p_result = solver.solveLemke(P, q, z, w);
  const LcpResult small_result = solver.solveLemke(P.topLeftCorner(5, 5), q_small, z5, w5);
  const LcpResult warm_result = solver.solveLemkeWarm(contact.M, contact.q, z24, w24);  // from its solution
  z24.setOnes();
  const LcpResult cold_fallback = solver.solveLemkeWarm(contact.M, contact.q, z24, w24);  // a wrong guess
  z.setZero();
  const LcpResult pgs_result = solver.solvePgs(S, q, z, w, 500, 1e-10);
  z24.setZero();
  const LcpResult pgs_contact = solver.solvePgs(contact.M, contact.q, z24, w24, 50);
  const double residual = lcpResidual(P, q, z);
  const long allocations = saltus::testing::heapAllocations() - before;
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(contact_result.status, LcpStatus::Solved);
  EXPECT_EQ(p_result.status, LcpStatus::Solved);
  EXPECT_EQ(small_result.status, LcpStatus::Solved);
  EXPECT_EQ(warm_result.status, LcpStatus::Solved);
  EXPECT_EQ(cold_fallback.status, LcpStatus::Solved);
  EXPECT_EQ(pgs_result.status, LcpStatus::Solved);
  EXPECT_NE(pgs_contact.status, LcpStatus::NonFinite);
  EXPECT_TRUE(std::isfinite(residual));
}

TEST(Lcp, EdgeCases) {
  LcpSolver solver(3);
  EXPECT_EQ(solver.capacity(), 3);
  {  // size 0
    const MatrixXd M(0, 0);
    const VectorXd q(0);
    VectorXd z(0), w(0);
    const LcpResult lemke_result = solver.solveLemke(M, q, z, w);
    EXPECT_EQ(lemke_result.status, LcpStatus::Solved);
    EXPECT_EQ(lemke_result.iterations, 0);
    EXPECT_EQ(lemke_result.residual, 0.0);
    EXPECT_EQ(solver.solvePgs(M, q, z, w).status, LcpStatus::Solved);
    EXPECT_EQ(lcpResidual(M, q, z), 0.0);
    LcpSolver empty(0);
    EXPECT_EQ(empty.solveLemke(M, q, z, w).status, LcpStatus::Solved);
  }
  {  // size 1: z = 2 solves 2 z − 4 = 0
    const MatrixXd M = MatrixXd::Constant(1, 1, 2.0);
    const VectorXd q = VectorXd::Constant(1, -4.0);
    const Solution s = lemke(solver, M, q);
    EXPECT_EQ(s.result.status, LcpStatus::Solved);
    EXPECT_EQ(s.result.iterations, 2);  // z0 in, z_1 in with z0 out
    EXPECT_NEAR(s.z[0], 2.0, 1e-15);
    EXPECT_NEAR(s.w[0], 0.0, 1e-15);
    const Solution p = pgs(solver, M, q, 10, 1e-12);
    EXPECT_EQ(p.result.status, LcpStatus::Solved);
    EXPECT_EQ(p.result.iterations, 1);
    EXPECT_NEAR(p.z[0], 2.0, 1e-15);
  }
  {  // size 1, M = 0 (no PGS step possible) with q < 0: infeasible
    const MatrixXd M = MatrixXd::Zero(1, 1);
    const VectorXd q = VectorXd::Constant(1, -1.0);
    EXPECT_EQ(lemke(solver, M, q).result.status, LcpStatus::RayTermination);
    const Solution p = pgs(solver, M, q, 10, 1e-12);
    EXPECT_EQ(p.result.status, LcpStatus::NotConverged);
    EXPECT_EQ(p.result.residual, 2.0);  // |min(0, −1)| + 1
  }
  {  // q ≥ 0: z = 0, w = q, whatever M is
    std::mt19937 rng(109);
    const MatrixXd M = randomMatrix(rng, 3, 3);
    const VectorXd q = (VectorXd(3) << 0.5, 0.0, 2.0).finished();
    const Solution s = lemke(solver, M, q);
    EXPECT_EQ(s.result.status, LcpStatus::Solved);
    EXPECT_EQ(s.result.iterations, 0);
    EXPECT_TRUE(s.z.isZero(0));
    EXPECT_TRUE(s.w == q);
    const Solution p = pgs(solver, M, q, 10, 1e-12);
    EXPECT_EQ(p.result.status, LcpStatus::Solved);
    EXPECT_TRUE(p.z.isZero(0));
  }
}

TEST(Lcp, NonFiniteInputsAndBadSizes) {
  LcpSolver solver(3);
  MatrixXd M = MatrixXd::Identity(2, 2);
  VectorXd q = -VectorXd::Ones(2), z = VectorXd::Zero(2), w(2);
  q[1] = NAN;
  EXPECT_EQ(solver.solveLemke(M, q, z, w).status, LcpStatus::NonFinite);
  EXPECT_TRUE(std::isnan(z[0]));
  z.setZero();
  EXPECT_EQ(solver.solvePgs(M, q, z, w).status, LcpStatus::NonFinite);
  q[1] = -1;
  M(0, 1) = INFINITY;
  EXPECT_EQ(solver.solveLemke(M, q, z, w).status, LcpStatus::NonFinite);
  M(0, 1) = 0;
  z[0] = NAN;
  EXPECT_EQ(solver.solvePgs(M, q, z, w).status, LcpStatus::NonFinite);

  VectorXd z3(3), w3(3);
  EXPECT_THROW(solver.solveLemke(M, q, z3, w), std::invalid_argument);
  EXPECT_THROW(solver.solvePgs(M, q, z, w3), std::invalid_argument);
  VectorXd z4(4), w4(4);
  EXPECT_THROW(solver.solveLemke(MatrixXd::Identity(4, 4), -VectorXd::Ones(4), z4, w4), std::invalid_argument);
  EXPECT_THROW(solver.solvePgs(M, q, z, w, 10, 1e-10, 2.0), std::invalid_argument);
  EXPECT_STREQ(toString(LcpStatus::RayTermination), "ray termination");
}

}  // namespace
}  // namespace saltus::timestepper
