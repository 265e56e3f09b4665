// The local functions of the transcription (local_function.hpp): equations of motion, contact
// kinematics, integration and the complementarity products, each with the paper's equation.
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "collocation/local_function.hpp"
#include "collocation/model_set.hpp"
#include "contact/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/world_translation.hpp"

namespace saltus::collocation {

constexpr int kMaxCoordinates = 64;  // bound of the stack arrays in the local functions
template <class S> using ConstMap = Eigen::Map<const Eigen::Matrix<S, Eigen::Dynamic, 1>>;
template <class S> using Vec3 = dynamics::Vec3<S>;

// The problem's unilateral constraints are the scene's contact pairs (contact/pair.hpp): a point
// on a plane (gap along the plane's normal, friction with a polyhedral cone of k directions,
// restitution e) or a joint stop (frictionless); their kinematics come from contact/kinematics.hpp.
using contact::ContactPair;

// How tangential reactions enter the equations of motion.
enum class FrictionForm {
  Activation,  // the paper's (11): r_t = μ r_n Σ d_i α_i, opposing the slip (force −r_t)
  Direct       // Posa et al.: a force Σ d_i β_i, β_i ≥ 0
};

// The contact force of a pair in world coordinates, f = n r_n + f_t, from its normal reaction r_n
// and its k tangential variables t (normal and friction directions d_i from the contact layer):
//   Activation (paper eq. 11): f_t = −μ r_n Σ_i d_i α_i     Direct (Posa et al.): f_t = Σ_i d_i β_i
// `tangential_only` leaves the normal part out (f_t alone).
template <class S>
Vec3<S> contactForce(const ContactPair& pair, const dynamics::Data<S>& data, FrictionForm form, const S& r_n,
                     const S* t, bool tangential_only = false) {
  Vec3<S> f = tangential_only ? Vec3<S>(Vec3<S>::Zero()) : Vec3<S>(contact::planeNormal(pair, data) * r_n);
  for (int i = 0; i < pair.k(); ++i) {
    const Vec3<S> d = contact::frictionDirection(pair, data, i);
    if (form == FrictionForm::Activation)
      f -= d * (S(pair.friction) * r_n * t[i]);
    else
      f += d * t[i];
  }
  return f;
}

// Equations of motion at a point, with the reactions of the contacts:
//   with_dynamics:  M(q) q̈ + C(q, q̇) q̇ + g(q) − τ_0 − B u − Σ_c J_cᵀ f_c = 0   (paper §II.C)
//   impulsive:      M(q) Δq̇ − Σ_c J_cᵀ p_c = 0                            (paper eq. 6)
// where f_c = n r_n − μ r_n Σ_i d_i α_i (Activation) or n r_n + Σ_i d_i β_i (Direct). A free
// contact point (ContactPair::free_axes) has J_c = J_A(x_A) − J_B(p + Σ t_i s_i): the reaction on
// B acts at the plane's point at the plane coordinates s, which are inputs.
// Inputs: q (n), then with_dynamics: q̇ (n); q̈ or Δq̇ (n); u (one per input coordinate); then per
// contact: r_n, its k tangential variables and, for a free point, its plane coordinates s.
struct EquationOfMotion {
  const ModelSet* models;
  const std::vector<ContactPair>* contacts;
  std::vector<int> actuated;  // coordinates the inputs act on
  bool with_dynamics = true;
  FrictionForm friction = FrictionForm::Activation;
  Eigen::VectorXd constant_input;  // τ_0: the scene's constant generalised force (empty: none)

  int nv() const { return models->model<double>().nv(); }
  int inputs_count() const { return with_dynamics ? static_cast<int>(actuated.size()) : 0; }
  int inputs() const {
    int k = (with_dynamics ? 3 : 2) * nv() + inputs_count();
    for (const ContactPair& c : *contacts) k += 1 + c.k() + c.freeAxes();
    return k;
  }
  int outputs() const { return nv(); }
  // Whether M, C q̇ and g depend on coordinate k's position and rate: not on a world
  // translation's (dynamics/world_translation.hpp). The reactions' −J_cᵀ f_c depend on q_k when
  // some contact's Jacobian does (ContactPair::jacobian_with), and are affine in the world
  // translations jointly. So F is affine in the world translations' q, and independent of their
  // q̇ and of those q no contact's Jacobian depends on (zero columns).
  bool inDynamics(int k) const { return !dynamics::isWorldTranslation(models->model<double>(), k); }
  bool inReactions(int k) const {
    for (const ContactPair& c : *contacts)
      if (!c.isStop() && c.jacobian_with[k]) return true;
    return false;
  }
  bool dependsOn(int k) const { return inDynamics(k) || inReactions(k); }
  // Affine in q̈ (or Δq̇), u and the tangential variables for fixed q, q̇, r_n; q̇ enters
  // quadratically (C(q, q̇) q̇), r_n times α_i in the Activation form's μ r_n α_i.
  bool nonlinear(int i) const {
    const int n = nv();
    if (i < n) return inDynamics(i);                             // q
    if (with_dynamics && i < 2 * n) return inDynamics(i - n);  // q̇
    int k = (with_dynamics ? 3 : 2) * n + inputs_count();
    for (const ContactPair& c : *contacts) {
      if (i == k) return friction == FrictionForm::Activation && c.k() > 0;  // r_n
      if (i >= k + 1 + c.k() && i < k + 1 + c.k() + c.freeAxes()) return true;  // s (times the reaction)
      k += 1 + c.k() + c.freeAxes();
    }
    return false;
  }
  // The Hessian of φ = λᵀF: nested duals only for the pairs within q and between q and q̇ (one
  // outer direction per coordinate); the rest, in addHessian (functions.cpp), from first-order
  // passes and double evaluations:
  //   (q, q̈):  ∂²φ/∂q_i∂q̈_j = ∂(M(q) λ)_j/∂q_i, M symmetric; M(q) λ = RNEA(q, 0, λ) without gravity
  //   (q, r):  φ_c = −f_c(q, r)·w_c(q), w_c = J_c(q) λ the contact's relative velocity at q̇ = λ
  //            (RBDA 4.4); f_c depends on q through the plane's frame when the plane is on a body
  //   (r_n, α_i): μ d_i·w_c (Activation; zero in the Direct form)
  //   (s, ·):  a free point's w_c is affine in its plane coordinates s, ∂w_c/∂s_i = e_i(q)
  //            (contact::relativeVelocityAtSlope): ∂φ/∂s_i = −f_c·e_i, differentiated in q,
  //            r_n and α as above; (s, s) is zero
  //   (q̇, q̇): ψ(q̇) = λᵀ C(q, q̇) q̇ = λᵀ RNEA(q, q̇, 0) without gravity is a quadratic form, so
  //            ∂²ψ/∂q̇_i² = 2ψ(e_i), ∂²ψ/∂q̇_i∂q̇_j = ψ(e_i + e_j) − ψ(e_i) − ψ(e_j)
  // The other pairs are zero: q̈, u and the tangential variables enter linearly, r_n only with α
  // and s; F is affine in the world translations' q and does not depend on their q̇. The sweeps
  // are left the pairs within q (of the coordinates F depends on, one of them not a world
  // translation) and between q and q̇ (the dynamics' coordinates).
  bool pairByAd(int i, int j) const {  // i ≥ j
    const int n = nv();
    if (j >= n || i >= (with_dynamics ? 2 : 1) * n) return false;
    if (i >= n) return inDynamics(i - n) && inDynamics(j);
    return dependsOn(i) && dependsOn(j) && (inDynamics(i) || inDynamics(j));
  }
  void addHessian(const double* x, const double* lambda, double* H) const;
  // The pairs addHessian writes (i ≥ j): (q̇, q̇) and (q̈ or Δq̇, q) of the dynamics' coordinates,
  // a contact's (r_n, q), (t_i, q) and (s, q) for the q its Jacobian depends on
  // (ContactPair::jacobian_with), its (t_i, r_n) in the Activation form, and a free point's
  // (s, r_n), (s, t_i).
  bool pairSupplied(int i, int j) const {
    const int n = nv(), first_acceleration = (with_dynamics ? 2 : 1) * n;
    if (with_dynamics && j >= n && i < 2 * n) return inDynamics(i - n) && inDynamics(j - n);
    if (i >= first_acceleration && i < first_acceleration + n) return j < n && inDynamics(j);
    int k = first_acceleration + n + inputs_count();
    for (const ContactPair& c : *contacts) {
      const int end = k + 1 + c.k() + c.freeAxes();
      if (i >= k && i < end) {
        if (c.isStop()) return false;
        if (j < n) return c.jacobian_with[j];
        if (j < k || i == j) return false;
        const int a = i - k, b = j - k;    // a > b: r_n is 0, t is 1 … k, s after
        if (a <= c.k()) return b == 0 && friction == FrictionForm::Activation;  // (t_a, r_n)
        return b <= c.k();                  // (s, r_n), (s, t_b); (s, s) is zero
      }
      k = end;
    }
    return false;
  }
  // The Jacobian by AD for the q and q̇ F depends on (the others' columns are zero) and a free
  // point's s only; the columns of the inputs F is affine in, with coefficients of q (and the reactions)
  // alone, in jacobianColumns (functions.cpp):
  //   q̈ or Δq̇: M(q) (CRBA, RBDA Table 6.2)    u: −B    r_n, t_i: −J_cᵀ ∂f_c/∂r_n, −J_cᵀ ∂f_c/∂t_i
  // (a stop's r_n: −sign e_i). For the biped that is 2 of 7 chunks of 8 in continuous time.
  bool columnByAd(int i) const {
    const int n = nv();
    if (i < n) return dependsOn(i);                            // q
    if (with_dynamics && i < 2 * n) return inDynamics(i - n);  // q̇
    int k = (with_dynamics ? 3 : 2) * n + inputs_count();
    for (const ContactPair& c : *contacts) {
      if (i >= k + 1 + c.k() && i < k + 1 + c.k() + c.freeAxes()) return true;  // s
      k += 1 + c.k() + c.freeAxes();
    }
    return false;
  }
  void jacobianColumns(const double* x, double* J) const;

  template <class S>
  void operator()(const S* x, S* y) const {
    const int n = nv();
    const auto& model = with_dynamics ? models->model<S>() : models->modelWithoutGravity<S>();
    auto& data = models->data<S>();
    const S* q = x;
    const S* v = with_dynamics ? x + n : nullptr;
    const S* a = with_dynamics ? x + 2 * n : x + n;
    const S* u = a + n;
    const S* r = u + inputs_count();
    // RNEA first: its outward pass leaves ^iX_λ (and S_i(q) of a multi-coordinate joint) in
    // data, from which the world poses the contact layer's Jacobians need are composed (the pose of
    // forwardKinematics(q) without evaluating the joint transforms twice).
    const auto zero = Eigen::Matrix<S, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1>::Zero(n);
    const auto& tau = with_dynamics ? dynamics::rnea(model, data, ConstMap<S>(q, n), ConstMap<S>(v, n), ConstMap<S>(a, n))
                                    : dynamics::rnea(model, data, ConstMap<S>(q, n), zero, ConstMap<S>(a, n));
    for (int i = 0; i < n; ++i) y[i] = tau[i];
    dynamics::composeWorldPoses(model, data);
    // − Σ J_cᵀ f_c, J_c the contact layer's relative Jacobian (contact::addReaction adds Jᵀ f:
    // here with the reaction's opposite; − sign r_n on a stop's coordinate).
    for (const ContactPair& c : *contacts) {
      const S& rn = r[0];
      const Vec3<S> f_t = contactForce(c, data, friction, rn, r + 1, true);
      if (c.freePoint())
        contact::addReactionAt(model, data, c, S(-rn), Vec3<S>(-f_t), r + 1 + c.k(), y);
      else
        contact::addReaction(model, data, c, S(-rn), Vec3<S>(-f_t), y);
      r += 1 + c.k() + c.freeAxes();
    }
    for (int k = 0; k < inputs_count(); ++k) y[actuated[k]] -= u[k];
    if (with_dynamics)
      for (int i = 0; i < constant_input.size(); ++i) y[i] -= S(constant_input[i]);
  }
};

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
  // (ContactPair::jacobian_with): F has no others; a free point's s (B's velocity at
  // p + Σ t_i s_i, times q̇ and the directions of q).
  bool isS(int i) const {
    const int n = models->model<double>().nv();
    return i >= 2 * n && i < 2 * n + contact->freeAxes();
  }
  bool nonlinear(int i) const {
    const int n = models->model<double>().nv();
    return (i < n && contact->jacobian_with[i]) || isS(i);
  }
  // γ and ψ enter with constant coefficients: the pairs of a q the Jacobian depends on
  // (ContactPair::jacobian_with) with another such q, one of them not a world translation, or
  // with a q̇ the contact moves with, and s with those q and q̇ (it enters affinely: no (s, s)).
  bool pairByAd(int i, int j) const {
    const int n = models->model<double>().nv();
    if (isS(i)) return j < 2 * n && contact->jacobian_with[j % n];
    if (j >= n || i >= 2 * n || !contact->jacobian_with[j]) return false;
    if (i >= n) return contact->moves_with[i - n];
    const auto& model = models->model<double>();  // J is affine in the world translations jointly
    return contact->jacobian_with[i] && (turnsWith(*contact, model, i) || turnsWith(*contact, model, j));
  }
  // The Jacobian by AD for the q's the Jacobian depends on and s; q̇'s columns are ±d_iᵀ J(q), γ's
  // −1, ψ's the identity, the other q's zero (jacobianColumns, functions.cpp).
  bool columnByAd(int i) const {
    return (i < models->model<double>().nv() && contact->jacobian_with[i]) || isS(i);
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
extern template class AdFunction<EquationOfMotion>;
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
