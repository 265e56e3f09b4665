#include "collocation/nlp.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <utility>

namespace saltus::collocation {

namespace {
// Adds the time of a scope to a counter.
class Timer {
 public:
  explicit Timer(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~Timer() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};
}  // namespace

const char* toString(Stage s) {
  switch (s) {
    case Stage::Feasibility: return "feasibility";
    case Stage::Tighten: return "tighten";
    case Stage::Task: return "task";
    case Stage::Penalty: return "penalty";
  }
  return "?";
}

Nlp::Nlp(const Transcription& t, Stage stage, const Eigen::VectorXd& x0, Multipliers start, bool hinted)
    : t_(t), stage_(stage), x0_(x0), start_(std::move(start)) {
  const bool first_stage = stage == Stage::Feasibility || stage == Stage::Penalty;
  x_lower_ = first_stage && hinted ? t.hintedLower() : t.variableLower();
  x_upper_ = first_stage && hinted ? t.hintedUpper() : t.variableUpper();
  if (!first_stage) {
    // ε ≤ the tolerance, less a margin: Ipopt meets A·B − ε ≤ 0 only to its constraint
    // tolerance, and a solution is judged by A·B ≤ tolerance (solver.hpp).
    boundProducts(kPenaltyBoundFraction * t.problem().complementarity_tolerance);
  }
  const auto& blocks = t.blocks();
  // The task and penalty stages weigh each product in the cost with ε fixed (nlp.hpp): at its
  // bound, or at 0 with the product's row left out of the constraints.
  const bool left_out = stage == Stage::Penalty || (stage == Stage::Task && t.problem().task_penalty);
  if ((stage == Stage::Task || left_out) && !t.productBlocks().empty()) {
    const double weight = stage == Stage::Task ? t.problem().cost.penalty_weight : 1.0;
    product_weight_.assign(blocks.size(), 0.0);
    for (std::size_t i = 0; i < t.productBlocks().size(); ++i)
      product_weight_[t.productBlocks()[i]] = weight * t.penaltyWeights()[i];
    for (int e : t.penaltyVariables()) x_lower_[e] = x_upper_[e] = left_out ? 0.0 : x_upper_[e];
  }
  row_.resize(t.constraints());
  for (int i = 0; i < t.constraints(); ++i) row_[i] = i;
  if (left_out)
    for (int b : t.productBlocks()) row_[blocks[b].row] = -1;
  for (int& r : row_)
    if (r >= 0) r = rows_++;
  g_full_.resize(t.constraints());
  // Sparsity: dense local Jacobian blocks and the pairs of the local Hessians that may be non-zero
  // (LocalFunction::hessianPair) mapped to global entries; duplicates share an entry.
  std::map<std::pair<int, int>, int> jac, hess;
  std::size_t max_in = 1, max_out = 1;
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    const Block& b = blocks[bi];
    const int n = b.f->inputs(), m = b.f->outputs();
    max_in = std::max<std::size_t>(max_in, n);
    max_out = std::max<std::size_t>(max_out, m);
    jac_first_.push_back(static_cast<int>(jac_pos_.size()));
    if (!b.isCost() && !leftOut(b))
      for (int c = 0; c < n; ++c)
        for (int r = 0; r < m; ++r) {
          const auto key = std::make_pair(b.row + r, b.vars[c]);
          auto [it, added] = jac.try_emplace(key, static_cast<int>(jac.size()));
          if (added) jac_row_.push_back(key.first), jac_col_.push_back(key.second);
          jac_pos_.push_back(it->second);
        }
    hess_first_.push_back(b.f->linear() || (b.isCost() && weight(bi) == 0) ? -1 : static_cast<int>(hess_pos_.size()));
    if (hess_first_.back() < 0) continue;
    for (int j = 0; j < n; ++j)
      for (int i = j; i < n; ++i) {
        if (!b.f->hessianPair(i, j)) {  // structurally zero: not in Ipopt's structure
          hess_pos_.push_back(-1);
          continue;
        }
        const int a = b.vars[i], c = b.vars[j];
        const auto key = std::make_pair(std::max(a, c), std::min(a, c));
        auto [it, added] = hess.try_emplace(key, static_cast<int>(hess.size()));
        if (added) hess_row_.push_back(key.first), hess_col_.push_back(key.second);
        hess_pos_.push_back(it->second);
      }
  }
  local_x_.resize(max_in);
  local_y_.resize(max_out);
  local_d_.resize(max_in * std::max(max_in, max_out));
  local_l_.resize(max_out);
}

double Nlp::weight(std::size_t block) const {
  if (productInCost(block)) return product_weight_[block];
  const Block& b = t_.blocks()[block];
  if (!b.isCost()) return 0.0;
  if (b.cost_group == kPenaltyCost && !product_weight_.empty()) return 0.0;  // Σ w ε: the products instead
  if (b.cost_group == kPenaltyCost)
    return stage_ == Stage::Task ? t_.problem().cost.penalty_weight : 1.0;
  if (b.cost_group == kTaskCost) return stage_ == Stage::Task ? 1.0 : 0.0;
  return 0.0;
}

const double* Nlp::gather(const Block& b, const Ipopt::Number* x) {
  for (std::size_t i = 0; i < b.vars.size(); ++i) local_x_[i] = x[b.vars[i]];
  return local_x_.data();
}

bool Nlp::get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                       IndexStyleEnum& index_style) {
  n = t_.variables();
  m = rows_;
  nnz_jac_g = static_cast<Ipopt::Index>(jac_row_.size());
  nnz_h_lag = static_cast<Ipopt::Index>(hess_row_.size());
  index_style = C_STYLE;
  return true;
}

bool Nlp::get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m,
                          Ipopt::Number* g_l, Ipopt::Number* g_u) {
  // Ipopt reads ±1e19 (nlp_lower/upper_bound_inf) as infinite.
  auto finite = [](double v) { return std::max(-1e19, std::min(1e19, v)); };
  for (int i = 0; i < n; ++i) x_l[i] = finite(x_lower_[i]), x_u[i] = finite(x_upper_[i]);
  for (int i = 0; i < t_.constraints(); ++i)
    if (row_[i] >= 0) g_l[row_[i]] = finite(t_.constraintLower()[i]), g_u[row_[i]] = finite(t_.constraintUpper()[i]);
  return true;
}

bool Nlp::get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number* z_L,
                             Ipopt::Number* z_U, Ipopt::Index m, bool init_lambda, Ipopt::Number* lambda) {
  if ((init_z || init_lambda) && start_.empty()) return false;
  if (init_x)
    for (int i = 0; i < n; ++i) x[i] = x0_[i];
  if (init_z)
    for (int i = 0; i < n; ++i) z_L[i] = start_.z_lower[i], z_U[i] = start_.z_upper[i];
  if (init_lambda)
    for (int i = 0; i < t_.constraints(); ++i)
      if (row_[i] >= 0) lambda[row_[i]] = start_.lambda[i];
  return true;
}

double Nlp::objectiveAt(const Ipopt::Number* x) {
  double f = 0;
  const auto& blocks = t_.blocks();
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    const Block& b = blocks[bi];
    const double w = weight(bi);
    if (w == 0) continue;
    if (productInCost(bi))
      local_y_[0] = static_cast<const ComplementarityProduct&>(*b.f).product(gather(b, x));
    else
      b.f->value(gather(b, x), local_y_.data());
    f += w * local_y_[0];
  }
  return f;
}

bool Nlp::eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& obj_value) {
  Timer timer(eval_seconds_);
  obj_value = objectiveAt(x);
  return true;
}

bool Nlp::eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* grad_f) {
  Timer timer(eval_seconds_);
  for (int i = 0; i < n; ++i) grad_f[i] = 0;
  const auto& blocks = t_.blocks();
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    const Block& b = blocks[bi];
    const double w = weight(bi);
    if (w == 0) continue;
    b.f->jacobian(gather(b, x), local_d_.data());
    // A product in the cost is A·B: its last input, ε, is not in it.
    const std::size_t count = productInCost(bi) ? b.vars.size() - 1 : b.vars.size();
    for (std::size_t c = 0; c < count; ++c) grad_f[b.vars[c]] += w * local_d_[c];
  }
  return true;
}

bool Nlp::eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* g) {
  Timer timer(eval_seconds_);
  // Every row into g when none is left out; else into g_full_ and the kept rows copied.
  const bool all_rows = rows_ == t_.constraints();
  double* g_all = all_rows ? g : g_full_.data();
  for (const Block& b : t_.blocks()) {
    if (b.isCost()) continue;
    b.f->value(gather(b, x), g_all + b.row);
  }
  if (!all_rows)
    for (int i = 0; i < t_.constraints(); ++i)
      if (row_[i] >= 0) g[row_[i]] = g_full_[i];
  if (best_violation_tolerance_ >= 0) considerFeasible(x, g_all);
  return true;
}

void Nlp::considerFeasible(const Ipopt::Number* x, const Ipopt::Number* g) {
  const Eigen::Map<const Eigen::VectorXd> gv(g, t_.constraints());
  // Written so that NaN fails every comparison.
  for (int i = 0; i < gv.size(); ++i)
    if (!(gv[i] >= t_.constraintLower()[i] - best_violation_tolerance_ &&
          gv[i] <= t_.constraintUpper()[i] + best_violation_tolerance_))
      return;
  const double f = objectiveAt(x);
  if (!std::isfinite(f) || (hasBestFeasible() && f >= best_objective_)) return;
  const Eigen::Map<const Eigen::VectorXd> xv(x, t_.variables());
  if (!xv.allFinite() || !(t_.largestProduct(xv) <= best_product_tolerance_)) return;
  best_x_ = xv;
  if (!product_weight_.empty()) t_.setPenaltyToProducts(best_x_);
  best_objective_ = f;
  best_iteration_ = iteration_ + 1;
}

bool Nlp::eval_jac_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index nele_jac,
                     Ipopt::Index* iRow, Ipopt::Index* jCol, Ipopt::Number* values) {
  Timer timer(eval_seconds_);
  if (values == nullptr) {
    for (int k = 0; k < nele_jac; ++k) iRow[k] = row_[jac_row_[k]], jCol[k] = jac_col_[k];
    return true;
  }
  for (int k = 0; k < nele_jac; ++k) values[k] = 0;
  const auto& blocks = t_.blocks();
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    const Block& b = blocks[bi];
    if (b.isCost() || leftOut(b)) continue;
    b.f->jacobian(gather(b, x), local_d_.data());
    const int count = b.f->inputs() * b.f->outputs();
    const int* pos = jac_pos_.data() + jac_first_[bi];
    for (int k = 0; k < count; ++k) values[pos[k]] += local_d_[k];
  }
  // A value that is not finite is an evaluation error for Ipopt (it cuts the step back), not a
  // matrix for MUMPS: Ipopt does not check derivatives (check_derivatives_for_naninf), and MUMPS's
  // analysis of such a matrix fails (and leaks).
  return std::all_of(values, values + nele_jac, [](double v) { return std::isfinite(v); });
}

bool Nlp::eval_h(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number obj_factor, Ipopt::Index,
                 const Ipopt::Number* lambda, bool, Ipopt::Index nele_hess, Ipopt::Index* iRow, Ipopt::Index* jCol,
                 Ipopt::Number* values) {
  Timer timer(eval_seconds_);
  if (values == nullptr) {
    for (int k = 0; k < nele_hess; ++k) iRow[k] = hess_row_[k], jCol[k] = hess_col_[k];
    return true;
  }
  ++hessian_evaluations_;
  for (int k = 0; k < nele_hess; ++k) values[k] = 0;
  const auto& blocks = t_.blocks();
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    if (hess_first_[bi] < 0) continue;
    const Block& b = blocks[bi];
    const int n = b.f->inputs(), m = b.f->outputs();
    bool any = false;
    for (int r = 0; r < m; ++r) {
      local_l_[r] = (b.isCost() || leftOut(b) ? 0.0 : lambda[row_[b.row + r]]) + obj_factor * weight(bi);
      any = any || local_l_[r] != 0;
    }
    if (!any) continue;
    std::fill(local_d_.begin(), local_d_.begin() + n * n, 0.0);
    b.f->hessian(gather(b, x), local_l_.data(), local_d_.data());
    const int* pos = hess_pos_.data() + hess_first_[bi];
    int k = 0;
    for (int j = 0; j < n; ++j)
      for (int i = j; i < n; ++i, ++k)
        if (pos[k] >= 0) values[pos[k]] += local_d_[i + j * n];
  }
  return std::all_of(values, values + nele_hess, [](double v) { return std::isfinite(v); });  // as eval_jac_g
}

void Nlp::finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x,
                            const Ipopt::Number* z_L, const Ipopt::Number* z_U, Ipopt::Index m, const Ipopt::Number*,
                            const Ipopt::Number* lambda, Ipopt::Number obj_value, const Ipopt::IpoptData*,
                            Ipopt::IpoptCalculatedQuantities*) {
  status_ = status;
  objective_ = obj_value;
  x_ = Eigen::Map<const Eigen::VectorXd>(x, n);
  multipliers_.z_lower = Eigen::Map<const Eigen::VectorXd>(z_L, n);
  multipliers_.z_upper = Eigen::Map<const Eigen::VectorXd>(z_U, n);
  multipliers_.lambda = Eigen::VectorXd::Zero(t_.constraints());  // the transcription's rows
  for (int i = 0; i < t_.constraints(); ++i)
    if (row_[i] >= 0 && row_[i] < m) multipliers_.lambda[i] = lambda[row_[i]];
  // ε fixed (the task and penalty stages): saved points carry each product in its ε.
  if (!product_weight_.empty()) t_.setPenaltyToProducts(x_);
}

double Nlp::cost(const Eigen::VectorXd& x) {
  double f;
  eval_f(static_cast<int>(x.size()), x.data(), true, f);
  return f;
}

Eigen::VectorXd Nlp::constraints(const Eigen::VectorXd& x) {  // every row, those left out too
  Eigen::VectorXd g(rows_);
  eval_g(static_cast<int>(x.size()), x.data(), true, rows_, g.data());
  return rows_ == t_.constraints() ? g : g_full_;
}

Eigen::MatrixXd Nlp::jacobian(const Eigen::VectorXd& x) {
  const int nnz = jacobianNonzeros();
  std::vector<double> v(nnz);
  eval_jac_g(static_cast<int>(x.size()), x.data(), true, rows_, nnz, nullptr, nullptr, v.data());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(t_.constraints(), t_.variables());
  for (int k = 0; k < nnz; ++k) J(jac_row_[k], jac_col_[k]) += v[k];
  return J;
}

Eigen::MatrixXd Nlp::hessian(const Eigen::VectorXd& x, double obj_factor, const Eigen::VectorXd& lambda) {
  const int nnz = hessianNonzeros();
  std::vector<double> v(nnz);
  Eigen::VectorXd lambda_nlp(rows_);  // Ipopt's rows
  for (int i = 0; i < t_.constraints(); ++i)
    if (row_[i] >= 0) lambda_nlp[row_[i]] = lambda[i];
  eval_h(static_cast<int>(x.size()), x.data(), true, obj_factor, rows_, lambda_nlp.data(), true, nnz, nullptr, nullptr,
         v.data());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(t_.variables(), t_.variables());
  for (int k = 0; k < nnz; ++k) {
    H(hess_row_[k], hess_col_[k]) += v[k];
    if (hess_row_[k] != hess_col_[k]) H(hess_col_[k], hess_row_[k]) += v[k];
  }
  return H;
}

}  // namespace saltus::collocation
