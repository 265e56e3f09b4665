// Moreau–Stewart–Trinkle time-stepping: each step solves one velocity-level linear
// complementarity problem for the contact impulses (D. E. Stewart & J. C. Trinkle, IJNME 39,
// 1996; M. Anitescu & F. A. Potra, Nonlinear Dynamics 14, 1997; V. Acary & B. Brogliato,
// "Numerical methods for nonsmooth dynamical systems", 2008, ch. 10 (Moreau–Jean)).
//
// One step of size h from (t, q, v), with θ ∈ [½, 1]:
//   q_θ  = q + (1 − θ) h v                      positions where the step is linearised
//   v*   = v + h M(q_θ)⁻¹ (τ − C(q_θ, v) v − g(q_θ))   free velocity
//   M (v⁺ − v*) = N ᵀ p_n + Dᵀ β                 impulses of the active contacts
//   q⁺   = q_θ + θ h v⁺
// θ = 1 is the Stewart–Trinkle / Anitescu–Potra scheme (first order, dissipative); θ = ½ is
// Moreau's midpoint scheme (second order on smooth phases, conserves energy in free flight).
//
// Forces are evaluated at (q_θ, v_θ) with the predictor v_θ = v + (1 − θ) h M⁻¹(τ − h(q_θ, v)),
// so the midpoint scheme is second order on smooth phases also with velocity-dependent forces.
//
// Active set: contact i takes part in the step when its gap at q_θ is ≤ contact_margin or its
// predicted gap at the end of the free step, gap(q_θ) + θ h n·v*, is ≤ contact_margin.
// Joint-limit stops likewise.
//
// Located impacts (locate_impacts, the default): when a contact that is open at the start of the
// step (gap g0 > contact_margin) is predicted to close within it, its time of impact t* is the
// earliest root in (0, h] of g(t) = g0 + v_n t + c t², c fitted to the predicted end gap g(h) (for
// a constant normal acceleration a_n, c = θ a_n: the θ-step of length t* then ends on the
// surface). If the approach speed there, v_n + c t*/θ, exceeds restitution_threshold (slower
// contacts are inelastic and the gap term below already closes them at the step's end), the step
// is split, the earliest t* over the contacts first:
//   1. a θ-step of length t*, in which only the contacts already closed (gap at q_θ ≤ margin) act;
//   2. the impact at t*: the LCP below with h = 0 (v* = v, no gap term) on the contacts closed
//      at t*, Newton's law with the approach velocity at t*;
//   3. a θ-step of length h − t* with the usual active set.
// Time still advances by h; the reports sum the impulses of the three parts. Steps in which no
// open contact closes are computed exactly as without the option. With θ = ½ a body in free
// flight under gravity is integrated exactly and g(t) is the exact quadratic, so a bounce is
// exact to round-off; without locating, the step's free fall before the impact is lost (up to
// one step, an O(h) error in the rebound height). A second impact within the same step, or a
// contact whose gap model misses (curved paths), falls back to the unsplit rule.
//
// Complementarity, for each active contact (normal row n_i of N, friction rows d_ij of D):
//   0 ≤ p_n,i ⊥ n_i v⁺ + e_i n_i v − n_i (v* − v) ≥ 0
//                                                Newton restitution at velocity level (Moreau),
//                                                the impact applied to the velocity before the
//                                                step and the free acceleration acting after it,
//                                                so an e = 1 bounce does not gain energy;
//                                                e_i = 0 when the approach speed is below
//                                                restitution_threshold (resting contacts)
//   0 ≤ p_n,i ⊥ n_i v⁺ + gap⁺_i / (θ h) ≥ 0      for e_i = 0: an open gap may close within the
//                                                step (Stewart–Trinkle), gap⁺ = max(gap, 0), so
//                                                a penetration is never pushed out by velocity
//   0 ≤ β_ij  ⊥ d_ij (v⁺ − v_surface(t + h)) + λ_i ≥ 0   polyhedral cone, k directions
//   0 ≤ λ_i   ⊥ μ_i p_n,i − Σ_j β_ij ≥ 0        λ_i: the sliding speed
// The surface velocity enters the relative tangential velocity, so a belt that steps in speed
// can be matched by a tangential impulse alone: an impact without collision (the resolution of
// Painlevé's paradox, paper §II.A).
//
// Drift: velocities only ever satisfy the linearised constraints, so positions can drift into a
// surface along curved paths. After each step any gap below −penetration_tolerance is removed by
// the smallest mass-weighted change of q (Cline & Pai's post-stabilisation): an LCP on
// N M⁻¹ Nᵀ that moves positions only, so no kinetic energy is injected.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "contact/pair.hpp"
#include "dynamics/data.hpp"
#include "timestepper/lcp.hpp"
#include "scene/scene.hpp"

namespace saltus::timestepper {

// The scene types the stepper reads (scene/scene.hpp).
using scene::Contact;
using scene::LimitStop;
using scene::Scene;
using scene::Surface;

enum class LcpMethod { Lemke, Pgs };

struct StepperOptions {
  double dt = 1e-3;
  double theta = 1.0;                     // ½ (Moreau midpoint) … 1 (Stewart–Trinkle)
  LcpMethod solver = LcpMethod::Lemke;
  double restitution_threshold = -1;      // [m/s]; < 0: 2 |g| dt (one step of free fall)
  double penetration_tolerance = 1e-9;    // [m] gaps below −this are projected out
  double contact_margin = 1e-6;           // [m] activation distance (see the active-set rule)
  // Lemke: start from the previous step's solution when the active contacts are unchanged
  // (LcpSolver::solveLemkeWarm); false: every LCP from Lemke's usual start.
  bool warm_start = true;
  // Split a step at the estimated time of impact t* of a contact that is open at its start and
  // predicted to close within it: sub-step to t*, the impact, sub-step over the rest (see above).
  bool locate_impacts = true;
  int pgs_iterations = 500;
  double pgs_tolerance = 1e-12;
};

// A solver failure or a non-finite state: says when, which contacts were active and how far the
// LCP solution was from complementarity.
class SimulationError : public std::runtime_error {
 public:
  SimulationError(const std::string& what, double time, std::vector<std::string> active, double residual)
      : std::runtime_error(what), time(time), active(std::move(active)), residual(residual) {}
  double time;
  std::vector<std::string> active;
  double residual;
};

// What a contact did over the last step (gap and velocities at the end of the step; impulses
// over the step). Tangential quantities are in the surface's basis (t1, t2).
struct ContactReport {
  bool active = false;
  // The point is over its plane's extent and has not gone under it (always, on a world surface or
  // a stop): only then can it touch the plane.
  bool over_plane = true;
  double gap = 0, vn = 0, vt1 = 0, vt2 = 0, pn = 0, pt1 = 0, pt2 = 0;
  double s1 = 0, s2 = 0;  // on a body's plane: the point's plane coordinates (contact::planeCoordinates) [m]
};

struct StepperStats {
  long steps = 0;
  long lcp_solves = 0;
  long lcp_failures = 0;
  long lcp_warm_solves = 0;    // Lemke: contact LCPs solved by the previous step's basis, no pivot
  long located_impacts = 0;    // steps split at an estimated time of impact (locate_impacts)
  int max_lcp_size = 0;
  double max_penetration = 0;  // largest −gap of a point contact after a step (before projection) [m]
  double max_stop_penetration = 0;  // largest −gap of a joint-limit stop after a step (before projection) [rad or m]
  double max_lcp_residual = 0;
};

class TimeStepper {
 public:
  TimeStepper(const Scene& scene, StepperOptions options);

  void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t = 0);
  // Advances by one step; throws SimulationError when the LCP solver fails or the state stops
  // being finite.
  void step();
  // Generalised forces τ (model coordinate order, nv values) held over the following steps until
  // set again, in place of the scene's constant input: a time-varying input is one call per step
  // (e.g. verify/replay.hpp). Copies into the stepper's own vector (no allocation); throws
  // std::invalid_argument for a wrong size or a non-finite value.
  void setInput(const Eigen::VectorXd& tau);
  const Eigen::VectorXd& input() const { return tau_; }

  double time() const { return t_; }
  const Eigen::VectorXd& q() const { return q_; }
  const Eigen::VectorXd& v() const { return v_; }
  const Scene& scene() const { return scene_; }
  const StepperOptions& options() const { return options_; }
  const std::vector<ContactReport>& contacts() const { return reports_; }  // scene contacts, then limits
  const StepperStats& stats() const { return stats_; }
  // Kinetic plus gravitational potential energy of the current state.
  double energy();

 private:
  void linearise(double h);
  double buildRows(double t_next, double h, bool predict);
  void advance(double h);
  void delassus(int rows);
  void applyImpulses(int rows, Eigen::VectorXd& v);
  void solveLcp(int nz, double h);
  void project();
  bool measureContacts();
  // Whether contact c can touch at the current kinematics (data_): within its plane's extent and
  // not under it (under_).
  bool touchable(int c) const;
  std::vector<std::string> activeNames() const;
  std::string lcpRowName(int row) const;  // solveLcp's row: "foot normal", "foot friction 1", "foot cone"

  Eigen::Vector3d surfaceVelocity(const contact::ContactPair& pair, double t) const;

  Scene scene_;
  StepperOptions options_;
  dynamics::Data<double> data_;
  double t_ = 0;
  Eigen::VectorXd q_, v_, q_theta_, v_theta_, v_free_, rhs_, tau_;
  Eigen::MatrixXd L_;  // M(q_θ) = Lᵀ L, branch-sparse (dynamics/ltl.hpp), in the lower triangle
  std::vector<contact::ContactPair> pairs_;  // the contact layer's pairs: scene contacts, then limit stops
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> J_point_;  // per pair: its relative Jacobian, 3 × nv
  // Active rows: normal rows first (contacts then limits), then the friction rows.
  std::vector<int> active_;           // indices into contacts (≥ n_contacts: limits)
  // Per pair: made active in this (sub-)step because the solution without it would pass it (an
  // impulse elsewhere drove it closed: a chain's stops), and whether it has a row now.
  std::vector<char> forced_, in_rows_;
  // Per contact on a body's plane: the point went below the plane's level beyond its edge and has
  // not come above that level since. It is under the body, not in it: it touches nothing, also
  // where it comes back within the extent (a one-sided plate, not a half-space).
  std::vector<char> under_;
  double rows_t_next_ = 0, rows_h_ = 0;  // buildRows' last arguments, for a re-solve
  bool rows_predict_ = false;
  std::vector<double> active_gap_, active_e_;
  std::vector<int> solved_active_;    // active_ of the last contact LCP whose solution z_ holds
  // J_ = [N; D]: the m normal rows, then the f friction rows (each row of J_ is a row of N or D).
  // With M = Lᵀ L (L_), Y_ = L⁻ᵀ J_ᵀ, so the Delassus matrix is W = J M⁻¹ Jᵀ = Yᵀ Y: one sparse
  // substitution per row (a contact's row is zero off its bodies' paths to the root, and stays
  // so) and symmetric by construction; the impulses act through one solve M⁻¹ (Jᵀ z) of a vector.
  Eigen::MatrixXd J_, Y_;                    // (m + f) × nv, nv × (m + f)
  Eigen::VectorXd surface_velocity_;         // d_ij · v_surface for each friction row
  Eigen::VectorXd impulse_;                  // Jᵀ z, then M⁻¹ Jᵀ z
  Eigen::MatrixXd A_;                        // LCP matrix
  Eigen::VectorXd b_, z_, w_;                // LCP vector and solution
  Eigen::VectorXd b_scale_;                  // magnitude of the terms summed into each b_ (round-off scale)
  LcpSolver solver_;
  int m_ = 0, f_ = 0;                        // active normal rows, friction rows
  std::vector<ContactReport> reports_;
  StepperStats stats_;
  double restitution_threshold_;
};

}  // namespace saltus::timestepper
