#include "timestepper/sticking_motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "contact/kinematics.hpp"
#include "dynamics/dynamics.hpp"

namespace saltus::timestepper::exact {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kQuadratureStep = 1e-4;  // [s] RK4 step of the rod's pivot equation
constexpr int kBisections = 50;

// The first time in (t_lo, t_hi] where violated(t) holds, given that it does at t_hi and not at
// t_lo, to round-off (bisection).
template <class F>
double bisect(double t_lo, double t_hi, const F& violated) {
  for (int k = 0; k < kBisections && t_hi - t_lo > 1e-15 * std::max(1.0, t_hi); ++k) {
    const double t = 0.5 * (t_lo + t_hi);
    (violated(t) ? t_hi : t_lo) = t;
  }
  return t_hi;
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Painlevé's rod

PainleveRodMotion::PainleveRodMotion(double half_length, double angle, double speed, double mu, double g)
    : l_(half_length), theta0_(angle), u_(speed), mu_(mu), g_(g) {
  if (!(half_length > 0) || !(speed > 0) || !(g > 0) || !(mu >= 0))
    throw std::invalid_argument("Painlevé rod: half_length, speed and g must be positive and mu non-negative");
  if (!(angle > 0 && angle < std::numbers::pi / 2))
    throw std::invalid_argument("Painlevé rod: the angle to the ground must lie in (0, pi/2), got " +
                                std::to_string(angle));
}

double PainleveRodMotion::paradoxCoefficient() const {
  const double c = std::cos(theta0_), s = std::sin(theta0_);
  return 1 + 3 * c * c - 3 * mu_ * s * c;
}

Eigen::Vector2d PainleveRodMotion::impulsePerMass() const {
  const double c = std::cos(theta0_), s = std::sin(theta0_);
  return {-u_ * (1 + 3 * c * c) / 4, 3 * u_ * s * c / 4};
}

// (θ, θ̇) from time t0 to t1 by classical RK4 in equal steps of at most kQuadratureStep.
void PainleveRodMotion::integrate(double& theta, double& theta_dot, double t0, double t1) const {
  const int n = static_cast<int>(std::ceil((t1 - t0) / kQuadratureStep));
  const double h = n > 0 ? (t1 - t0) / n : 0;
  for (int k = 0; k < n; ++k) {
    const double k1t = theta_dot, k1w = pivotAcceleration(theta);
    const double k2t = theta_dot + h / 2 * k1w, k2w = pivotAcceleration(theta + h / 2 * k1t);
    const double k3t = theta_dot + h / 2 * k2w, k3w = pivotAcceleration(theta + h / 2 * k2t);
    const double k4t = theta_dot + h * k3w, k4w = pivotAcceleration(theta + h * k3t);
    theta += h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
    theta_dot += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
  }
}

PainleveRodMotion::State PainleveRodMotion::stateOf(double theta, double theta_dot) const {
  State out;
  out.theta = theta;
  out.theta_dot = theta_dot;
  const double c = std::cos(theta), s = std::sin(theta), a = pivotAcceleration(theta);
  out.force_t = l_ * (c * theta_dot * theta_dot + s * a);
  out.force_n = g_ - l_ * s * theta_dot * theta_dot + l_ * c * a;
  return out;
}

PainleveRodMotion::State PainleveRodMotion::at(double t) const {
  if (!(t >= 0)) throw std::invalid_argument("Painlevé rod: time must be non-negative");
  double theta = theta0_, theta_dot = 3 * u_ * std::sin(theta0_) / (4 * l_);  // just after the stop
  integrate(theta, theta_dot, 0, t);
  return stateOf(theta, theta_dot);
}

double PainleveRodMotion::stickEnd(double t_max, double check_dt) const {
  if (!stopsByImpulse()) return 0;
  const auto outside = [&](const State& st) { return st.force_n < 0 || std::abs(st.force_t) > mu_ * st.force_n; };
  double theta = theta0_, theta_dot = 3 * u_ * std::sin(theta0_) / (4 * l_);
  if (outside(stateOf(theta, theta_dot))) return 0;
  double t_prev = 0;
  for (int k = 1;; ++k) {  // march, then bisect the first interval that ends outside
    const double t = std::min(k * check_dt, t_max);
    integrate(theta, theta_dot, t_prev, t);
    if (outside(stateOf(theta, theta_dot))) return bisect(t_prev, t, [&](double tb) { return outside(at(tb)); });
    if (t >= t_max) return kInf;
    t_prev = t;
  }
}

Eigen::Matrix<double, 6, 1> PainleveRodMotion::planarState(double t, double x0, double z_ground) const {
  const State st = at(t);
  const double c = std::cos(st.theta), s = std::sin(st.theta);
  const double x_end = x0 + l_ * std::cos(theta0_);  // the stuck end
  Eigen::Matrix<double, 6, 1> x;
  x << x_end - l_ * c, z_ground + l_ * s, st.theta, l_ * s * st.theta_dot, l_ * c * st.theta_dot, st.theta_dot;
  return x;
}

// ---------------------------------------------------------------------------------------------
// A two-coordinate mechanism stuck to a belt

namespace {
const scene::Scene& checkedBeltScene(const scene::Scene& s) {
  const std::string what = "scene '" + s.name + "': the belt-sticking motion needs ";
  if (s.model.nv() != 2) throw std::invalid_argument(what + "two coordinates, not " + std::to_string(s.model.nv()));
  if (s.contacts.size() != 1) throw std::invalid_argument(what + "exactly one contact");
  if (!s.limits.empty()) throw std::invalid_argument(what + "no limit stops");
  if (s.contacts[0].directions == 0 || !(s.contacts[0].friction > 0))
    throw std::invalid_argument(what + "a contact with friction");
  const scene::Surface& surface = s.surfaces[s.contacts[0].surface];
  if (std::abs(surface.normal.y()) > 1e-12) throw std::invalid_argument(what + "a surface normal in the x-z plane");
  for (const scene::Surface::Step& step : surface.velocity_schedule)
    if (std::abs(step.velocity.dot(surface.normal)) > 1e-12 || std::abs(step.velocity.y()) > 1e-12)
      throw std::invalid_argument(what + "a belt moving along the surface in the x-z plane");
  if (s.v0.norm() > 1e-12) throw std::invalid_argument(what + "the mechanism at rest at t = 0");
  return s;
}

// A⁻¹ b for a 2 × 2 matrix (Cramer's rule); a singular A (the point Jacobian loses rank: the
// mechanism is stretched out) throws.
Eigen::Vector2d solve2(const Eigen::Matrix2d& A, const Eigen::Vector2d& b) {
  const double det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  if (!(std::abs(det) > 1e-12 * A.squaredNorm()))
    throw std::runtime_error("belt-sticking motion: the contact point's Jacobian is singular");
  return Eigen::Vector2d(A(1, 1) * b[0] - A(0, 1) * b[1], A(0, 0) * b[1] - A(1, 0) * b[0]) / det;
}
}  // namespace

BeltStickingMotion::BeltStickingMotion(const scene::Scene& scene)
    : scene_(checkedBeltScene(scene)),
      pair_(contact::contactPairs(scene_).front()),
      surface_(scene_.surfaces[pair_.surface]),
      t1_(surface_.tangents().col(0)),
      data_(scene_.model) {
  dynamics::forwardKinematics(scene_.model, data_, scene_.q0);
  p0_ = contact::contactPoint(pair_, data_);
  const double gap = contact::gap(pair_, data_, scene_.q0.data());
  if (std::abs(gap) > 1e-9)
    throw std::invalid_argument("scene '" + scene_.name + "': the contact point must start on the surface (gap " +
                                std::to_string(gap) + " m)");
  Eigen::Matrix3Xd J(3, 2);
  contact::relativeJacobian(scene_.model, data_, pair_, J);
  if (J.row(1).norm() > 1e-12)  // y: the mechanism must move in the x–z plane
    throw std::invalid_argument("scene '" + scene_.name + "': the contact point leaves the x-z plane");
}

Eigen::Matrix2d BeltStickingMotion::constraintRows(const Eigen::VectorXd& q) const {
  dynamics::forwardKinematics(scene_.model, data_, q);
  Eigen::Matrix3Xd J(3, 2);
  contact::relativeJacobian(scene_.model, data_, pair_, J);
  Eigen::Matrix2d A;
  A << t1_.transpose() * J, surface_.normal.transpose() * J;
  return A;
}

Eigen::VectorXd BeltStickingMotion::positionsAt(double t) const {
  const Eigen::Vector3d d = surface_.displacement(t);
  // Continuation from q0 in belt moves of at most 5 mm keeps Newton on the initial branch.
  const int moves = std::max(1, static_cast<int>(std::ceil(d.norm() / 5e-3)));
  Eigen::VectorXd q = scene_.q0;
  for (int j = 1; j <= moves; ++j) {
    const Eigen::Vector3d target = p0_ + d * (static_cast<double>(j) / moves);
    bool converged = false;
    for (int it = 0; it < 50 && !converged; ++it) {
      const Eigen::Matrix2d A = constraintRows(q);  // leaves the kinematics at q
      const Eigen::Vector3d r = target - contact::contactPoint(pair_, data_);
      const Eigen::Vector2d r2(t1_.dot(r), surface_.normal.dot(r));
      converged = r2.norm() < 1e-13;
      if (!converged) {
        const Eigen::Vector2d dq = solve2(A, r2);
        q[0] += dq[0];
        q[1] += dq[1];
      }
    }
    if (!converged || !q.allFinite())
      throw std::runtime_error("scene '" + scene_.name + "': the contact point cannot follow the belt at t = " +
                               std::to_string(t) + " s (no configuration reaches it)");
  }
  return q;
}

Eigen::VectorXd BeltStickingMotion::state(double t) const {
  const Eigen::VectorXd q = positionsAt(t);
  const Eigen::Matrix2d A = constraintRows(q);
  const Eigen::Vector2d rhs(t1_.dot(surface_.velocity(t)), 0.0);
  Eigen::VectorXd x(4);
  x << q, solve2(A, rhs);
  return x;
}

Eigen::Vector2d BeltStickingMotion::contactForce(double t) const {
  const Eigen::VectorXd x = state(t);
  const Eigen::VectorXd q = x.head(2), v = x.tail(2);
  const dynamics::Model<double>& model = scene_.model;
  dynamics::forwardKinematics(model, data_, q, v);
  const Eigen::Vector3d bias = dynamics::pointAccelerationBias(data_, pair_.body_a, pair_.point_A);  // J̇ q̇ (a world plane)
  const Eigen::Matrix2d A = constraintRows(q);
  const Eigen::Vector2d qdd = -solve2(A, Eigen::Vector2d(t1_.dot(bias), surface_.normal.dot(bias)));
  const Eigen::MatrixXd M = dynamics::crba(model, data_, q);
  const Eigen::VectorXd h = dynamics::nonLinearEffects(model, data_, q, v);
  const Eigen::Vector2d generalised = M * qdd + h - scene_.tau;
  return solve2(A.transpose(), generalised);
}

Eigen::Vector2d BeltStickingMotion::stepImpulse(double t_step) const {
  const Eigen::VectorXd q = positionsAt(t_step);
  const Eigen::Matrix2d A = constraintRows(q);
  const Eigen::Vector2d dv_point(t1_.dot(surface_.velocity(t_step) - surface_.velocityBefore(t_step)), 0.0);
  const Eigen::Vector2d dqd = solve2(A, dv_point);
  const Eigen::MatrixXd M = dynamics::crba(scene_.model, data_, q);
  return solve2(A.transpose(), M * dqd);
}

bool BeltStickingMotion::insideCone(const Eigen::Vector2d& f) const {
  return f[1] >= 0 && std::abs(f[0]) <= pair_.friction * f[1];
}

double BeltStickingMotion::stickEnd(double t_max, double check_dt) const {
  // The belt steps within [0, t_max] (an impulse each), then the forces between them.
  std::vector<double> steps;
  for (const scene::Surface::Step& s : surface_.velocity_schedule)
    if (s.time >= 0 && s.time <= t_max && (surface_.velocity(s.time) - surface_.velocityBefore(s.time)).norm() > 0)
      steps.push_back(s.time);
  const auto violated = [&](double t) { return !insideCone(contactForce(t)); };
  double t_prev = 0;
  std::size_t next_step = 0;
  if (violated(0)) return 0;
  for (int k = 1;; ++k) {
    const double t = std::min(k * check_dt, t_max);
    while (next_step < steps.size() && steps[next_step] <= t) {
      if (!insideCone(stepImpulse(steps[next_step]))) return steps[next_step];
      ++next_step;
    }
    if (violated(t)) return bisect(t_prev, t, violated);
    if (t >= t_max) return kInf;
    t_prev = t;
  }
}

}  // namespace saltus::timestepper::exact
