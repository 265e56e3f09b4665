// Local functions: every constraint block and cost term of the transcription depends on a few
// variables only (the state at one collocation point, an element's mesh points, ...). Each is a
// LocalFunction y = F(x), x ∈ Rⁿ, y ∈ Rᵐ with n, m small; its Jacobian and the Hessian of λᵀF
// come from forward-mode AD of one templated functor, in chunks of fixed-size derivative vectors
// so that nothing touches the heap during a solve. Generic dynamic-size AD over the whole problem
// is what makes AD slow (drake#8482: Drake's AutoDiffXd mass matrix is ~140× slower than double).
//
//   Jacobian: x seeded with Dual<8> directions, ⌈n/8⌉ evaluations; fewer when the functor forms
//   some columns itself (SuppliesJacobianColumns: the equations of motion's M(q), −B and −Jᵀ;
//   the slip's, restitution's and gap's velocity and slack columns).
//   Hessian of φ = λᵀF: nested duals, the outer one carrying one direction e_i and the inner one
//   a chunk of 8 directions e_j (j ≤ i), so the outer derivative's inner derivatives are
//   ∂²φ/∂x_i∂x_j; each pair of the lower triangle once, about ⌈n(n+1)/16⌉ evaluations but at
//   least one per input. Fewer when the functor names the inputs it is affine in (AdFunction
//   below): those carry no outer direction; and fewer still when it computes some pairs itself
//   (SuppliesHessianPairs: the equations of motion's bilinear and velocity blocks).
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>  // after Eigen/Core

#include <algorithm>
#include <concepts>
#include <memory>
#include <vector>

namespace saltus::collocation {

constexpr int kChunk = 8;
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, kChunk, 1>>;
using Dual2 = Eigen::AutoDiffScalar<Eigen::Matrix<Dual, 1, 1>>;  // second order: e_i over a chunk
// The same over a chunk of 4, for Hessians whose sweeps need no more inner directions (the
// small models' rows): each nested-dual operation then carries 5 numbers per level, not 9.
constexpr int kSmallChunk = 4;
using DualSmall = Eigen::AutoDiffScalar<Eigen::Matrix<double, kSmallChunk, 1>>;
using Dual2Small = Eigen::AutoDiffScalar<Eigen::Matrix<DualSmall, 1, 1>>;

class LocalFunction {
 public:
  virtual ~LocalFunction() = default;
  virtual int inputs() const = 0;
  virtual int outputs() const = 0;
  virtual bool linear() const { return false; }  // zero Hessian: left out of its pattern
  virtual void value(const double* x, double* y) const = 0;
  // J: outputs × inputs, column-major (J[r + c·m] = ∂y_r/∂x_c).
  virtual void jacobian(const double* x, double* J) const = 0;
  // H: inputs × inputs, column-major, lower triangle filled (H[i + j·n] for i ≥ j) with
  // ∂²(λᵀF)/∂x_i∂x_j; the upper triangle is left untouched.
  virtual void hessian(const double* x, const double* lambda, double* H) const = 0;
  // Whether ∂²(λᵀF)/∂x_i∂x_j (i ≥ j) can be non-zero at some x and λ: the pairs of this block
  // the NLP's Hessian structure holds (Nlp). Every pair unless the function says otherwise.
  virtual bool hessianPair(int i, int j) const { return true; }
};

// A functor may say which of its inputs enter linearly: `bool nonlinear(int i) const` false for
// the inputs x_L on which F is affine jointly, for fixed values of the others x_N (F = A(x_N) x_L
// + b(x_N)). Then ∂²F/∂x_a∂x_b = 0 for a, b ∈ L, and the Hessian needs outer directions e_i
// for i ∈ N only. Without the member every input counts as nonlinear.
template <class F>
concept DeclaresLinearInputs = requires(const F& f) {
  { f.nonlinear(0) } -> std::convertible_to<bool>;
};

// A functor may also name the pairs the sweeps are to leave out: `bool pairByAd(int i, int j)
// const` (i ≥ j) false for them. They are zero unless the functor computes them itself, more
// cheaply than nested duals can: `void addHessian(const double* x, const double* lambda,
// double* H) const` adds ∂²(λᵀF)/∂x_i∂x_j of those pairs into H's lower triangle, which starts
// at zero outside the sweeps' pairs, and `bool pairSupplied(int i, int j) const` (i ≥ j) names
// them. An input with none of its pairs left to the sweeps has no outer direction. The pairs
// neither computed nor supplied are structurally zero: the NLP's Hessian leaves them out
// (LocalFunction::hessianPair).
template <class F>
concept DeclaresHessianPairs = requires(const F& f) {
  { f.pairByAd(0, 0) } -> std::convertible_to<bool>;
};
template <class F>
concept SuppliesHessianPairs = DeclaresHessianPairs<F> && requires(const F& f, const double* x, double* H) {
  f.addHessian(x, x, H);
  { f.pairSupplied(0, 0) } -> std::convertible_to<bool>;
};

// A functor may form some columns of its Jacobian itself: `bool columnByAd(int i) const` false for
// them and `void jacobianColumns(const double* x, double* J) const` writing each of them whole
// (zeros too) into J (outputs × inputs, column-major), leaving the others. The AD chunks then seed
// the other inputs only: for a functor affine in most of its inputs with coefficients it knows in
// closed form, a fraction of the evaluations.
template <class F>
concept SuppliesJacobianColumns = requires(const F& f, const double* x, double* J) {
  { f.columnByAd(0) } -> std::convertible_to<bool>;
  f.jacobianColumns(x, J);
};

// A LocalFunction from a functor F with `int inputs() const`, `int outputs() const` and
// `template <class S> void operator()(const S* x, S* y) const`, evaluated for S = double, Dual
// and Dual2 (or Dual2Small). The work arrays and the Hessian's plan of directions are made once, here; the
// member functions are defined out of the class so that collocation/functions.cpp can
// instantiate them for the transcription's functors, in a translation unit compiled with the
// inlining limits the AD expression templates need (collocation/CMakeLists.txt).
template <class F>
class AdFunction final : public LocalFunction {
 public:
  explicit AdFunction(F f);

  int inputs() const override { return n_; }
  int outputs() const override { return m_; }
  const F& functor() const { return f_; }

  void value(const double* x, double* y) const override;
  void jacobian(const double* x, double* J) const override;
  void hessian(const double* x, const double* lambda, double* H) const override;
  bool hessianPair(int i, int j) const override {
    return structural_[static_cast<std::size_t>(std::max(i, j) + std::min(i, j) * n_)];
  }

  // The Hessian's forward-over-forward evaluations: one per nonlinear input with pairs left to
  // the sweeps, while its row of pairs fits a chunk (tests).
  int hessianSweeps() const { return static_cast<int>(sweeps_.size()); }
  // Whether the sweeps run in Dual2Small (every sweep's inner directions fit kSmallChunk).
  bool smallSweeps() const { return small_; }
  // The Jacobian's evaluations in Dual: one per chunk of the columns by AD (tests).
  int jacobianSweeps() const { return (static_cast<int>(ad_columns_.size()) + kChunk - 1) / kChunk; }

 private:
  // One evaluation in Dual2: the outer direction e_outer, inner directions e_inner[0..count).
  struct Sweep {
    int outer = 0, count = 0;
    int inner[kChunk] = {};
  };

  template <class D2>
  void runSweeps(const double* x, const double* lambda, double* H, Eigen::Matrix<D2, Eigen::Dynamic, 1>& xs,
                 Eigen::Matrix<D2, Eigen::Dynamic, 1>& ys) const;

  F f_;
  int n_, m_;
  bool small_ = false;
  std::vector<Sweep> sweeps_;
  std::vector<int> linear_;  // the inputs in L (their pairs are zero in H)
  std::vector<bool> structural_;  // per pair (i ≥ j, at i + j·n): swept or supplied, so maybe non-zero
  std::vector<int> ad_columns_;  // the Jacobian's columns by AD (all but those F supplies)
  mutable Eigen::Matrix<Dual, Eigen::Dynamic, 1> xd_, yd_;
  mutable Eigen::Matrix<Dual2, Eigen::Dynamic, 1> x2_, y2_;
  mutable Eigen::Matrix<Dual2Small, Eigen::Dynamic, 1> x2s_, y2s_;
};

template <class F>
AdFunction<F>::AdFunction(F f)
    : f_(std::move(f)), n_(f_.inputs()), m_(f_.outputs()), xd_(n_), yd_(m_), x2_(n_), y2_(m_), x2s_(n_), y2s_(m_) {
  // An addHessian without pairByAd and pairSupplied would never be called, and its pairs would
  // be left out of the structure.
  static_assert(!requires(const F& g, const double* x, double* H) { g.addHessian(x, x, H); } || SuppliesHessianPairs<F>,
                "a functor with addHessian names the pairs it writes (pairSupplied) and those left to AD (pairByAd)");
  std::vector<bool> nonlinear(n_, true);
  if constexpr (DeclaresLinearInputs<F>)
    for (int i = 0; i < n_; ++i) nonlinear[i] = f_.nonlinear(i);
  for (int i = 0; i < n_; ++i)
    if (!nonlinear[i]) linear_.push_back(i);
  for (int i = 0; i < n_; ++i) {
    if constexpr (SuppliesJacobianColumns<F>)
      if (!f_.columnByAd(i)) continue;
    ad_columns_.push_back(i);
  }
  // The pairs (i, j) of H to compute, each once, grouped by outer direction: a row i ∈ N holds
  // its diagonal and (i, j) for every j ∈ L (only e_i can carry those: L has no outer
  // directions); each pair of two nonlinear inputs goes to the row of either, whichever has room
  // left in its last chunk of 8 (the shorter row when both or neither have). The pairs within L
  // are zero.
  // Pairs a functor supplies itself (SuppliesHessianPairs) are left out.
  auto by_ad = [this](int i, int j) {
    if constexpr (DeclaresHessianPairs<F>)
      return static_cast<bool>(f_.pairByAd(std::max(i, j), std::min(i, j)));
    else
      return true;
  };
  std::vector<std::vector<int>> rows(n_);
  for (int i = 0; i < n_; ++i) {
    if (!nonlinear[i]) continue;
    if (by_ad(i, i)) rows[i].push_back(i);
    for (int l : linear_)
      if (by_ad(i, l)) rows[i].push_back(l);
  }
  // The pairs go by distance from the diagonal, which keeps the rows even (nine nonlinear
  // inputs: nine sweeps; by rows, the last ones overflow into a tenth).
  auto spare = [](const std::vector<int>& row) { return row.size() % kChunk != 0; };
  for (int d = 1; d < n_; ++d)
    for (int i = d; i < n_; ++i) {
      const int j = i - d;
      if (!nonlinear[i] || !nonlinear[j] || !by_ad(i, j)) continue;
      const bool to_i = spare(rows[i]) != spare(rows[j]) ? spare(rows[i]) : rows[i].size() <= rows[j].size();
      if (to_i)
        rows[i].push_back(j);
      else
        rows[j].push_back(i);
    }
  for (int i = 0; i < n_; ++i)
    for (std::size_t first = 0; first < rows[i].size(); first += kChunk) {
      Sweep sweep;
      sweep.outer = i;
      sweep.count = static_cast<int>(std::min<std::size_t>(kChunk, rows[i].size() - first));
      std::copy_n(rows[i].begin() + static_cast<std::ptrdiff_t>(first), sweep.count, sweep.inner);
      sweeps_.push_back(sweep);
    }
  small_ = std::all_of(sweeps_.begin(), sweeps_.end(), [](const Sweep& s) { return s.count <= kSmallChunk; });
  // The pairs the sweeps compute (a nonlinear input's; within L they are zero) and those the
  // functor supplies.
  structural_.assign(static_cast<std::size_t>(n_) * n_, false);
  for (int j = 0; j < n_; ++j)
    for (int i = j; i < n_; ++i) {
      bool maybe = (nonlinear[i] || nonlinear[j]) && by_ad(i, j);
      if constexpr (SuppliesHessianPairs<F>) maybe = maybe || f_.pairSupplied(i, j);
      structural_[static_cast<std::size_t>(i + j * n_)] = maybe;
    }
}

template <class F>
void AdFunction<F>::value(const double* x, double* y) const {
  f_(x, y);
}

template <class F>
void AdFunction<F>::jacobian(const double* x, double* J) const {
  if constexpr (SuppliesJacobianColumns<F>) f_.jacobianColumns(x, J);
  const int count = static_cast<int>(ad_columns_.size());
  for (int i = 0; i < n_; ++i) {
    xd_[i].value() = x[i];
    xd_[i].derivatives().setZero();
  }
  for (int first = 0; first < count; first += kChunk) {
    const int cols = std::min(kChunk, count - first);
    for (int c = 0; c < cols; ++c) xd_[ad_columns_[first + c]].derivatives()[c] = 1.0;
    f_(xd_.data(), yd_.data());
    for (int c = 0; c < cols; ++c) {
      double* column = J + ad_columns_[first + c] * m_;
      for (int r = 0; r < m_; ++r) column[r] = yd_[r].derivatives()[c];
      xd_[ad_columns_[first + c]].derivatives()[c] = 0.0;
    }
  }
}

template <class F>
void AdFunction<F>::hessian(const double* x, const double* lambda, double* H) const {
  if constexpr (DeclaresHessianPairs<F>)
    for (int j = 0; j < n_; ++j)
      for (int i = j; i < n_; ++i) H[i + j * n_] = 0.0;
  if (small_)
    runSweeps(x, lambda, H, x2s_, y2s_);
  else
    runSweeps(x, lambda, H, x2_, y2_);
  if constexpr (SuppliesHessianPairs<F>)
    f_.addHessian(x, lambda, H);
  else if constexpr (!DeclaresHessianPairs<F>)
    for (int b : linear_)
      for (int a : linear_)
        if (a >= b) H[a + b * n_] = 0.0;
}

template <class F>
template <class D2>
void AdFunction<F>::runSweeps(const double* x, const double* lambda, double* H, Eigen::Matrix<D2, Eigen::Dynamic, 1>& xs,
                              Eigen::Matrix<D2, Eigen::Dynamic, 1>& ys) const {
  // Nested duals: the outer one carries e_i, the inner one the sweep's e_j; the outer
  // derivative's inner derivatives are ∂²y_r/∂x_i∂x_j, summed with the weights λ_r.
  using Inner = typename D2::Scalar;
  using InnerDerivatives = typename Inner::DerType;
  for (const Sweep& sweep : sweeps_) {
    for (int k = 0; k < n_; ++k) {
      xs[k].value() = Inner(x[k], InnerDerivatives::Zero());
      xs[k].derivatives()[0] = Inner(k == sweep.outer ? 1.0 : 0.0, InnerDerivatives::Zero());
    }
    for (int c = 0; c < sweep.count; ++c) xs[sweep.inner[c]].value().derivatives()[c] = 1.0;
    f_(xs.data(), ys.data());
    for (int c = 0; c < sweep.count; ++c) {
      double s = 0;
      for (int r = 0; r < m_; ++r)
        if (lambda[r] != 0.0) s += lambda[r] * ys[r].derivatives()[0].derivatives()[c];
      const int i = sweep.outer, j = sweep.inner[c];
      H[std::max(i, j) + std::min(i, j) * n_] = s;
    }
  }
}

template <class F>
std::unique_ptr<LocalFunction> makeAd(F f) {
  return std::make_unique<AdFunction<F>>(std::move(f));
}

}  // namespace saltus::collocation
