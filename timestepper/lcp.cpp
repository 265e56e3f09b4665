// Lemke's method with the lexicographic ratio test, and projected Gauss–Seidel (see lcp.hpp).
#include "timestepper/lcp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace saltus::timestepper {
namespace {

using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using ConstVectorRef = Eigen::Ref<const Eigen::VectorXd>;

// An entry a_i of the entering column B⁻¹ a_s is a pivot candidate only when it exceeds this
// fraction of Σ_k |B⁻¹_ik a_sk|, the magnitude it was summed from: below that it is round-off.
constexpr double kPivotTolerance = 1e-11;
// Ratios (and lexicographic entries) closer than this fraction of their round-off scale are ties.
constexpr double kTieTolerance = 1e-11;
// Lemke's final basis counts as Solved when its residual is at most this fraction of the scale
// 1 + ‖q‖∞ + max|M_ij| ‖z‖₁ of the terms in w = M z + q.
constexpr double kLemkeAcceptance = 1e-9;

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
  for (Eigen::VectorXd* v : {&basic_value_, &entering_column_, &column_scale_, &value_scale_, &pivot_row_, &ratio_, &pgs_diagonal_})
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

LcpResult LcpSolver::solveLemke(const ConstMatrixRef& M, const ConstVectorRef& q, Eigen::Ref<Eigen::VectorXd> z,
                                Eigen::Ref<Eigen::VectorXd> w, int max_pivots) {
  checkSizes(M, q, z, w);
  const int n = static_cast<int>(q.size());
  if (max_pivots <= 0) max_pivots = 50 * n + 100;
  if (!M.allFinite() || !q.allFinite()) return nonFinite(z, w, 0);
  if (n == 0 || q.minCoeff() >= 0) {  // z = 0, w = q
    z.setZero();
    w = q;
    return {LcpStatus::Solved, 0, 0.0};
  }

  // Variables of I w − M z − d z0 = q, labelled w_j = j, z_j = n + j, z0 = 2n. The basis
  // starts as w: B = I, x_B = q.
  const int z0 = 2 * n;
  auto Binv = basis_inverse_.topLeftCorner(n, n);
  auto x = basic_value_.head(n);
  auto a = entering_column_.head(n);
  auto column_scale = column_scale_.head(n);
  auto value_scale = value_scale_.head(n);
  auto pivot_row = pivot_row_.head(n);
  auto ratio = ratio_.head(n);
  Binv.setIdentity();
  x = q;
  for (int i = 0; i < n; ++i) basic_variable_[i] = i;

  // Pivot on row r of the entering column a: row r of B⁻¹ and x_B is divided by a_r and
  // eliminated from the others (one Gauss–Jordan step, a rank-one update of B⁻¹).
  const auto pivot = [&](int r) {
    const double inverse = 1.0 / a[r];
    for (int k = 0; k < n; ++k) pivot_row[k] = Binv(r, k) * inverse;
    const double* const a_data = a.data();
    for (int k = 0; k < n; ++k) {
      double* const b = &Binv.coeffRef(0, k);
      const double t = pivot_row[k];
      for (int i = 0; i < n; ++i) b[i] -= t * a_data[i];
      b[r] = t;
    }
    const double x_r = x[r] * inverse;
    x -= x_r * a;
    x[r] = x_r;
  };

  // a = B⁻¹ (column of the entering variable), with the round-off scales of a and x_B: one
  // fused pass over B⁻¹ by columns.
  const auto enteringColumn = [&](int entering) {
    a.setZero();
    column_scale.setZero();
    value_scale.setZero();
    double* const a_data = a.data();
    double* const column_scale_data = column_scale.data();
    double* const value_scale_data = value_scale.data();
    for (int k = 0; k < n; ++k) {
      const double c = entering < n ? (k == entering ? 1.0 : 0.0) : -M(k, entering - n);
      const double c_abs = std::abs(c), q_abs = std::abs(q[k]);
      const double* const b = &Binv.coeffRef(0, k);
      for (int i = 0; i < n; ++i) {
        const double b_abs = std::abs(b[i]);
        a_data[i] += c * b[i];
        column_scale_data[i] += c_abs * b_abs;
        value_scale_data[i] += q_abs * b_abs;
      }
    }
  };

  // Is row c of [x_B  B⁻¹] / a lexicographically smaller than row b? x_B is already tied, so
  // the comparison starts at B⁻¹; entries within round-off of each other count as equal.
  const auto lexicographicallySmaller = [&](int c, int b) {
    const double scale = kTieTolerance * (Binv.row(c).cwiseAbs().maxCoeff() / a[c] +
                                          Binv.row(b).cwiseAbs().maxCoeff() / a[b]);
    for (int k = 0; k < n; ++k) {
      const double vc = Binv(c, k) / a[c], vb = Binv(b, k) / a[b];
      if (vc < vb - scale) return true;
      if (vc > vb + scale) return false;
    }
    return false;
  };

  // Lexicographic minimum-ratio test (CPS §4.9): among rows with a_i > 0, the smallest
  // x_i / a_i; ties go to z0 (which ends the method) or else to the lexicographically smallest
  // row of B⁻¹ / a_i. Returns −1 when no a_i is positive: a secondary ray.
  const auto ratioTest = [&]() {
    for (int i = 0; i < n; ++i)
      ratio[i] = a[i] > kPivotTolerance * column_scale[i] ? std::max(x[i], 0.0) / a[i] : kInfinity;
    int best;
    const double best_ratio = ratio.minCoeff(&best);
    if (best_ratio == kInfinity) return -1;
    const double best_noise = (value_scale[best] + best_ratio * column_scale[best]) / a[best];
    int tied = 0;
    for (int i = 0; i < n; ++i) {
      if (ratio[i] == kInfinity) continue;
      const double noise = (value_scale[i] + ratio[i] * column_scale[i]) / a[i];
      if (ratio[i] <= best_ratio + kTieTolerance * (noise + best_noise)) {
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
  // negative q_i leaves. Among ties the lexicographic minimum of (q_i, e_iᵀ) is the largest i.
  const double q_min = q.minCoeff();
  int r = 0;
  for (int i = 0; i < n; ++i)
    if (q[i] <= q_min + kTieTolerance * std::abs(q_min)) r = i;
  a.setConstant(-1.0);
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

  // One step of iterative refinement of B x_B = q against the original data: the residual
  // q − B x_B, with columns e_j for w_j, −M e_j for z_j and −1 for z0, corrected through B⁻¹.
  auto residual = pivot_row;
  residual = q;
  for (int i = 0; i < n; ++i) {
    const int v = basic_variable_[i];
    if (v < n) residual[v] -= x[i];
    else if (v < z0) residual += x[i] * M.col(v - n);
    else residual.array() += x[i];
  }
  for (int k = 0; k < n; ++k) x += residual[k] * Binv.col(k);

  z.setZero();
  for (int i = 0; i < n; ++i)
    if (basic_variable_[i] >= n && basic_variable_[i] < z0) z[basic_variable_[i] - n] = x[i];
  computeSlack(M, q, z, w);
  if (!z.allFinite() || !w.allFinite()) return nonFinite(z, w, pivots);
  const double residual_norm = complementarityResidual(z, w);
  if (status == LcpStatus::Solved) {
    const double scale = 1.0 + q.cwiseAbs().maxCoeff() + M.cwiseAbs().maxCoeff() * z.lpNorm<1>();
    if (residual_norm > kLemkeAcceptance * scale) status = LcpStatus::NotConverged;
  }
  return {status, pivots, residual_norm};
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
