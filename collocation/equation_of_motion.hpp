// The equations of motion at a collocation point or an element boundary, with the contacts'
// reactions: a local function of the transcription (local_function.hpp; the others are in
// functions.hpp), with the Hessian pairs and Jacobian columns it forms itself
// (equation_of_motion.cpp).
#pragma once

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
  // some contact's Jacobian where its reaction acts does (ContactPair::reaction_jacobian_with),
  // and are affine in the world translations jointly. So F is affine in the world translations'
  // q, and independent of their q̇ and of those q no contact's Jacobian depends on (zero columns).
  bool inDynamics(int k) const { return !dynamics::isWorldTranslation(models->model<double>(), k); }
  bool inReactions(int k) const {
    for (const ContactPair& c : *contacts)
      if (!c.isStop() && c.reaction_jacobian_with[k]) return true;
    return false;
  }
  bool dependsOn(int k) const { return inDynamics(k) || inReactions(k); }
  // The contact among whose inputs input i is (its r_n, its k tangential variables, a free
  // point's s): the pair, the input index of its r_n and i's place from there (0: r_n, 1 … k:
  // the tangential variables, then s); no pair when i is not a contact's.
  struct ContactInput {
    const ContactPair* pair = nullptr;
    int first = 0, offset = 0;
  };
  ContactInput contactInput(int i) const {
    int k = (with_dynamics ? 3 : 2) * nv() + inputs_count();
    for (const ContactPair& c : *contacts) {
      const int end = k + 1 + c.k() + c.freeAxes();
      if (i >= k && i < end) return {&c, k, i - k};
      k = end;
    }
    return {};
  }
  // Affine in q̈ (or Δq̇), u and the tangential variables for fixed q, q̇, r_n; q̇ enters
  // quadratically (C(q, q̇) q̇), r_n times α_i in the Activation form's μ r_n α_i.
  bool nonlinear(int i) const {
    const int n = nv();
    if (i < n) return inDynamics(i);                             // q
    if (with_dynamics && i < 2 * n) return inDynamics(i - n);  // q̇
    const ContactInput in = contactInput(i);
    if (!in.pair) return false;
    if (in.offset == 0) return friction == FrictionForm::Activation && in.pair->k() > 0;  // r_n
    return in.offset > in.pair->k();  // s (times the reaction)
  }
  // The Hessian of φ = λᵀF: nested duals only for the pairs within q and between q and q̇ (one
  // outer direction per coordinate); the rest, in addHessian (equation_of_motion.cpp), from first-order
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
  // (ContactPair::reaction_jacobian_with), its (t_i, r_n) in the Activation form, and a free point's
  // (s, r_n), (s, t_i).
  bool pairSupplied(int i, int j) const {
    const int n = nv(), first_acceleration = (with_dynamics ? 2 : 1) * n;
    if (with_dynamics && j >= n && i < 2 * n) return inDynamics(i - n) && inDynamics(j - n);
    if (i >= first_acceleration && i < first_acceleration + n) return j < n && inDynamics(j);
    const ContactInput in = contactInput(i);
    if (!in.pair || in.pair->isStop()) return false;
    const ContactPair& c = *in.pair;
    if (j < n) return c.reaction_jacobian_with[j];
    if (j < in.first || i == j) return false;
    const int a = in.offset, b = j - in.first;  // a > b: r_n is 0, t is 1 … k, s after
    if (a <= c.k()) return b == 0 && friction == FrictionForm::Activation;  // (t_a, r_n)
    return b <= c.k();                                                      // (s, r_n), (s, t_b); (s, s) is zero
  }
  // The Jacobian by AD for a free point's s; the other columns in jacobianColumns
  // (equation_of_motion.cpp):
  //   q, q̇: ∂τ/∂q, ∂τ/∂q̇ of RNEA (dynamics::rneaDerivatives, forward-mode AD of RBDA Table 5.1
  //         on tangents), plus −∂(Σ J_cᵀ f_c)/∂q by AD through the kinematics and the contact layer
  //         alone, for the q some contact's Jacobian depends on (ContactPair::reaction_jacobian_with)
  //   q̈ or Δq̇: M(q) (CRBA, RBDA Table 6.2)    u: −B    r_n, t_i: −J_cᵀ ∂f_c/∂r_n, −J_cᵀ ∂f_c/∂t_i
  // (a stop's r_n: −sign e_i). When the q and q̇ F depends on fit in the chunks of AD that s
  // needs anyway (a point mass on a board: the board's angle and rate), they go by AD with it;
  // when there are none, no pass at all.
  bool columnByAd(int i) const {
    const int n = nv();
    if (i < n) return !qByRneaDerivatives() && dependsOn(i);                                // q
    if (with_dynamics && i < 2 * n) return !qByRneaDerivatives() && inDynamics(i - n);  // q̇
    const ContactInput in = contactInput(i);
    return in.pair && in.offset > in.pair->k();  // s
  }
  // Whether jacobianColumns forms the q and q̇ columns (above): when by AD they would add a chunk
  // to those s needs (none when F depends on no q, as for a point mass in the world).
  bool qByRneaDerivatives() const {
    if (q_by_rnea_derivatives < 0) {
      int s = 0, q = 0;
      for (const ContactPair& c : *contacts) s += c.freeAxes();
      for (int k = 0; k < nv(); ++k) q += dependsOn(k) + (with_dynamics && inDynamics(k));
      const auto chunks = [](int columns) { return (columns + kChunk - 1) / kChunk; };
      q_by_rnea_derivatives = chunks(s + q) > chunks(s);
    }
    return q_by_rnea_derivatives > 0;
  }
  void jacobianColumns(const double* x, double* J) const;
  void addReactionColumns(const double* x, double* J) const;  // jacobianColumns' reactions over q

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
    subtractReactions(model, data, r, y);
    for (int k = 0; k < inputs_count(); ++k) y[actuated[k]] -= u[k];
    if (with_dynamics)
      for (int i = 0; i < constant_input.size(); ++i) y[i] -= S(constant_input[i]);
  }

  // y −= Σ_c J_cᵀ f_c, J_c the contact layer's relative Jacobian at the world poses in data
  // (contact::addReaction adds Jᵀ f: here with the reaction's opposite; − sign r_n on a stop's
  // coordinate). r: per contact, r_n, its k tangential variables and a free point's s.
  template <class S>
  void subtractReactions(const dynamics::Model<S>& model, dynamics::Data<S>& data, const S* r, S* y) const {
    for (const ContactPair& c : *contacts) {
      const S& rn = r[0];
      const Vec3<S> f_t = contactForce(c, data, friction, rn, r + 1, true);
      if (c.freePoint())
        contact::addReactionAt(model, data, c, S(-rn), Vec3<S>(-f_t), r + 1 + c.k(), y);
      else
        contact::addReaction(model, data, c, S(-rn), Vec3<S>(-f_t), y);
      r += 1 + c.k() + c.freeAxes();
    }
  }

  // Scratch: the reactions' inputs in first-order duals, for jacobianColumns' pass over q.
  mutable std::vector<Dual> reactions_dual{};
  mutable int q_by_rnea_derivatives = -1;  // qByRneaDerivatives, once known
};

// Instantiated once, in equation_of_motion.cpp (see AdFunction).
extern template class AdFunction<EquationOfMotion>;

}  // namespace saltus::collocation
