// Test and benchmark support for the LCP solvers (timestepper/lcp.hpp): random matrices, random
// velocity-level contact LCPs of the Stewart–Trinkle time-stepper, and Siconos Numerics'
// solvers (Debian libsiconos-numerics-dev) as the independent reference. A fixed-seed generator
// makes every problem reproducible.
#pragma once

#include <LCP_Solvers.h>
#include <LinearComplementarityProblem.h>
#include <NumericsMatrix.h>
#include <SolverOptions.h>
#include <lcp_cst.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>

namespace saltus::testing {

using Eigen::MatrixXd;
using Eigen::VectorXd;

inline MatrixXd randomMatrix(std::mt19937& rng, int rows, int cols, double scale = 1.0) {
  std::normal_distribution<double> g(0.0, scale);
  MatrixXd A(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) A(i, j) = g(rng);
  return A;
}

inline VectorXd randomVector(std::mt19937& rng, int n, double scale = 1.0) { return randomMatrix(rng, n, 1, scale); }

// The velocity-level contact LCP of the Stewart–Trinkle / Anitescu–Potra time-stepper, unknowns
// (c_n, β, λ) for m contacts with k friction directions each:
//   M = [Jn A Jnᵀ  Jn A Dᵀ  0;  D A Jnᵀ  D A Dᵀ  E;  μ  −Eᵀ  0],   q = (Jn v; D v; 0),
// A = M_mass⁻¹ (SPD), E block diagonal with a column of k ones per contact, μ diagonal. The k
// directions of a contact are cos(2πj/k) t1 + sin(2πj/k) t2: they positively span its tangent
// plane (a line for k = 2).
struct ContactLcp {
  MatrixXd M;
  VectorXd q;
};

inline ContactLcp randomContactLcp(std::mt19937& rng, int nv, int m, int k) {
  const double pi = std::acos(-1.0);
  std::uniform_real_distribution<double> friction(0.1, 1.0);
  const MatrixXd R = randomMatrix(rng, nv, nv, 1.0 / std::sqrt(nv));
  const MatrixXd A = R * R.transpose() + 0.1 * MatrixXd::Identity(nv, nv);
  const MatrixXd Jn = randomMatrix(rng, m, nv);
  MatrixXd D(m * k, nv), E = MatrixXd::Zero(m * k, m), mu = MatrixXd::Zero(m, m);
  for (int c = 0; c < m; ++c) {
    const VectorXd t1 = randomVector(rng, nv), t2 = randomVector(rng, nv);
    for (int j = 0; j < k; ++j) {
      D.row(c * k + j) = std::cos(2 * pi * j / k) * t1.transpose() + std::sin(2 * pi * j / k) * t2.transpose();
      E(c * k + j, c) = 1;
    }
    mu(c, c) = friction(rng);
  }
  const int n = m * (k + 2);
  ContactLcp lcp{MatrixXd::Zero(n, n), VectorXd::Zero(n)};
  lcp.M.block(0, 0, m, m) = Jn * A * Jn.transpose();
  lcp.M.block(0, m, m, m * k) = Jn * A * D.transpose();
  lcp.M.block(m, 0, m * k, m) = D * A * Jn.transpose();
  lcp.M.block(m, m, m * k, m * k) = D * A * D.transpose();
  lcp.M.block(m, m + m * k, m * k, m) = E;
  lcp.M.block(m + m * k, 0, m, m) = mu;
  lcp.M.block(m + m * k, m, m, m * k) = -E.transpose();
  const VectorXd v = randomVector(rng, nv);
  lcp.q.head(m) = Jn * v;
  lcp.q.segment(m, m * k) = D * v;
  return lcp;
}

// Siconos Numerics' solver `solver_id` on LCP(q, M): its info (0: solved) and z, w.
struct SiconosSolution {
  int info;
  VectorXd z, w;
};

inline SiconosSolution siconosSolve(int solver_id, const MatrixXd& M, const VectorXd& q, int max_iterations = 100000,
                             double tolerance = 1e-12) {
  const int n = static_cast<int>(q.size());
  NumericsMatrix* matrix = NM_create(NM_DENSE, n, n);
  std::copy(M.data(), M.data() + n * n, matrix->matrix0);  // both column-major
  VectorXd q_copy = q;
  LinearComplementarityProblem problem{n, matrix, q_copy.data()};
  SolverOptions* options = solver_options_create(solver_id);
  options->iparam[SICONOS_IPARAM_MAX_ITER] = max_iterations;
  options->dparam[SICONOS_DPARAM_TOL] = tolerance;
  SiconosSolution s{-1, VectorXd::Zero(n), VectorXd::Zero(n)};
  if (solver_id == SICONOS_LCP_LEMKE) lcp_lexicolemke(&problem, s.z.data(), s.w.data(), &s.info, options);
  else if (solver_id == SICONOS_LCP_PGS) lcp_pgs(&problem, s.z.data(), s.w.data(), &s.info, options);
  solver_options_delete(options);
  std::free(options);  // solver_options_delete frees the members only
  NM_free(matrix);
  return s;
}

}  // namespace saltus::testing
