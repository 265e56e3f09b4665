// Linear complementarity problems of the time-stepper: given M (n x n) and q, find z with
//   z ≥ 0,   w = M z + q ≥ 0,   zᵀ w = 0
// (CPS = R. W. Cottle, J.-S. Pang, R. E. Stone, "The Linear Complementarity Problem",
// Academic Press 1992, §1.1).
//
// The velocity-level contact LCP of the Stewart–Trinkle / Anitescu–Potra time-stepper with
// polyhedral friction cones (D. E. Stewart, J. C. Trinkle, IJNME 39, 1996; M. Anitescu,
// F. A. Potra, Nonlinear Dynamics 14, 1997) has
//   M = [Jn A Jnᵀ  Jn A Dᵀ  0;  D A Jnᵀ  D A Dᵀ  E;  μ  −Eᵀ  0],   A = M_mass⁻¹,
// which is copositive-plus but neither symmetric nor a P-matrix, with a zero diagonal block for
// the friction-cone slack λ. Lemke's method processes that class: with a covering vector d > 0 it
// stops either at a solution or on a secondary ray, and for copositive-plus M a secondary ray
// proves that the LCP is infeasible (CPS §4.4). The lexicographic minimum-ratio rule
// (CPS §4.9) keeps every row of [B⁻¹q  B⁻¹] lexicographically positive, so no almost
// complementary basis repeats and degenerate problems cannot cycle.
//
// Siconos Numerics' lcp_lexicolemke mallocs its tableau on every call, which is why Saltus has
// its own solver (the time-stepper must not allocate per step). The tests use Siconos as the
// reference implementation.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace saltus::timestepper {

enum class LcpStatus {
  Solved,          // z, w satisfy the LCP (Lemke: to round-off, checked; PGS: residual <= tolerance)
  RayTermination,  // Lemke ended on a secondary ray, no solution found; for copositive-plus M the LCP is infeasible
  IterationLimit,  // Lemke used up max_pivots before z0 left the basis
  NotConverged,    // PGS stopped at max_iterations above tolerance; or z0 left Lemke's basis but the result
                   // failed the acceptance check (numerical breakdown)
  NonFinite,       // M, q (or PGS' warm start) hold NaN or infinity, or a pivot produced one
};
const char* toString(LcpStatus status);

struct LcpResult {
  LcpStatus status;
  int iterations;   // Lemke: pivots, the one that brings z0 in included; PGS: sweeps
  double residual;  // lcp residual of the returned z, w (see lcpResidual); +inf on NonFinite
  // A Lemke solution its acceptance check refused: the row furthest outside the check (relative
  // to what it allows there), its w_i, and the allowance, in q's units (−1: no row refused).
  int rejected_row = -1;
  double rejected_w = 0, rejected_allowance = 0;
};

// max_i |min(z_i, w_i)| + max(0, max_i −z_i, max_i −w_i) with w = M z + q. Zero exactly at a
// solution; on the scale of z and w otherwise. Does not allocate.
double lcpResidual(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                   const Eigen::Ref<const Eigen::VectorXd>& z);

// Dense LCP solvers over a workspace sized once for the largest problem. Solving a problem of
// size n <= capacity() performs no heap allocation. Size mismatches and n > capacity() are
// programming errors and throw std::invalid_argument.
class LcpSolver {
 public:
  explicit LcpSolver(int capacity);

  // Lemke's complementary pivoting (CPS §4.4) with the lexicographic minimum-ratio test
  // (CPS §4.9), on the problem equilibrated by diagonal row and column scaling (exact, powers
  // of two), with covering vector d = (1, …, 1) there. The basis inverse is kept explicitly and
  // updated by one elimination per pivot, O(n²); pivot candidates and ties are judged against
  // round-off scales, and the final basic solution gets one step of iterative refinement. The
  // result is then checked: Solved means w_i ≥ 0 and w_i = 0 where z_i > 0, each to 1e-9 of
  // |q_i| + (|M| z)_i (a solution of a slightly perturbed LCP) plus a round-off floor; a basis
  // that passes is Solved even when the pivoting ended on a ray or at max_pivots with z0 at
  // round-off level. Otherwise z is the last basic solution without z0 and w = M z + q.
  // max_pivots = 0 means 50 n + 100. q_scale (optional, size n): the magnitude of the terms each
  // q_i was summed from, Σ_j |J_ij| |v_j| for a contact velocity: a q_i computed as 1e-13 from
  // terms of 1 m/s is round-off, and the check then allows 1e-9 of that scale (without it, the
  // monopod's lateral friction row, q_i = −1.3e-13, failed a solved LCP).
  LcpResult solveLemke(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                       Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_pivots = 0,
                       const Eigen::VectorXd* q_scale = nullptr);

  // Lemke warm-started from a guess z (on entry, as for solvePgs): the complementary basis with
  // z_i basic where the guess is positive (index set P) and w_i basic elsewhere is tried first,
  // by solving M̂_PP ẑ_P = −q̂_P on the equilibrated problem (a principal pivot on P, CPS §4.1).
  // Its basic solution is returned (iterations = 0) when ẑ_P ≥ 0 and it passes the same
  // acceptance check as solveLemke's result; otherwise — M̂_PP singular, ẑ_P or w infeasible —
  // solveLemke runs from its usual start. The time-stepper passes the previous step's solution
  // when the active contacts are the same, and then usually no pivot is needed. Where the LCP has
  // several solutions (e.g. the split of a sticking impulse between opposite cone directions)
  // the one returned may differ from solveLemke's.
  LcpResult solveLemkeWarm(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                           Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_pivots = 0,
                           const Eigen::VectorXd* q_scale = nullptr);

  // Projected Gauss–Seidel / SOR (CPS chapter 5), warm-started from z (negative entries are
  // projected to 0): z_i ← max(0, z_i − ω w_i / d_i) row by row, w updated along.
  // Stops when the residual is <= tolerance (Solved) or after max_iterations sweeps
  // (NotConverged). Converges for symmetric positive definite M and 0 < ω < 2 (C. W. Cryer,
  // SIAM J. Control 9, 1971); for other M it may not.
  // Rows with M_ii <= 0 — the friction-cone slack λ of the contact LCP — cannot take a plain
  // Gauss–Seidel step. For them d_i is the diagonal after one block elimination of the rows
  // with positive diagonal, d_i = M_ii − Σ_{j: M_jj > 0} M_ij M_ji / M_jj: for a λ row that is
  // Σ_j 1 / (D A Dᵀ)_jj over the contact's friction directions, the rate at which w_λ grows when
  // λ grows and those directions' β answer by their own Gauss–Seidel steps. Rows where this is
  // still <= 0 are left at their warm-start value. On the friction LCP this is a heuristic
  // without a convergence guarantee: PGS usually converges there (most random contact LCPs in
  // the tests), and when it stalls above tolerance it says so (NotConverged). Lemke is the
  // exact solver for contact problems.
  LcpResult solvePgs(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                     Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_iterations = 200,
                     double tolerance = 1e-10, double relaxation = 1.0);

  int capacity() const { return capacity_; }

 private:
  void checkSizes(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<Eigen::VectorXd>& z, const Eigen::Ref<Eigen::VectorXd>& w) const;
  enum class Acceptance { Accepted, Rejected, NonFinite };
  // w = M z + q and the acceptance check of solveLemke's result; needs equilibrate(M).
  // q_scale: as solveLemke's (nullptr: |q_i|).
  Acceptance accept(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                    const Eigen::Ref<Eigen::VectorXd>& z, Eigen::Ref<Eigen::VectorXd> w,
                    const Eigen::VectorXd* q_scale);
  // Ruiz equilibration M̂ = D_r M D_c of M (see lcp.cpp) into scaled_matrix_, q̂ = D_r q.
  void equilibrate(const Eigen::Ref<const Eigen::MatrixXd>& M, int n);

  int capacity_;
  // accept()'s row furthest outside the check (−1: none), its w_i and allowance (LcpResult).
  int rejected_row_ = -1;
  double rejected_w_ = 0, rejected_allowance_ = 0;
  // Lemke: the equilibrated M̂ and q̂, the diagonals of D_r and D_c and one sweep's factors;
  // basis inverse B⁻¹ of the system I ŵ − M̂ ẑ − d z0 = q̂, values of the basic variables
  // x_B = B⁻¹ q̂ and the entering column B⁻¹ â_s with their round-off scales, the row norms
  // ‖B⁻¹_i‖∞, the pivot row, the ratios x_i / a_i, the label of each row's basic variable
  // (ŵ_j = j, ẑ_j = n + j, z0 = 2n) and the rows tied in the ratio test.
  Eigen::MatrixXd scaled_matrix_, basis_inverse_;
  Eigen::VectorXd scaled_q_, row_scaling_, column_scaling_, row_factor_, column_factor_, basic_value_,
      basic_value_magnitude_, entering_column_, entering_column_magnitude_, row_norm_, pivot_row_, ratio_;
  std::vector<int> basic_variable_, tied_rows_;
  // PGS: the diagonal d_i each row divides by.
  Eigen::VectorXd pgs_diagonal_;
};

}  // namespace saltus::timestepper
