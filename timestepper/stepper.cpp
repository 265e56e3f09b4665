#include "timestepper/stepper.hpp"

#include "contact/initial_state.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "contact/kinematics.hpp"
#include "dynamics/configuration.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/ltl.hpp"
#include "dynamics/rnea.hpp"

namespace saltus::timestepper {
namespace {

// When a contact that is open at the start of a step (gap g0 > 0, normal velocity vn) closes
// within it: the earliest root in (0, h] of the gap model g(t) = g0 + vn t + c t², with c fitted
// to the step's predicted end gap g(h) = g_end, or h when the model has no root there (it closes
// within the margin at the end, or only grazes). A θ-step of length t from a body with constant
// normal acceleration a_n ends at g0 + vn t + θ a_n t² (q_θ + θ t v*, v* = v + t a_n), the model
// with c = θ a_n: a sub-step of length t* lands on the surface, at the approach velocity
// vn + a_n t* = vn + c t*/θ. +∞ when that approach is slower than `threshold` (the impact would be
// inelastic, which the step's own gap term already places at the step's end: no split).
double impactTime(double g0, double vn, double g_end, double h, double theta, double threshold) {
  const double c = (g_end - g0 - vn * h) / (h * h);
  const double discriminant = vn * vn - 4 * c * g0;
  double t = h;
  const double denominator = -vn + std::sqrt(std::max(discriminant, 0.0));
  if (discriminant >= 0 && denominator > 0) {  // 2 g0 / denominator: the smaller positive root,
    const double root = 2 * g0 / denominator;  // without cancellation
    if (root > 0 && root < h) t = root;
  }
  return vn + c * t / theta < -threshold ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

TimeStepper::TimeStepper(const Scene& scene, StepperOptions options)
    : scene_(scene), options_(options), data_(scene_.model), solver_(0) {
  const int nv = scene_.model.nv();
  if (!(options_.dt > 0)) throw std::invalid_argument("time step must be positive");
  if (options_.theta < 0.5 || options_.theta > 1) throw std::invalid_argument("theta must lie in [0.5, 1]");
  contact::checkInitialState(scene_, scene_.initial_location.empty() ? scene_.name : scene_.initial_location);
  pairs_ = contact::contactPairs(scene_);
  int f_max = 0, lambda_max = 0;
  for (const contact::ContactPair& p : pairs_) {
    f_max += p.k();
    lambda_max += p.k() > 0;
  }
  const int m_max = static_cast<int>(pairs_.size());
  const int nz_max = m_max + f_max + lambda_max;
  q_ = scene_.q0;
  v_ = scene_.v0;
  q_theta_.resize(scene_.model.nq());
  v_theta_.resize(nv);
  v_free_.resize(nv);
  rhs_.resize(nv);
  tau_ = scene_.tau.size() == nv ? scene_.tau : Eigen::VectorXd::Zero(nv);
  J_point_.assign(pairs_.size(), Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, nv));
  active_.reserve(m_max);
  solved_active_.reserve(m_max);
  active_gap_.reserve(m_max);
  active_e_.reserve(m_max);
  J_.resize(m_max + f_max, nv);
  Y_.resize(nv, m_max + f_max);
  L_.resize(nv, nv);
  impulse_.resize(nv);
  surface_velocity_.resize(f_max);
  A_.setZero(nz_max, nz_max);
  b_.resize(nz_max);
  b_scale_.resize(nz_max);
  z_.resize(nz_max);
  w_.resize(nz_max);
  solver_ = LcpSolver(nz_max);
  reports_.assign(pairs_.size(), ContactReport{});
  forced_.assign(pairs_.size(), 0);
  in_rows_.assign(pairs_.size(), 0);
  under_.assign(pairs_.size(), 0);
  measureContacts();
  stats_.max_penetration = stats_.max_stop_penetration = 0;
  const double g = scene_.model.gravity.norm();
  restitution_threshold_ = options_.restitution_threshold >= 0 ? options_.restitution_threshold : 2 * g * options_.dt;
}

void TimeStepper::reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) {
  q_ = q;
  v_ = v;
  t_ = t;
  for (ContactReport& r : reports_) r = ContactReport{};
  std::fill(under_.begin(), under_.end(), 0);
  solved_active_.clear();
  measureContacts();
  stats_ = StepperStats{};
}

void TimeStepper::setInput(const Eigen::VectorXd& tau) {
  if (tau.size() != tau_.size())
    throw std::invalid_argument("TimeStepper::setInput: " + std::to_string(tau.size()) + " values for " +
                                std::to_string(tau_.size()) + " coordinates");
  if (!tau.allFinite()) throw std::invalid_argument("TimeStepper::setInput: the input is not finite");
  tau_ = tau;  // same size: Eigen copies without reallocating
}

// The material velocity of a pair's world plane at time t (a belt's schedule); zero otherwise.
Eigen::Vector3d TimeStepper::surfaceVelocity(const contact::ContactPair& pair, double t) const {
  if (pair.isStop() || pair.body_b >= 0 || pair.surface < 0) return Eigen::Vector3d::Zero();
  return scene_.surfaces[pair.surface].velocity(t);
}

double TimeStepper::energy() {
  dynamics::forwardKinematics(scene_.model, data_, q_, v_);
  return dynamics::kineticEnergy(scene_.model, data_) + dynamics::potentialEnergy(scene_.model, data_);
}

// Active normal rows (contacts, then limit stops) into the top of J_, their friction rows below,
// for a (sub-)step of length h ending at t_next. Needs the kinematics and v_free_ at q_θ.
// predict: a contact is also active when its predicted gap at the end of the step is within the
// margin (the active-set rule); false for the sub-step that ends at a located impact (the contacts
// that close there are resolved by the impact) and for the impact itself (h = 0).
// Returns the earliest estimated time of impact, in (0, h], of the contacts that are open at the
// start of the step (gap > margin in reports_) and predicted to close within it faster than the
// restitution threshold (impactTime), or +∞ when there is none or `predict` is false.
double TimeStepper::buildRows(double t_next, double h, bool predict) {
  const dynamics::Model<double>& model = scene_.model;
  const double th_h = options_.theta * h;
  const double margin = options_.contact_margin;
  double t_close = std::numeric_limits<double>::infinity();
  rows_t_next_ = t_next;
  rows_h_ = h;
  rows_predict_ = predict;
  active_.clear();
  active_gap_.clear();
  active_e_.clear();
  m_ = f_ = 0;
  for (int c = 0; c < static_cast<int>(pairs_.size()); ++c) {
    const contact::ContactPair& pair = pairs_[c];
    const double gap = contact::gap(pair, data_, q_theta_.data());
    double vn_free;
    Eigen::Vector3d normal;
    if (pair.isStop()) {
      vn_free = pair.sign * v_free_[pair.coordinate];
    } else {
      contact::relativeJacobian(model, data_, pair, J_point_[c]);
      normal = contact::planeNormal(pair, data_);
      vn_free = normal.dot(J_point_[c] * v_free_);
    }
    const double gap_end = gap + th_h * vn_free;
    if (!forced_[c] && gap > margin && (!predict || gap_end > margin)) continue;
    if (!touchable(c)) continue;  // beyond a body's plane or under it: touches nothing
    const double vn = pair.isStop() ? pair.sign * v_[pair.coordinate] : normal.dot(J_point_[c] * v_);
    if (predict && reports_[c].gap > margin)  // open at the start, closing within the step
      t_close = std::min(t_close, impactTime(reports_[c].gap, reports_[c].vn, gap_end, h, options_.theta,
                                             restitution_threshold_));
    active_.push_back(c);
    active_gap_.push_back(gap);
    active_e_.push_back(vn < -restitution_threshold_ ? pair.restitution : 0.0);
    if (pair.isStop()) {
      J_.row(m_).setZero();
      J_(m_++, pair.coordinate) = pair.sign;
    } else {
      J_.row(m_++).noalias() = normal.transpose() * J_point_[c];
    }
  }
  for (int r = 0; r < m_; ++r) {
    const int c = active_[r];
    const contact::ContactPair& pair = pairs_[c];
    if (pair.k() == 0) continue;
    const Eigen::Vector3d v_surface = surfaceVelocity(pair, t_next);
    for (int j = 0; j < pair.k(); ++j) {
      const Eigen::Vector3d d = contact::frictionDirection(pair, data_, j);
      J_.row(m_ + f_).noalias() = d.transpose() * J_point_[c];
      surface_velocity_[f_++] = d.dot(v_surface);
    }
  }
  return t_close;
}

// Y = L⁻¹ Jᵀ for the first `rows` rows of J, and the Delassus matrix W = J M⁻¹ Jᵀ = Yᵀ Y into
// the top-left corner of A_, lower triangle mirrored. Needs L_.
void TimeStepper::delassus(int rows) {
  const dynamics::Model<double>& model = scene_.model;
  const int nv = model.nv();
  for (int r = 0; r < rows; ++r) {
    double* const y = &Y_(0, r);
    for (int i = 0; i < nv; ++i) y[i] = J_(r, i);
    dynamics::solveLtlTranspose(model, L_, y);  // zero off the contact's paths to the root
  }
  for (int j = 0; j < rows; ++j)
    for (int i = j; i < rows; ++i) A_(i, j) = A_(j, i) = Y_.col(i).dot(Y_.col(j));
}

// v += M⁻¹ Jᵀ z for the first `rows` rows of J and entries of z_.
void TimeStepper::applyImpulses(int rows, Eigen::VectorXd& v) {
  impulse_.noalias() = J_.topRows(rows).transpose() * z_.head(rows);
  dynamics::solveMassLtl(scene_.model, L_, impulse_.data());
  v += impulse_;
}

// Assembles and solves the LCP in z = (p_n, β, λ) of a (sub-)step of length h (h = 0: an impact,
// velocities only); throws on failure. Needs J_ and L_.
void TimeStepper::solveLcp(int nz, double h) {
  const int m = m_, f = f_;
  auto A = A_.topLeftCorner(nz, nz);
  A.rightCols(nz - m - f).setZero();
  A.bottomLeftCorner(nz - m - f, m + f).setZero();
  delassus(m + f);  // W = [N; D] M⁻¹ [N; D]ᵀ
  b_.head(m + f).noalias() = J_.topRows(m + f) * v_free_;
  for (int r = 0; r < m; ++r) {
    if (active_e_[r] > 0)  // impact: v_n⁺ ≥ −e v_n + (v_n* − v_n), i.e. w = W p + (1 + e) v_n
      b_[r] = (1 + active_e_[r]) * J_.row(r).dot(v_);
    else if (active_gap_[r] > 0 && h > 0)  // + gap/(θh): an open gap may close within the step
      b_[r] += active_gap_[r] / (options_.theta * h);
  }
  if (f > 0) b_.segment(m, f) -= surface_velocity_.head(f);
  // Round-off scale of b: Σ_j |J_rj| |v_j| and the other terms' magnitudes (cone rows: 0).
  b_scale_.head(nz).setZero();
  for (int r = 0; r < m + f; ++r) {
    const bool impact = r < m && active_e_[r] > 0;
    const Eigen::VectorXd& v = impact ? v_ : v_free_;
    double s = 0;
    for (int j = 0; j < J_.cols(); ++j) s += std::abs(J_(r, j)) * std::abs(v[j]);
    if (impact) s *= 1 + active_e_[r];
    else if (r < m && active_gap_[r] > 0 && h > 0) s += active_gap_[r] / (options_.theta * h);
    if (r >= m) s += std::abs(surface_velocity_[r - m]);
    b_scale_[r] = s;
  }
  // Cone rows: E couples β_ij to λ_i, μ p_n − Σ β ≥ 0.
  int row = m + f, col = m;
  for (int r = 0; r < m; ++r) {
    const contact::ContactPair& pair = pairs_[active_[r]];
    const int k = pair.k();
    if (k == 0) continue;
    for (int j = 0; j < k; ++j) {
      A(col + j, row) = 1.0;             // β rows: + λ
      A(row, col + j) = -1.0;            // λ row: − Σ β
    }
    A(row, r) = pair.friction;
    b_[row] = 0;
    ++row;
    col += k;
  }
  LcpResult result;
  auto z = z_.head(nz);
  auto w = w_.head(nz);
  if (options_.solver == LcpMethod::Lemke) {
    // The previous step's solution is a guess for the same active contacts (z_ still holds it).
    if (options_.warm_start && active_ == solved_active_) {
      result = solver_.solveLemkeWarm(A, b_.head(nz), z, w, 0, &b_scale_);
      stats_.lcp_warm_solves += result.status == LcpStatus::Solved && result.iterations == 0;
    } else
      result = solver_.solveLemke(A, b_.head(nz), z, w, 0, &b_scale_);
    solved_active_ = active_;
  } else {
    z.setZero();
    result = solver_.solvePgs(A, b_.head(nz), z, w, options_.pgs_iterations, options_.pgs_tolerance);
  }
  ++stats_.lcp_solves;
  stats_.max_lcp_size = std::max(stats_.max_lcp_size, nz);
  stats_.max_lcp_residual = std::max(stats_.max_lcp_residual, result.residual);
  if (result.status != LcpStatus::Solved) {
    ++stats_.lcp_failures;
    std::ostringstream msg;
    msg << "LCP solver (" << (options_.solver == LcpMethod::Lemke ? "lemke" : "pgs") << ") failed at t = " << t_
        << " s: " << toString(result.status) << " after " << result.iterations << " iterations, residual "
        << result.residual << ", LCP size " << nz;
    if (result.rejected_row >= 0)
      msg << ", the acceptance check refused row " << result.rejected_row << " (" << lcpRowName(result.rejected_row)
          << "): w = " << result.rejected_w << " where " << (z[result.rejected_row] > 0 ? "0" : "w >= 0")
          << " was required to within " << result.rejected_allowance;
    msg << ", active contacts:";
    for (const std::string& name : activeNames()) msg << " " << name;
    throw SimulationError(msg.str(), t_, activeNames(), result.residual);
  }
}

// solveLcp's layout: the m normal rows of the active pairs, their friction directions (f rows),
// then one cone row per frictional pair.
std::string TimeStepper::lcpRowName(int row) const {
  if (row < m_) return pairs_[active_[row]].name + " normal";
  int friction = m_, cone = m_ + f_;
  for (int r = 0; r < m_; ++r) {
    const contact::ContactPair& pair = pairs_[active_[r]];
    if (pair.k() == 0) continue;
    if (row >= friction && row < friction + pair.k()) return pair.name + " friction " + std::to_string(row - friction);
    if (row == cone) return pair.name + " cone";
    friction += pair.k();
    ++cone;
  }
  return "row " + std::to_string(row);
}

std::vector<std::string> TimeStepper::activeNames() const {
  std::vector<std::string> names;
  for (int c : active_) names.push_back(pairs_[c].name);
  return names;
}

// Removes penetration beyond the tolerance by the smallest change of q in the metric M:
// min ½ Δqᵀ M Δq subject to gap + N Δq ≥ 0, i.e. the LCP (N M⁻¹ Nᵀ, gap) with Δq = M⁻¹ Nᵀ p.
// Velocities are left as they are.
void TimeStepper::project() {
  const dynamics::Model<double>& model = scene_.model;
  m_ = 0;
  active_.clear();
  for (int c = 0; c < static_cast<int>(pairs_.size()); ++c) {
    if (reports_[c].gap >= -options_.penetration_tolerance || !reports_[c].over_plane) continue;
    contact::normalRow(model, data_, pairs_[c], J_.row(m_));
    b_[m_++] = reports_[c].gap;
    active_.push_back(c);
  }
  if (m_ == 0) return;
  solved_active_.clear();  // z_ is about to hold the projection's solution
  delassus(m_);  // N M⁻¹ Nᵀ
  auto A = A_.topLeftCorner(m_, m_);
  auto z = z_.head(m_);
  auto w = w_.head(m_);
  const LcpResult result = solver_.solveLemke(A, b_.head(m_), z, w);
  if (result.status != LcpStatus::Solved) {
    ++stats_.lcp_failures;
    throw SimulationError("position projection LCP failed at t = " + std::to_string(t_) + " s: " +
                              toString(result.status) + ", residual " + std::to_string(result.residual),
                          t_, activeNames(), result.residual);
  }
  impulse_.noalias() = J_.topRows(m_).transpose() * z_.head(m_);
  dynamics::solveMassLtl(model, L_, impulse_.data());
  dynamics::integrate(model, q_, impulse_, 1.0, q_);  // q ⊕ Δ, Δ = M⁻¹ Nᵀ p
}

bool TimeStepper::touchable(int c) const { return !under_[c] && contact::withinExtent(pairs_[c], data_); }

// Gaps and relative velocities of every contact and stop at the current state; returns whether
// any gap is below −penetration_tolerance.
bool TimeStepper::measureContacts() {
  const dynamics::Model<double>& model = scene_.model;
  dynamics::forwardVelocities(model, data_, q_, v_);  // poses and velocities: no J̇v needed
  bool penetrating = false;
  for (int c = 0; c < static_cast<int>(pairs_.size()); ++c) {
    const contact::ContactPair& pair = pairs_[c];
    ContactReport& r = reports_[c];
    r.gap = contact::gap(pair, data_, q_.data());
    if (pair.isStop()) {
      r.vn = contact::normalVelocity(pair, data_, v_.data());
    } else {
      const Eigen::Vector3d v_frame = contact::frameVelocity(pair, data_, surfaceVelocity(pair, t_));
      r.vn = v_frame[0];
      r.vt1 = v_frame[1];
      r.vt2 = v_frame[2];
    }
    r.over_plane = true;
    if (contact::hasExtent(pair)) {
      const Eigen::Vector2d s = contact::planeCoordinates(pair, data_);
      r.s1 = s[0];
      r.s2 = s[1];
      // Below the plane's level beyond its edge, the point is under the body until it is above
      // that level again; coming back within the extent from below does not put it on top.
      const bool within = contact::withinExtent(pair, s);
      if (r.gap >= 0)
        under_[c] = 0;
      else if (!within && r.gap < -options_.penetration_tolerance)
        under_[c] = 1;
      r.over_plane = within && !under_[c];
    }
    if (!r.over_plane) continue;  // below a body's plane but beyond its edge or under it: not a penetration
    penetrating |= r.gap < -options_.penetration_tolerance;
    double& largest = pair.isStop() ? stats_.max_stop_penetration : stats_.max_penetration;  // rad or m / m
    largest = std::max(largest, -r.gap);
  }
  return penetrating;
}

// The θ-method's linearisation for a (sub-)step of length h from (q_, v_): q_θ, M(q_θ) and its
// Cholesky factor, the kinematics at q_θ and the free velocity v* (h = 0: v* = v, at q).
void TimeStepper::linearise(double h) {
  const dynamics::Model<double>& model = scene_.model;
  const double theta = options_.theta;
  dynamics::integrate(model, q_, v_, (1 - theta) * h, q_theta_);  // q_θ = q ⊕ (1 − θ) h v
  dynamics::forwardKinematics(model, data_, q_theta_);  // the world poses used below
  dynamics::crba(model, data_, q_theta_);  // with the joint transforms reused by h below
  L_ = data_.M;  // same size: no allocation
  if (!dynamics::factorLtl(model, L_))
    throw SimulationError("mass matrix is not positive definite at t = " + std::to_string(t_) + " s", t_, {}, 0);
  rhs_ = tau_ - dynamics::nonLinearEffectsAtCurrentPoses(model, data_, v_);
  dynamics::solveMassLtl(model, L_, rhs_.data());
  if (theta < 1) {  // forces at the predicted v_θ
    v_theta_ = v_ + (1 - theta) * h * rhs_;
    rhs_ = tau_ - dynamics::nonLinearEffectsAtCurrentPoses(model, data_, v_theta_);
    dynamics::solveMassLtl(model, L_, rhs_.data());
  }
  v_free_ = v_ + h * rhs_;
}

// Completes a (sub-)step of length h linearised by linearise(h), with the rows of buildRows: the
// contact LCP, v⁺ and q⁺ = q_θ + θ h v⁺ into (q_, v_); the impulses are added to the reports.
void TimeStepper::advance(double h) {
  Eigen::VectorXd& v_next = rhs_;  // reuse storage: v⁺
  // The rows were chosen by the free motion; an impulse on one row can drive another contact
  // closed within the step (a chain striking several stops): such a contact gets a row and the
  // LCP is solved again, until none is passed (a few rounds at most).
  for (int round = 0;; ++round) {
    v_next = v_free_;
    if (m_ == 0) break;
    int n_lambda = 0;
    for (int r = 0; r < m_; ++r) n_lambda += pairs_[active_[r]].k() > 0;
    solveLcp(m_ + f_ + n_lambda, h);
    applyImpulses(m_ + f_, v_next);  // v⁺ = v* + M⁻¹ (Nᵀ p_n + Dᵀ β)
    if (h <= 0 || round == 8) break;
    std::fill(in_rows_.begin(), in_rows_.end(), 0);
    for (int r = 0; r < m_; ++r) in_rows_[active_[r]] = 1;
    bool passed = false;
    for (int c = 0; c < static_cast<int>(pairs_.size()); ++c) {
      if (in_rows_[c] || !touchable(c)) continue;
      const contact::ContactPair& pair = pairs_[c];
      const double vn = pair.isStop() ? pair.sign * v_next[pair.coordinate]
                                      : contact::planeNormal(pair, data_).dot(J_point_[c] * v_next);
      if (contact::gap(pair, data_, q_theta_.data()) + options_.theta * h * vn < -options_.penetration_tolerance) {
        forced_[c] = 1;
        passed = true;
      }
    }
    if (!passed) break;
    buildRows(rows_t_next_, rows_h_, rows_predict_);
  }
  std::fill(forced_.begin(), forced_.end(), 0);
  if (m_ > 0) {
    // Impulses per contact, tangential ones in the surface basis.
    int fr = m_;
    for (int r = 0; r < m_; ++r) {
      const int c = active_[r];
      reports_[c].active = true;
      reports_[c].pn += z_[r];
      const contact::ContactPair& pair = pairs_[c];
      if (pair.k() == 0) continue;
      Eigen::Vector3d pt_B = Eigen::Vector3d::Zero();  // in the plane's body coordinates
      for (int j = 0; j < pair.k(); ++j) pt_B += z_[fr++] * pair.directions_B.col(j);
      reports_[c].pt1 += pt_B.dot(pair.tangents_B.col(0));
      reports_[c].pt2 += pt_B.dot(pair.tangents_B.col(1));
    }
  }
  v_ = v_next;
  dynamics::integrate(scene_.model, q_theta_, v_, options_.theta * h, q_);  // q⁺ = q_θ ⊕ θ h v⁺
}

void TimeStepper::step() {
  const dynamics::Model<double>& model = scene_.model;
  const double h = options_.dt;
  for (ContactReport& r : reports_) {
    r.active = false;
    r.pn = r.pt1 = r.pt2 = 0;
  }
  linearise(h);
  const double t_close = buildRows(t_ + h, h, true);
  if (options_.locate_impacts && t_close <= h) {
    // A contact open at the start closes at t* within the step: free (or constrained by the
    // contacts already closed) motion to t*, the impact there with the approach velocity at t*,
    // then the rest of the step (see the header).
    ++stats_.located_impacts;
    linearise(t_close);
    buildRows(t_ + t_close, t_close, false);
    advance(t_close);
    linearise(0);
    buildRows(t_ + t_close, 0, false);
    advance(0);
    if (t_close < h) {
      linearise(h - t_close);
      buildRows(t_ + h, h - t_close, true);
      advance(h - t_close);
    }
  } else {
    advance(h);
  }
  t_ += h;
  ++stats_.steps;
  if (!q_.allFinite() || !v_.allFinite())
    throw SimulationError("state is not finite at t = " + std::to_string(t_) + " s", t_, activeNames(), 0);

  // Gaps and relative velocities at the end of the step; then remove drift.
  const bool penetrating = measureContacts();
  if (penetrating) {
    project();
    dynamics::forwardKinematics(model, data_, q_);
    for (int c = 0; c < static_cast<int>(pairs_.size()); ++c) reports_[c].gap = contact::gap(pairs_[c], data_, q_.data());
  }
}

}  // namespace saltus::timestepper
