// Lemke's method with the lexicographic ratio test, and projected Gauss–Seidel (see lcp.hpp).
#include "timestepper/lcp.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace saltus::timestepper {
namespace {

using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using ConstVectorRef = Eigen::Ref<const Eigen::VectorXd>;

// Lemke works on the equilibrated problem M̂ = D_r M D_c, q̂ = D_r q (z = D_c ẑ, w = D_r⁻¹ ŵ): Ruiz'
// scaling (D. Ruiz, "A scaling algorithm to equilibrate both rows and columns norms in
// matrices", RAL-TR-2001-034) brings the largest entry of every row and column of M̂ near 1,
// in powers of two so that M̂ is exact. Contact LCPs mix units (velocities, impulses, the
// cone's dimensionless E and μ) and inverse masses over orders of magnitude; equilibrated,
// one round-off scale fits all rows.
constexpr int kEquilibrationSweeps = 8;
// Round-off scales: a_i = Σ_k B⁻¹_ik â_sk of the entering column is known to about
// Σ_k |B⁻¹_ik| |â_sk| + ‖B⁻¹_i‖∞ ‖â_s‖∞ times the relative precision (the sum's magnitude, plus
// one entry of B⁻¹ that should be zero but holds elimination round-off), x_i to about
// Σ_k |B⁻¹_ik| |q̂_k| times it. a_i is a pivot candidate only above this fraction of its
// scale: below, it may be a zero that round-off made positive.
constexpr double kPivotTolerance = 1e-11;
// Ratios and lexicographic entries closer than this fraction of their error scales are ties.
constexpr double kTieTolerance = 1e-11;
// Lemke's result counts as Solved when each w_i is within this fraction of |q_i| + (|M| z)_i
// of satisfying the LCP, give or take the floor: this fraction of the largest such magnitude in
// equilibrated units (see the end of solveLemke). The floor sits above the pivot tolerance:
// pivoting treats entries within 1e-11 of their scale as zeros, so it cannot correct a w_i of
// that size (at 1e-12 the monopod's seed failed solved LCPs with a lateral friction row at
// w_i = −1.5e-11 against terms of 21 m/s).
constexpr double kLemkeAcceptance = 1e-9;
constexpr double kLemkeFloor = 1e-10;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// max_i |min(z_i, w_i)| + max(0, max_i −z_i, max_i −w_i).
double complementarityResidual(const ConstVectorRef& z, const ConstVectorRef& w) {
  double complementarity = 0, negativity = 0;
  for (Eigen::Index i = 0; i < z.size(); ++i) {
    complementarity = std::max(complementarity, std::abs(std::min(z[i], w[i])));
    negativity = std::max({negativity, -z[i], -w[i]});
  }
  return complementarity + negativity;
}

// w = M z + q by columns, skipping zero z_j.
void computeSlack(const ConstMatrixRef& M, const ConstVectorRef& q, const ConstVectorRef& z,
                  Eigen::Ref<Eigen::VectorXd> w) {
  w = q;
  for (Eigen::Index j = 0; j < z.size(); ++j)
    if (z[j] != 0) w += z[j] * M.col(j);
}

LcpResult nonFinite(Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int iterations) {
  z.setConstant(std::numeric_limits<double>::quiet_NaN());
  w.setConstant(std::numeric_limits<double>::quiet_NaN());
  return {LcpStatus::NonFinite, iterations, kInfinity};
}

}  // namespace

const char* toString(LcpStatus status) {
  switch (status) {
    case LcpStatus::Solved: return "solved";
    case LcpStatus::RayTermination: return "ray termination";
    case LcpStatus::IterationLimit: return "iteration limit";
    case LcpStatus::NotConverged: return "not converged";
    case LcpStatus::NonFinite: return "non-finite";
  }
  return "unknown";
}

double lcpResidual(const ConstMatrixRef& M, const ConstVectorRef& q, const ConstVectorRef& z) {
  const Eigen::Index n = q.size();
  if (M.rows() != n || M.cols() != n || z.size() != n)
    throw std::invalid_argument("lcpResidual: M must be n x n and z of size n = q.size()");
  double complementarity = 0, negativity = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w_i = q[i] + M.row(i).dot(z);
    complementarity = std::max(complementarity, std::abs(std::min(z[i], w_i)));
    negativity = std::max({negativity, -z[i], -w_i});
  }
  return complementarity + negativity;
}

LcpSolver::LcpSolver(int capacity) : capacity_(capacity) {
  if (capacity < 0) throw std::invalid_argument("LcpSolver: negative capacity");
  basis_inverse_.resize(capacity, capacity);
  scaled_matrix_.resize(capacity, capacity);
  for (Eigen::VectorXd* v : {&scaled_q_, &row_scaling_, &column_scaling_, &row_factor_, &column_factor_, &basic_value_,
                             &entering_column_, &entering_column_magnitude_, &basic_value_magnitude_,
                             &row_norm_, &pivot_row_, &ratio_, &pgs_diagonal_})
    v->resize(capacity);
  basic_variable_.resize(capacity);
  tied_rows_.resize(capacity);
}

void LcpSolver::checkSizes(const ConstMatrixRef& M, const ConstVectorRef& q, const Eigen::Ref<Eigen::VectorXd>& z,
                           const Eigen::Ref<Eigen::VectorXd>& w) const {
  const Eigen::Index n = q.size();
  if (M.rows() != n || M.cols() != n || z.size() != n || w.size() != n)
    throw std::invalid_argument("LcpSolver: M must be n x n and z, w of size n = q.size() = " + std::to_string(n));
  if (n > capacity_)
    throw std::invalid_argument("LcpSolver: problem size " + std::to_string(n) + " exceeds capacity " +
                                std::to_string(capacity_));
}

// The loops below run over plain arrays: Lemke's problems here have a handful of rows, where the
// set-up of one Eigen expression on a runtime-sized block costs as much as its arithmetic.
void LcpSolver::equilibrate(const ConstMatrixRef& M, int n) {
  auto M_hat = scaled_matrix_.topLeftCorner(n, n);
  double* const row_scaling = row_scaling_.data();
  double* const column_scaling = column_scaling_.data();
  double* const row_factor = row_factor_.data();
  double* const column_factor = column_factor_.data();
  M_hat = M;
  for (int i = 0; i < n; ++i) row_scaling[i] = column_scaling[i] = 1.0;
  // 1/√m rounded to a power of two, 2^−⌊e/2⌋ for m = 2^e · 1.x, read off the bits of normal
  // m; empty rows and columns (and subnormal maxima) keep factor 1.
  const auto factor = [](double m) {
    if (!(m >= std::numeric_limits<double>::min())) return 1.0;
    const int exponent = static_cast<int>((std::bit_cast<std::uint64_t>(m) >> 52) & 0x7ff) - 1023;
    return std::bit_cast<double>(static_cast<std::uint64_t>(1023 - exponent / 2) << 52);
  };
  for (int sweep = 0; sweep < kEquilibrationSweeps; ++sweep) {
    // Largest |entry| of every row and column, in one pass by columns.
    for (int i = 0; i < n; ++i) row_factor[i] = 0;
    for (int j = 0; j < n; ++j) {
      const double* const column = &M_hat.coeffRef(0, j);
      double column_max = 0;
      for (int i = 0; i < n; ++i) {
        const double entry = std::abs(column[i]);
        column_max = std::max(column_max, entry);
        row_factor[i] = std::max(row_factor[i], entry);
      }
      column_factor[j] = column_max;
    }
    bool unchanged = true;
    for (int i = 0; i < n; ++i) {
      row_factor[i] = factor(row_factor[i]);
      column_factor[i] = factor(column_factor[i]);
      unchanged = unchanged && row_factor[i] == 1.0 && column_factor[i] == 1.0;
    }
    if (unchanged) break;
    for (int j = 0; j < n; ++j) {
      double* const column = &M_hat.coeffRef(0, j);
      for (int i = 0; i < n; ++i) column[i] *= column_factor[j] * row_factor[i];
    }
    for (int i = 0; i < n; ++i) {
      row_scaling[i] *= row_factor[i];
      column_scaling[i] *= column_factor[i];
    }
  }
}

LcpResult LcpSolver::solveLemke(const ConstMatrixRef& M_original, const ConstVectorRef& q_original,
                                Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_pivots,
                                const Eigen::VectorXd* q_scale) {
  checkSizes(M_original, q_original, z, w);
  if (q_scale && q_scale->size() < q_original.size())
    throw std::invalid_argument("solveLemke: q_scale has fewer entries than q");
  const int n = static_cast<int>(q_original.size());
  if (max_pivots <= 0) max_pivots = 50 * n + 100;
  if (!M_original.allFinite() || !q_original.allFinite()) return nonFinite(z, w, 0);
  if (n == 0 || q_original.minCoeff() >= 0) {  // z = 0, w = q
    z.setZero();
    w = q_original;
    return {LcpStatus::Solved, 0, 0.0};
  }

  equilibrate(M_original, n);
  const auto M = scaled_matrix_.topLeftCorner(n, n);
  const double* const row_scaling = row_scaling_.data();
  const double* const column_scaling = column_scaling_.data();
  double* const q = scaled_q_.data();
  for (int i = 0; i < n; ++i) q[i] = row_scaling[i] * q_original[i];

  // Variables of I ŵ − M̂ ẑ − d z0 = q̂ (d = 1), labelled ŵ_j = j, ẑ_j = n + j, z0 = 2n. The
  // basis starts as ŵ: B = I, x_B = q̂. (Below, M and q are the equilibrated M̂ and q̂.)
  const int z0 = 2 * n;
  auto Binv = basis_inverse_.topLeftCorner(n, n);
  double* const x = basic_value_.data();
  double* const a = entering_column_.data();
  double* const row_norm = row_norm_.data();
  double* const a_magnitude = entering_column_magnitude_.data();
  double* const x_magnitude = basic_value_magnitude_.data();
  double* const pivot_row = pivot_row_.data();
  double* const ratio = ratio_.data();
  Binv.setIdentity();
  for (int i = 0; i < n; ++i) {
    x[i] = q[i];
    basic_variable_[i] = i;
  }

  // Pivot on row r of the entering column a: row r of B⁻¹ and x_B is divided by a_r and
  // eliminated from the others (one Gauss–Jordan step, a rank-one update of B⁻¹).
  const auto pivot = [&](int r) {
    const double inverse = 1.0 / a[r];
    for (int k = 0; k < n; ++k) pivot_row[k] = Binv(r, k) * inverse;
    for (int k = 0; k < n; ++k) {
      double* const b = &Binv.coeffRef(0, k);
      const double t = pivot_row[k];
      for (int i = 0; i < n; ++i) b[i] -= t * a[i];
      b[r] = t;
    }
    const double x_r = x[r] * inverse;
    for (int i = 0; i < n; ++i) x[i] -= x_r * a[i];
    x[r] = x_r;
  };

  // a = B⁻¹ â_s for the entering variable's column â_s (e_j for ŵ_j, −M̂ e_j for ẑ_j), the row
  // norms ‖B⁻¹_i‖∞ and the round-off scales of a and x_B, in one pass over B⁻¹ by columns.
  const auto enteringColumn = [&](int entering) {
    for (int i = 0; i < n; ++i) a[i] = row_norm[i] = a_magnitude[i] = x_magnitude[i] = 0;
    double column_max = 1.0;
    if (entering >= n) {
      column_max = 0;
      for (int k = 0; k < n; ++k) column_max = std::max(column_max, std::abs(M(k, entering - n)));
    }
    for (int k = 0; k < n; ++k) {
      const double c = entering < n ? (k == entering ? 1.0 : 0.0) : -M(k, entering - n);
      const double c_abs = std::abs(c), q_abs = std::abs(q[k]);
      const double* const b = &Binv.coeffRef(0, k);
      for (int i = 0; i < n; ++i) {
        const double b_abs = std::abs(b[i]);
        a[i] += c * b[i];
        row_norm[i] = std::max(row_norm[i], b_abs);
        a_magnitude[i] += c_abs * b_abs;
        x_magnitude[i] += q_abs * b_abs;
      }
    }
    for (int i = 0; i < n; ++i) a_magnitude[i] += column_max * row_norm[i];
  };

  // Is row c of [x_B  B⁻¹] / a lexicographically smaller than row b? x_B is already tied, so
  // the comparison starts at B⁻¹; entries within round-off of each other count as equal.
  const auto lexicographicallySmaller = [&](int c, int b) {
    const double tie = kTieTolerance * (row_norm[c] / a[c] + row_norm[b] / a[b]);
    for (int k = 0; k < n; ++k) {
      const double vc = Binv(c, k) / a[c], vb = Binv(b, k) / a[b];
      if (vc < vb - tie) return true;
      if (vc > vb + tie) return false;
    }
    return false;
  };

  // Lexicographic minimum-ratio test (CPS §4.9): among rows with a_i > 0, the smallest
  // x_i / a_i; ties go to z0 (which ends the method) or else to the lexicographically smallest
  // row of B⁻¹ / a_i. Returns −1 when no a_i is positive: a secondary ray.
  const auto ratioTest = [&]() {
    int best = 0;
    for (int i = 0; i < n; ++i) {
      ratio[i] = a[i] > kPivotTolerance * a_magnitude[i] ? std::max(x[i], 0.0) / a[i] : kInfinity;
      if (ratio[i] < ratio[best]) best = i;  // the first smallest
    }
    const double best_ratio = ratio[best];
    if (best_ratio == kInfinity) return -1;
    // Round-off scale of x_i / a_i: (δx_i + ratio δa_i) / a_i.
    const auto noise = [&](int i) { return (x_magnitude[i] + ratio[i] * a_magnitude[i]) / a[i]; };
    const double best_noise = noise(best);
    int tied = 0;
    for (int i = 0; i < n; ++i) {
      if (ratio[i] == kInfinity) continue;
      if (ratio[i] <= best_ratio + kTieTolerance * (noise(i) + best_noise)) {
        if (basic_variable_[i] == z0) return i;
        tied_rows_[tied++] = i;
      }
    }
    best = tied_rows_[0];
    for (int t = 1; t < tied; ++t)
      if (lexicographicallySmaller(tied_rows_[t], best)) best = tied_rows_[t];
    return best;
  };

  // z0 enters with column −d = −1 at the level that makes x_B ≥ 0: the row of the most
  // negative q̂_i leaves. Among ties the lexicographic minimum of (q̂_i, e_iᵀ) is the largest i.
  double q_min = q[0];
  for (int i = 1; i < n; ++i) q_min = std::min(q_min, q[i]);
  int r = 0;
  for (int i = 0; i < n; ++i)
    if (q[i] <= q_min + kTieTolerance * std::abs(q_min)) r = i;
  for (int i = 0; i < n; ++i) a[i] = -1.0;
  pivot(r);
  int leaving = basic_variable_[r];
  basic_variable_[r] = z0;
  int pivots = 1;

  LcpStatus status;
  for (;;) {
    if (leaving == z0) {
      status = LcpStatus::Solved;
      break;
    }
    if (pivots >= max_pivots) {
      status = LcpStatus::IterationLimit;
      break;
    }
    // Complementary pivot rule: the complement of the variable that just left enters.
    const int entering = leaving < n ? leaving + n : leaving - n;
    enteringColumn(entering);
    r = ratioTest();
    if (r < 0) {
      status = LcpStatus::RayTermination;
      break;
    }
    pivot(r);
    if (!std::isfinite(x[r])) return nonFinite(z, w, pivots);
    leaving = basic_variable_[r];
    basic_variable_[r] = entering;
    ++pivots;
  }

  // One step of iterative refinement of B x_B = q̂: the residual q̂ − B x_B, with columns e_j
  // for ŵ_j, −M̂ e_j for ẑ_j and −1 for z0, corrected through B⁻¹.
  double* const residual = pivot_row;
  for (int i = 0; i < n; ++i) residual[i] = q[i];
  for (int i = 0; i < n; ++i) {
    const int v = basic_variable_[i];
    if (v < n) {
      residual[v] -= x[i];
    } else if (v < z0) {
      const double* const column = &M.coeffRef(0, v - n);
      for (int k = 0; k < n; ++k) residual[k] += x[i] * column[k];
    } else {
      for (int k = 0; k < n; ++k) residual[k] += x[i];
    }
  }
  for (int k = 0; k < n; ++k) {
    const double* const column = &Binv.coeffRef(0, k);
    for (int i = 0; i < n; ++i) x[i] += residual[k] * column[i];
  }

  // z = D_c ẑ (exact: powers of two; round-off below zero cut off).
  for (int i = 0; i < n; ++i) z[i] = 0;
  for (int i = 0; i < n; ++i) {
    const int v = basic_variable_[i];
    if (v >= n && v < z0) z[v - n] = std::max(0.0, column_scaling[v - n] * x[i]);
  }
  const Acceptance acceptance = accept(M_original, q_original, z, w, q_scale);
  if (acceptance == Acceptance::NonFinite) return nonFinite(z, w, pivots);
  if (acceptance == Acceptance::Accepted) status = LcpStatus::Solved;
  else if (status == LcpStatus::Solved) status = LcpStatus::NotConverged;
  LcpResult result{status, pivots, complementarityResidual(z, w)};
  if (acceptance == Acceptance::Rejected)
    result.rejected_row = rejected_row_, result.rejected_w = rejected_w_, result.rejected_allowance = rejected_allowance_;
  return result;
}

// w = M z + q from the original data, and whether z, w pass the check (lcp.hpp, solveLemke).
// Needs row_scaling_ of the equilibration of M.
LcpSolver::Acceptance LcpSolver::accept(const ConstMatrixRef& M_original, const ConstVectorRef& q_original,
                                        const Eigen::Ref<Eigen::VectorXd>& z, Eigen::Ref<Eigen::VectorXd> w,
                                        const Eigen::VectorXd* q_scale) {
  const int n = static_cast<int>(q_original.size());
  const double* const row_scaling = row_scaling_.data();
  // The magnitude |q| + |M| z of the terms summed into each w_i.
  double* const w_magnitude = row_norm_.data();
  for (int i = 0; i < n; ++i) {
    w[i] = q_original[i];
    w_magnitude[i] = std::abs(q_original[i]) + (q_scale ? std::abs((*q_scale)[i]) : 0.0);
  }
  for (int j = 0; j < n; ++j) {
    if (z[j] == 0) continue;
    const double* const column = &M_original.coeffRef(0, j);
    for (int i = 0; i < n; ++i) {
      w[i] += z[j] * column[i];
      w_magnitude[i] += z[j] * std::abs(column[i]);
    }
  }
  bool finite = true;
  for (int i = 0; i < n; ++i) finite = finite && std::isfinite(z[i]) && std::isfinite(w[i]);
  if (!finite) return Acceptance::NonFinite;
  // Acceptance: w_i ≥ 0, and w_i = 0 where z_i > 0, each to a fraction of the magnitude
  // |q_i| + (|M| z)_i of its terms (then z solves the LCP of a slightly perturbed M and q), plus
  // a floor at round-off of the largest such magnitude, compared in equilibrated units
  // (ŵ = D_r w). A basis left by z0 that fails this is numerical breakdown; a ray or the pivot
  // limit reached with z0 at round-off level still leaves a solution, and a verified solution
  // is what counts.
  double largest_magnitude = 0;
  for (int i = 0; i < n; ++i) largest_magnitude = std::max(largest_magnitude, row_scaling[i] * w_magnitude[i]);
  const double noise_floor = kLemkeFloor * largest_magnitude;
  bool accepted = true;
  double worst = 1;  // excess over the allowance of the row furthest outside
  rejected_row_ = -1;
  for (int i = 0; i < n; ++i) {
    const double w_hat = row_scaling[i] * w[i];
    const double tolerance = kLemkeAcceptance * row_scaling[i] * w_magnitude[i] + noise_floor;
    const double outside = z[i] > 0 ? std::abs(w_hat) : -w_hat;  // w_i < 0, or w_i ≠ 0 where z_i > 0
    if (outside > tolerance) {
      accepted = false;
      if (outside > worst * tolerance) {
        worst = outside / tolerance;
        rejected_row_ = i, rejected_w_ = w[i], rejected_allowance_ = tolerance / row_scaling[i];
      }
    }
  }
  return accepted ? Acceptance::Accepted : Acceptance::Rejected;
}

LcpResult LcpSolver::solveLemkeWarm(const ConstMatrixRef& M_original, const ConstVectorRef& q_original,
                                    Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_pivots,
                                    const Eigen::VectorXd* q_scale) {
  checkSizes(M_original, q_original, z, w);
  if (q_scale && q_scale->size() < q_original.size())
    throw std::invalid_argument("solveLemkeWarm: q_scale has fewer entries than q");
  const int n = static_cast<int>(q_original.size());
  if (!M_original.allFinite() || !q_original.allFinite()) return nonFinite(z, w, 0);
  // The guessed index set P = {i : z_i > 0}; none (or the trivial solution z = 0): cold start.
  int p = 0;
  for (int i = 0; i < n; ++i)
    if (z[i] > 0) tied_rows_[p++] = i;
  if (p == 0 || q_original.minCoeff() >= 0) return solveLemke(M_original, q_original, z, w, max_pivots, q_scale);

  // M̂_PP ẑ_P = −q̂_P on the equilibrated problem, by Gaussian elimination with partial pivoting
  // (Golub & Van Loan, Alg. 3.4.1) in the workspace of B⁻¹; a pivot below round-off of its
  // column means M̂_PP is (numerically) singular: cold start.
  equilibrate(M_original, n);
  const auto M = scaled_matrix_.topLeftCorner(n, n);
  const int* const set = tied_rows_.data();
  auto G = basis_inverse_.topLeftCorner(p, p);
  double* const x = basic_value_.data();
  for (int j = 0; j < p; ++j) {
    for (int i = 0; i < p; ++i) G(i, j) = M(set[i], set[j]);
    x[j] = -row_scaling_[set[j]] * q_original[set[j]];
  }
  bool singular = false;
  for (int k = 0; k < p && !singular; ++k) {
    int r = k;
    double column_max = 0;
    for (int i = k; i < p; ++i) {
      column_max = std::max(column_max, std::abs(G(i, k)));
      if (std::abs(G(i, k)) > std::abs(G(r, k))) r = i;
    }
    for (int i = 0; i < k; ++i) column_max = std::max(column_max, std::abs(G(i, k)));
    if (!(std::abs(G(r, k)) > kPivotTolerance * column_max)) {
      singular = true;
      break;
    }
    if (r != k) {
      for (int j = k; j < p; ++j) std::swap(G(k, j), G(r, j));
      std::swap(x[k], x[r]);
    }
    for (int i = k + 1; i < p; ++i) {
      const double l = G(i, k) / G(k, k);
      for (int j = k + 1; j < p; ++j) G(i, j) -= l * G(k, j);
      x[i] -= l * x[k];
    }
  }
  if (!singular) {
    for (int i = p - 1; i >= 0; --i) {  // back substitution
      double s = x[i];
      for (int j = i + 1; j < p; ++j) s -= G(i, j) * x[j];
      x[i] = s / G(i, i);
    }
    // z = D_c ẑ, round-off below zero cut off; the same acceptance check as Lemke's result.
    bool nonnegative = true;
    for (int i = 0; i < n; ++i) z[i] = 0;
    for (int j = 0; j < p; ++j) {
      nonnegative = nonnegative && x[j] >= 0;
      z[set[j]] = std::max(0.0, column_scaling_[set[j]] * x[j]);
    }
    if (nonnegative && accept(M_original, q_original, z, w, q_scale) == Acceptance::Accepted)
      return {LcpStatus::Solved, 0, complementarityResidual(z, w)};
  }
  return solveLemke(M_original, q_original, z, w, max_pivots, q_scale);
}

LcpResult LcpSolver::solvePgs(const ConstMatrixRef& M, const ConstVectorRef& q, Eigen::Ref<Eigen::VectorXd> z,
                              Eigen::Ref<Eigen::VectorXd> w, int max_iterations, double tolerance,
                              double relaxation) {
  checkSizes(M, q, z, w);
  if (!(relaxation > 0 && relaxation < 2)) throw std::invalid_argument("solvePgs: relaxation must be in (0, 2)");
  const int n = static_cast<int>(q.size());
  if (!M.allFinite() || !q.allFinite() || !z.allFinite()) return nonFinite(z, w, 0);

  // The diagonal each row divides by; for M_ii <= 0 the diagonal after eliminating the rows
  // with positive diagonal (see lcp.hpp), 0 where that is not positive either: row frozen.
  auto d = pgs_diagonal_.head(n);
  for (int i = 0; i < n; ++i) {
    double d_i = M(i, i);
    if (!(d_i > 0)) {
      for (int j = 0; j < n; ++j)
        if (j != i && M(j, j) > 0) d_i -= M(i, j) * M(j, i) / M(j, j);
    }
    d[i] = d_i > 0 ? d_i : 0.0;
  }

  z = z.cwiseMax(0.0);
  computeSlack(M, q, z, w);
  double residual = complementarityResidual(z, w);
  int sweeps = 0;
  while (residual > tolerance && sweeps < max_iterations) {
    ++sweeps;
    // One Gauss–Seidel sweep; w follows each change of z_i along column i of M.
    for (int i = 0; i < n; ++i) {
      if (d[i] == 0) continue;
      const double z_i = std::max(0.0, z[i] - relaxation * w[i] / d[i]);
      const double change = z_i - z[i];
      if (change != 0) {
        z[i] = z_i;
        w += change * M.col(i);
      }
    }
    residual = complementarityResidual(z, w);
    if (residual <= tolerance) {  // confirm against w recomputed from scratch
      computeSlack(M, q, z, w);
      residual = complementarityResidual(z, w);
    }
  }
  computeSlack(M, q, z, w);
  residual = complementarityResidual(z, w);
  if (!std::isfinite(residual)) return nonFinite(z, w, sweeps);
  return {residual <= tolerance ? LcpStatus::Solved : LcpStatus::NotConverged, sweeps, residual};
}

}  // namespace saltus::timestepper
