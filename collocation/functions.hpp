// The local functions of the transcription (local_function.hpp): contact kinematics, integration
// and the complementarity products, each with the paper's equation; the equations of motion are
// in equation_of_motion.hpp.
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "collocation/equation_of_motion.hpp"
#include "collocation/local_function.hpp"
#include "collocation/model_set.hpp"
#include "contact/kinematics.hpp"
#include "dynamics/world_translation.hpp"

namespace saltus::collocation {

// Whether a point-on-plane pair turns with coordinate k: it moves with it and k is not a world
// translation (dynamics/world_translation.hpp). The pair's gap, plane coordinates, frame and
// Jacobian are affine in the world translations jointly, for fixed values of these.
inline bool turnsWith(const ContactPair& c, const dynamics::Model<double>& model, int k) {
  return c.moves_with[k] && !dynamics::isWorldTranslation(model, k);
}

// Whether ∂²/∂q_i∂q_j of a point-on-plane pair's gap or plane coordinates can be non-zero (i, j
// velocity coordinates): both move the pair and one turns it; a world translation pairs only
// with the coordinates that turn a body's plane (for a world plane the gap is linear in the
// translations).
inline bool gapPair(const ContactPair& c, const dynamics::Model<double>& model, int i, int j) {
  if (!c.moves_with[i] || !c.moves_with[j]) return false;
  const bool ti = turnsWith(c, model, i), tj = turnsWith(c, model, j);
  return (ti && tj) || (c.body_b >= 0 && (ti || tj));
}

// Gap variables: y_c − gap_c(q) = 0 for every contact at one point (the gaps are variables so
// that non-penetration y ≥ 0 is a bound and (9b), (10) are products of variables).
// Inputs: q (n), y (one per contact).
struct GapDefinition {
  const ModelSet* models;
  const std::vector<ContactPair>* contacts;
  // The contacts with a gap variable (the points on planes; a joint stop's gap is its
  // coordinate, Transcription::gap), in the order of their y inputs and outputs.
  std::vector<int> pairs;
  int inputs() const { return models->model<double>().nv() + outputs(); }
  int outputs() const { return static_cast<int>(pairs.size()); }
  // q, of the coordinates some point-on-plane contact turns with (turnsWith): affine in the world
  // translations (and their pairs with the others go to the latter's sweeps), and in y.
  bool nonlinear(int i) const {
    if (i >= models->model<double>().nv()) return false;
    for (int c : pairs)
      if (turnsWith((*contacts)[c], models->model<double>(), i)) return true;
    return false;
  }
  bool pairByAd(int i, int j) const {  // y enters with coefficient 1
    const int n = models->model<double>().nv();
    if (i >= n || j >= n) return false;
    for (int c : pairs)
      if (gapPair((*contacts)[c], models->model<double>(), i, j)) return true;
    return false;
  }
  // The Jacobian by AD for the q some contact moves with; the others' columns are zero, y's the
  // identity.
  bool columnByAd(int i) const {
    if (i >= models->model<double>().nv()) return false;
    for (int c : pairs)
      if ((*contacts)[c].moves_with[i]) return true;
    return false;
  }
  void jacobianColumns(const double*, double* J) const {
    const int n = models->model<double>().nv(), m = outputs();
    for (int i = 0; i < n + m; ++i)
      if (!columnByAd(i)) std::fill(J + i * m, J + (i + 1) * m, 0.0);
    for (int c = 0; c < m; ++c) J[c + (n + c) * m] = 1.0;
  }
  template <class S>
  void operator()(const S* x, S* y) const {
    const int n = models->model<double>().nv();
    auto& data = models->data<S>();
    dynamics::forwardKinematics(models->model<S>(), data, ConstMap<S>(x, n));
    for (int c = 0; c < outputs(); ++c) y[c] = x[n + c] - contact::gap((*contacts)[pairs[c]], data, x);
  }
};

// The contact point's coordinate s_axis along a tangent of a plane fixed in a body
// (contact::planeCoordinates), which the transcription bounds by the plane's extent: the
// optimiser keeps such a point over its rectangle, where the gap of the unbounded plane is the
// gap (see Transcription::buildContactConstraints). Inputs: q (n).
struct PlaneCoordinate {
  const ModelSet* models;
  const ContactPair* contact;
  int axis = 0;
  int inputs() const { return models->model<double>().nv(); }
  int outputs() const { return 1; }
  // Of q, only the coordinates the contact moves with: the others' columns are zero. Affine in
  // the world translations, like the gap (gapPair).
  bool nonlinear(int i) const { return turnsWith(*contact, models->model<double>(), i); }
  bool pairByAd(int i, int j) const { return gapPair(*contact, models->model<double>(), i, j); }
  bool columnByAd(int i) const { return contact->moves_with[i]; }
  void jacobianColumns(const double*, double* J) const {
    for (int i = 0; i < inputs(); ++i)
      if (!columnByAd(i)) J[i] = 0.0;
  }
  template <class S>
  void operator()(const S* x, S* y) const {
    auto& data = models->data<S>();
    dynamics::forwardKinematics(models->model<S>(), data, ConstMap<S>(x, inputs()));
    y[0] = contact::planeCoordinates(*contact, data)[axis];
  }
};

// A free contact point's offset (ContactPair::free_axes): for each free axis i,
//   s_A,i(q) − s_i − d⁺_i + d⁻_i = 0,   d⁺_i, d⁻_i ≥ 0
// where s_A = planeCoordinates(q) is A's point projected onto B's plane and s the contact point's
// plane coordinates (bounded by the extent). The transcription makes r_n ⊥ Σ_i (d⁺_i + d⁻_i) and
// d⁺_i ⊥ d⁻_i: while the contact carries a reaction the contact point is A's projection, so A
// is over the rectangle; while it carries none A may be beyond it (above the plane's level: the
// gap stays the unbounded plane's). Inputs: q (n), s, d⁺, d⁻ (m each).
struct FreePointOffset {
  const ModelSet* models;
  const ContactPair* contact;
  int m() const { return contact->freeAxes(); }
  int inputs() const { return models->model<double>().nv() + 3 * m(); }
  int outputs() const { return m(); }
  // q, of the coordinates the contact turns with (affine in the world translations, as the gap:
  // gapPair); s, d⁺, d⁻ enter with coefficients ±1.
  bool nonlinear(int i) const { return i < models->model<double>().nv() && turnsWith(*contact, models->model<double>(), i); }
  bool pairByAd(int i, int j) const {
    const int n = models->model<double>().nv();
    return i < n && j < n && gapPair(*contact, models->model<double>(), i, j);
  }
  // The Jacobian by AD for the q the contact moves with: the other q's columns are zero, s's −1,
  // d⁺'s −1, d⁻'s +1.
  bool columnByAd(int i) const { return i < models->model<double>().nv() && contact->moves_with[i]; }
  void jacobianColumns(const double*, double* J) const {
    const int n = models->model<double>().nv(), k = m();
    for (int i = 0; i < n + 3 * k; ++i)
      if (!columnByAd(i)) std::fill(J + i * k, J + (i + 1) * k, 0.0);
    for (int i = 0; i < k; ++i) {
      J[i + (n + i) * k] = -1.0;
      J[i + (n + k + i) * k] = -1.0;
      J[i + (n + 2 * k + i) * k] = 1.0;
    }
  }
  template <class S>
  void operator()(const S* x, S* y) const {
    const int n = models->model<double>().nv();
    auto& data = models->data<S>();
    dynamics::forwardKinematics(models->model<S>(), data, ConstMap<S>(x, n));
    const Eigen::Matrix<S, 2, 1> s_A = contact::planeCoordinates(*contact, data);
    const S* s = x + n;
    for (int i = 0; i < m(); ++i) y[i] = s_A[contact->free_axes[i]] - s[i] - s[m() + i] + s[2 * m() + i];
  }
};

// Restitution at an element boundary, paper eq. (9a):
//   a⁺ − a⁻ − ẏ[n, 0] − e ẏ[n−1, P+1] = 0   (ẏ[n, 0] after the jump, ẏ[n−1, P+1] before it)
// Inputs: q, q̇ after (2n), q, q̇ before (2n), a⁺, a⁻; without the state before when e = 0
// (`before` false), where its term is zero: half the inputs and a quarter of the Hessian's work
// (one side's kinematics per sweep, half the sweeps). A joint stop's balance is linear
// (ẏ = ±q̇_i) and is not this functor (Transcription::buildContactConstraints).
struct RestitutionBalance {
  const ModelSet* models;
  const ContactPair* contact;
  bool before = true;
  int sides() const { return before ? 2 : 1; }
  int inputs() const { return 2 * sides() * models->model<double>().nv() + 2; }
  int outputs() const { return 1; }
  // ẏ = nᵀ J(q) q̇ (contact::normalVelocity) is linear in q̇ for fixed q: only the q's are nonlinear.
  // Of those, the coordinates the Jacobian depends on (ContactPair::jacobian_with): F has no
  // others. (A world translation among them moves the point against B's rotation: F is bilinear
  // in it and B's rates, so it is not linear with them.)
  bool isQ(int i) const {
    const int n = models->model<double>().nv();
    return i < n || (before && i >= 2 * n && i < 3 * n);
  }
  bool nonlinear(int i) const { return isQ(i) && contact->jacobian_with[i % models->model<double>().nv()]; }
  bool turns(int i) const { return turnsWith(*contact, models->model<double>(), i % models->model<double>().nv()); }
  // The two sides do not mix and a⁺, a⁻ enter with constant coefficients: the pairs within
  // (q, q̇) after and within (q, q̇) before, of a q the Jacobian depends on
  // (ContactPair::jacobian_with) with another such q, one of them not a world translation, or
  // with a q̇ the contact moves with.
  bool pairByAd(int i, int j) const {  // i ≥ j
    const int n = models->model<double>().nv();
    const bool side = (j < n && i < 2 * n) || (before && j >= 2 * n && j < 3 * n && i < 4 * n);
    if (!side || !contact->jacobian_with[j % n]) return false;
    if (!isQ(i)) return contact->moves_with[i % n];
    return contact->jacobian_with[i % n] && (turns(i) || turns(j));  // J is affine in the translations jointly
  }
  // The Jacobian by AD for the q's the Jacobian depends on; q̇'s columns are −nᵀJ(q) (and
  // −e nᵀJ(q⁻)), a⁺'s and a⁻'s ±1, the other q's zero (jacobianColumns, functions.cpp).
  bool columnByAd(int i) const { return isQ(i) && contact->jacobian_with[i % models->model<double>().nv()]; }
  void jacobianColumns(const double* x, double* J) const;
  template <class S>
  void operator()(const S* x, S* y) const {
    const int n = models->model<double>().nv();
    const auto& model = models->model<S>();
    auto& data = models->data<S>();
    dynamics::forwardVelocities(model, data, ConstMap<S>(x, n), ConstMap<S>(x + n, n));
    y[0] = -contact::normalVelocity(*contact, data, x + n);
    if (before) {
      dynamics::forwardVelocities(model, data, ConstMap<S>(x + 2 * n, n), ConstMap<S>(x + 3 * n, n));
      y[0] -= S(contact->restitution) * contact::normalVelocity(*contact, data, x + 3 * n);
    }
    const S* a = x + 2 * sides() * n;
    y[0] += a[0] - a[1];
  }
};

// Slip slacks of a friction cone at one point:
//   Activation (paper eq. 12): ψ_i = γ − d_iᵀ v_t ≥ 0,   α_i ⊥ ψ_i
//   Direct (Posa et al.):      ψ_i = γ + d_iᵀ v_t ≥ 0,   β_i ⊥ ψ_i
// as equalities ψ_i − γ ± d_iᵀ v_t = 0, v_t the contact's relative velocity (contact layer; for a
// world plane less the surface's velocity at this element; for a free point with B's material
// point at the plane coordinates s). Inputs: q, q̇ (2n), s (free point: m), γ, ψ_1 … ψ_k.
struct SlipSlack {
  const ModelSet* models;
  const ContactPair* contact;
  Eigen::Vector3d surface_velocity = Eigen::Vector3d::Zero();
  FrictionForm friction = FrictionForm::Activation;
  int inputs() const { return 2 * models->model<double>().nv() + contact->freeAxes() + 1 + contact->k(); }
  int outputs() const { return contact->k(); }
  // q (v_t = J(q) q̇ − v_surface), of the coordinates the Jacobian depends on
  // (ContactPair::reaction_jacobian_with): F has no others; a free point's s (B's velocity at
  // p + Σ t_i s_i, times q̇ and the directions of q).
  bool isS(int i) const {
    const int n = models->model<double>().nv();
    return i >= 2 * n && i < 2 * n + contact->freeAxes();
  }
  bool nonlinear(int i) const {
    const int n = models->model<double>().nv();
    return (i < n && contact->reaction_jacobian_with[i]) || isS(i);
  }
  // γ and ψ enter with constant coefficients: the pairs of a q the Jacobian depends on
  // (ContactPair::reaction_jacobian_with) with another such q, one of them not a world translation, or
  // with a q̇ the contact moves with, and s with those q and q̇ (it enters affinely: no (s, s)).
  bool pairByAd(int i, int j) const {
    const int n = models->model<double>().nv();
    if (isS(i)) return j < 2 * n && contact->reaction_jacobian_with[j % n];
    if (j >= n || i >= 2 * n || !contact->reaction_jacobian_with[j]) return false;
    if (i >= n) return contact->moves_with[i - n];
    const auto& model = models->model<double>();  // J is affine in the world translations jointly
    return contact->reaction_jacobian_with[i] && (turnsWith(*contact, model, i) || turnsWith(*contact, model, j));
  }
  // The Jacobian by AD for the q's the Jacobian depends on and s; q̇'s columns are ±d_iᵀ J(q), γ's
  // −1, ψ's the identity, the other q's zero (jacobianColumns, functions.cpp).
  bool columnByAd(int i) const {
    return (i < models->model<double>().nv() && contact->reaction_jacobian_with[i]) || isS(i);
  }
  void jacobianColumns(const double* x, double* J) const;
  template <class S>
  void operator()(const S* x, S* y) const {
    const int n = models->model<double>().nv();
    auto& data = models->data<S>();
    dynamics::forwardVelocities(models->model<S>(), data, ConstMap<S>(x, n), ConstMap<S>(x + n, n));
    const int m = contact->freeAxes();
    const Vec3<S> slip = m > 0 ? contact::relativeVelocityAt(*contact, data, x + 2 * n)
                               : contact::relativeVelocity(*contact, data, Vec3<S>(surface_velocity.cast<S>()));
    const S& gamma = x[2 * n + m];
    const S sign(friction == FrictionForm::Activation ? 1.0 : -1.0);
    for (int i = 0; i < contact->k(); ++i)
      y[i] = x[2 * n + m + 1 + i] - gamma + sign * contact::frictionDirection(*contact, data, i).dot(slip);
  }
};

// Integration within an element, paper eqs. (3) and (4), for one coordinate:
//   x_end − x_0 − h Σ_j c_j ẋ_j = 0   (c = a row of Ω, or the quadrature weights b)
// Inputs: x_end, x_0, h, ẋ_1 … ẋ_P.
struct Integration {
  Eigen::VectorXd c;
  int inputs() const { return 3 + static_cast<int>(c.size()); }
  int outputs() const { return 1; }
  bool nonlinear(int i) const { return i == 2; }  // h (times the rates)
  // The one nonzero block, ∂²(λ y)/∂h∂ẋ_j = −λ c_j, written directly: no nested duals.
  bool pairByAd(int, int) const { return false; }
  bool pairSupplied(int i, int j) const { return j == 2 && i >= 3; }
  void addHessian(const double*, const double* lambda, double* H) const {
    const int n = inputs();
    for (int j = 0; j < c.size(); ++j) H[(3 + j) + 2 * n] -= lambda[0] * c[j];
  }
  template <class S>
  void operator()(const S* x, S* y) const {
    S sum(0);
    for (int j = 0; j < c.size(); ++j) sum += S(c[j]) * x[3 + j];
    y[0] = x[0] - x[1] - x[2] * sum;
  }
};

// Actuator effort over an element by its quadrature: h Σ_j b_j Σ_i u_i[j]². Inputs: h, then the
// inputs at the collocation points (point-major).
struct Effort {
  Eigen::VectorXd b;
  int nu = 0;
  int inputs() const { return 1 + static_cast<int>(b.size()) * nu; }
  int outputs() const { return 1; }
  // ∂²/∂u² = 2 h b_j on the diagonal, ∂²/∂h∂u = 2 b_j u; the rest is zero.
  bool pairByAd(int i, int j) const { return i > 0 && (i == j || j == 0); }  // i ≥ j
  template <class S>
  void operator()(const S* x, S* y) const {
    S sum(0);
    for (int j = 0; j < b.size(); ++j)
      for (int i = 0; i < nu; ++i) sum += S(b[j]) * x[1 + j * nu + i] * x[1 + j * nu + i];
    y[0] = x[0] * sum;
  }
};

// The transcription's functors are instantiated once, in functions.cpp (see AdFunction).
extern template class AdFunction<GapDefinition>;
extern template class AdFunction<PlaneCoordinate>;
extern template class AdFunction<FreePointOffset>;
extern template class AdFunction<RestitutionBalance>;
extern template class AdFunction<SlipSlack>;
extern template class AdFunction<Integration>;
extern template class AdFunction<Effort>;

// Σ_i c_i x_i (a linear constraint or cost term; its Hessian is zero).
class LinearFunction final : public LocalFunction {
 public:
  explicit LinearFunction(Eigen::VectorXd c) : c_(std::move(c)) {}
  int inputs() const override { return static_cast<int>(c_.size()); }
  int outputs() const override { return 1; }
  bool linear() const override { return true; }
  void value(const double* x, double* y) const override { y[0] = c_.dot(ConstMap<double>(x, c_.size())); }
  void jacobian(const double*, double* J) const override {
    for (int i = 0; i < c_.size(); ++i) J[i] = c_[i];
  }
  void hessian(const double*, const double*, double*) const override {}

 private:
  Eigen::VectorXd c_;
};

// weight × f (a weighted cost term sharing its function with the other elements).
class ScaledFunction final : public LocalFunction {
 public:
  ScaledFunction(std::shared_ptr<const LocalFunction> f, double weight) : f_(std::move(f)), w_(weight) {}
  int inputs() const override { return f_->inputs(); }
  int outputs() const override { return f_->outputs(); }
  bool linear() const override { return f_->linear(); }
  void value(const double* x, double* y) const override {
    f_->value(x, y);
    for (int r = 0; r < outputs(); ++r) y[r] *= w_;
  }
  void jacobian(const double* x, double* J) const override {
    f_->jacobian(x, J);
    for (int i = 0; i < inputs() * outputs(); ++i) J[i] *= w_;
  }
  void hessian(const double* x, const double* lambda, double* H) const override {
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 64, 1> l = ConstMap<double>(lambda, outputs()) * w_;
    f_->hessian(x, l.data(), H);
  }
  bool hessianPair(int i, int j) const override { return f_->hessianPair(i, j); }

 private:
  std::shared_ptr<const LocalFunction> f_;
  double w_;
};

// A relaxed complementarity product, paper eq. (8):
//   (Σ_{i<na} a_i x_i + a_0)(Σ_{na≤i<n−1} b_i x_i + b_0) − ε ≤ 0, ε = x_{n−1}.
class ComplementarityProduct final : public LocalFunction {
 public:
  ComplementarityProduct(Eigen::VectorXd a, double a0, Eigen::VectorXd b, double b0)
      : a_(std::move(a)), b_(std::move(b)), a0_(a0), b0_(b0) {}
  int inputs() const override { return static_cast<int>(a_.size() + b_.size()) + 1; }
  int outputs() const override { return 1; }
  double product(const double* x) const { return factorA(x) * factorB(x); }
  void value(const double* x, double* y) const override { y[0] = product(x) - x[inputs() - 1]; }
  void jacobian(const double* x, double* J) const override {
    const double A = factorA(x), B = factorB(x);
    const int na = static_cast<int>(a_.size());
    for (int i = 0; i < na; ++i) J[i] = a_[i] * B;
    for (int i = 0; i < b_.size(); ++i) J[na + i] = b_[i] * A;
    J[inputs() - 1] = -1;
  }
  void hessian(const double*, const double* lambda, double* H) const override {
    const int n = inputs(), na = static_cast<int>(a_.size());
    for (int j = 0; j < na; ++j)
      for (int i = 0; i < b_.size(); ++i) H[(na + i) + j * n] = lambda[0] * a_[j] * b_[i];
  }
  bool hessianPair(int i, int j) const override {  // i ≥ j: a b-input with an a-input
    const int na = static_cast<int>(a_.size());
    return j < na && i >= na && i < na + b_.size();
  }

 private:
  double factorA(const double* x) const { return a_.dot(ConstMap<double>(x, a_.size())) + a0_; }
  double factorB(const double* x) const { return b_.dot(ConstMap<double>(x + a_.size(), b_.size())) + b0_; }
  Eigen::VectorXd a_, b_;
  double a0_, b0_;
};

}  // namespace saltus::collocation
