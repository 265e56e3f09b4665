// Local functions: every constraint block and cost term of the transcription depends on a few
// variables only (the state at one collocation point, an element's mesh points, ...). Each is a
// LocalFunction y = F(x), x ∈ Rⁿ, y ∈ Rᵐ with n, m small; its Jacobian and the Hessian of λᵀF
// come from forward-mode AD of one templated functor, in chunks of fixed-size derivative vectors
// so that nothing touches the heap during a solve. Generic dynamic-size AD over the whole problem
// is what makes AD slow (shared/reference/facts.md §2: Drake's AutoDiffXd mass matrix ~140×).
//
//   Jacobian: x seeded with Dual<8> directions, ⌈n/8⌉ evaluations.
//   Hessian of φ = λᵀF: nested duals, the outer one carrying one direction e_i and the inner one
//   a chunk of 8 directions e_j (j ≤ i), so the outer derivative's inner derivatives are
//   ∂²φ/∂x_i∂x_j; Σ_i ⌈(i+1)/8⌉ evaluations for the lower triangle.
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>  // after Eigen/Core

#include <algorithm>
#include <memory>

namespace saltus::collocation {

constexpr int kChunk = 8;
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, kChunk, 1>>;
using Dual2 = Eigen::AutoDiffScalar<Eigen::Matrix<Dual, 1, 1>>;  // second order: e_i over a chunk

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
};

// A LocalFunction from a functor F with `int inputs() const`, `int outputs() const` and
// `template <class S> void operator()(const S* x, S* y) const`, evaluated for S = double, Dual
// and Dual2. The work arrays are sized once, here.
template <class F>
class AdFunction final : public LocalFunction {
 public:
  explicit AdFunction(F f)
      : f_(std::move(f)), n_(f_.inputs()), m_(f_.outputs()),
        xd_(n_), yd_(m_), x2_(n_), y2_(m_) {}

  int inputs() const override { return n_; }
  int outputs() const override { return m_; }
  const F& functor() const { return f_; }

  void value(const double* x, double* y) const override { f_(x, y); }

  void jacobian(const double* x, double* J) const override {
    for (int first = 0; first < n_; first += kChunk) {
      for (int i = 0; i < n_; ++i) {
        xd_[i].value() = x[i];
        xd_[i].derivatives().setZero();
        if (i >= first && i < first + kChunk) xd_[i].derivatives()[i - first] = 1.0;
      }
      f_(xd_.data(), yd_.data());
      const int cols = std::min(kChunk, n_ - first);
      for (int r = 0; r < m_; ++r)
        for (int c = 0; c < cols; ++c) J[r + (first + c) * m_] = yd_[r].derivatives()[c];
    }
  }

  void hessian(const double* x, const double* lambda, double* H) const override {
    for (int i = 0; i < n_; ++i) {
      for (int first = 0; first <= i; first += kChunk) {
        for (int k = 0; k < n_; ++k) {
          Dual inner(x[k], Eigen::Matrix<double, kChunk, 1>::Zero());
          if (k >= first && k < first + kChunk) inner.derivatives()[k - first] = 1.0;
          x2_[k].value() = inner;
          x2_[k].derivatives()[0] = Dual(k == i ? 1.0 : 0.0, Eigen::Matrix<double, kChunk, 1>::Zero());
        }
        f_(x2_.data(), y2_.data());
        const int cols = std::min({kChunk, n_ - first, i + 1 - first});
        for (int c = 0; c < cols; ++c) {
          double s = 0;
          for (int r = 0; r < m_; ++r)
            if (lambda[r] != 0.0) s += lambda[r] * y2_[r].derivatives()[0].derivatives()[c];
          H[i + (first + c) * n_] = s;
        }
      }
    }
  }

 private:
  F f_;
  int n_, m_;
  mutable Eigen::Matrix<Dual, Eigen::Dynamic, 1> xd_, yd_;
  mutable Eigen::Matrix<Dual2, Eigen::Dynamic, 1> x2_, y2_;
};

template <class F>
std::unique_ptr<LocalFunction> makeAd(F f) {
  return std::make_unique<AdFunction<F>>(std::move(f));
}

}  // namespace saltus::collocation
