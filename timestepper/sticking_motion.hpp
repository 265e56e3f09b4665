// Exact motions of the two validation scenes that an impact without collision resolves
// (Champneys & Várkonyi, "The Painlevé paradox in contact mechanics", IMA J. Appl. Math. 2016;
// Shield, Johnson & Patel, IEEE T-RO 2023, §II.A and §IV.A): a tangential impulse stops the slip,
// and while the contact then sticks the motion follows from kinematics and the equations of motion
// alone, with no contact solver involved. These are the reference answers against which both
// engines are measured (`saltus bench`, tests/verify). Each motion also checks that sticking is
// consistent: the impulse and every later contact force inside the Coulomb cone, the normal
// force non-negative; stickEnd() says until when.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "contact/pair.hpp"
#include "dynamics/data.hpp"
#include "scene/scene.hpp"

namespace saltus::timestepper::exact {

// Painlevé's rod (scene painleve_rod): uniform, half-length l, inertia m l²/3 about its centre
// across the rod, its lower end on the ground at angle θ0 sliding forward (end leading) at speed u,
// no spin. The impulse (P_t, P_n) at the end that leaves it at rest, from the momentum and the
// angular momentum about the centre:
//   P_t = −m u (1 + 3cos²θ0)/4,   P_n = 3 m u sinθ0 cosθ0/4,
//   (ẋ, ż, θ̇)⁺ = (3u/4) (sin²θ0, sinθ0 cosθ0, sinθ0/l)
// (x along the slide, z up, θ the angle between rod and ground). It lies in the cone
// |P_t| ≤ μ P_n iff B = 1 + 3cos²θ0 − 3μ sinθ0 cosθ0 ≤ 0: exactly Painlevé's condition, so the
// inconsistent case (B < 0 with A = −g < 0) ends by this impulse. Afterwards the rod pivots
// about its stuck end, (4/3) m l² θ̈ = −m g l cos θ, with the force at the end
//   F_t = m l (cos θ θ̇² + sin θ θ̈),   F_n = m (g − l sin θ θ̇² + l cos θ θ̈).
class PainleveRodMotion {
 public:
  struct State {
    double theta = 0, theta_dot = 0;  // rod angle to the ground and its rate [rad, rad/s]
    double force_t = 0, force_n = 0;  // force of the ground on the end, per unit mass [N/kg]
  };

  // Throws std::invalid_argument for a non-positive length, speed or g, or an angle outside
  // (0, π/2).
  PainleveRodMotion(double half_length, double angle, double speed, double mu, double g);

  // B = 1 + 3cos²θ0 − 3μ sinθ0 cosθ0 (Champneys & Várkonyi 2016); the impulsive stop needs B ≤ 0.
  double paradoxCoefficient() const;
  bool stopsByImpulse() const { return paradoxCoefficient() <= 0; }
  // (P_t, P_n) per unit mass [m/s].
  Eigen::Vector2d impulsePerMass() const;
  // The state at t ≥ 0 after the stop (t = 0: just after it): RK4 quadrature of the pivot
  // equation with steps of at most 1e-4 s (error below 1e-14 rad over a second).
  State at(double t) const;
  // The first time in (0, t_max] (sampled every `check_dt`, refined by bisection) at which the
  // end force leaves the cone or pulls (F_n < 0); +∞ when sticking holds throughout. 0 when
  // the impulse itself is outside the cone.
  double stickEnd(double t_max, double check_dt = 1e-3) const;
  // The planar base state (x, z, θ, ẋ, ż, θ̇) of the rod's centre at time t, for a rod whose
  // centre started at x0 with its end on the ground at height z_ground.
  Eigen::Matrix<double, 6, 1> planarState(double t, double x0, double z_ground) const;

 private:
  double pivotAcceleration(double theta) const { return -3 * g_ * std::cos(theta) / (4 * l_); }  // θ̈
  void integrate(double& theta, double& theta_dot, double t0, double t1) const;
  State stateOf(double theta, double theta_dot) const;

  double l_, theta0_, u_, mu_, g_;
};

// A mechanism with two coordinates moving in the x–z plane whose one contact point rests on a belt
// (scene pendulum_conveyor: a flat surface moving tangentially with a piecewise-constant velocity
// schedule) and sticks to it. Two equations for two coordinates: the point follows the belt,
// p(t) = p(0) + ∫₀ᵗ v_belt. With A = [t₁ᵀ; nᵀ] J (tangential and normal rows of the point
// Jacobian):
//  - q(t) by Newton's method on the point position (continued from q0 in small belt moves);
//  - q̇ from A q̇ = (t₁·v_belt, 0);
//  - each step of the belt speed is an impulse P = A⁻ᵀ M Δq̇;
//  - between steps the contact force F = A⁻ᵀ (M q̈ + h − τ) with A q̈ = −[t₁ᵀ; nᵀ] J̇q̇
//    (RBDA 8.3: the constraint force of a closed loop).
class BeltStickingMotion {
 public:
  // Throws std::invalid_argument, naming what is wrong, unless the scene has two coordinates, one
  // contact with friction, a surface normal in the x–z plane, the point on the surface and at
  // rest at t = 0, and no limit stops.
  explicit BeltStickingMotion(const scene::Scene& scene);
  BeltStickingMotion(const BeltStickingMotion&) = delete;  // holds references into its own scene
  BeltStickingMotion& operator=(const BeltStickingMotion&) = delete;

  // [q; q̇] at time t (after a belt step at t: q̇⁺).
  Eigen::VectorXd state(double t) const;
  // Tangential and normal contact force at time t (between steps) [N].
  Eigen::Vector2d contactForce(double t) const;
  // Tangential and normal impulse of the belt step at time t_step [N s].
  Eigen::Vector2d stepImpulse(double t_step) const;
  // The first time in [0, t_max] (checked every `check_dt` and at each belt step) at which the
  // force or an impulse leaves the cone or pulls; +∞ when sticking holds throughout.
  double stickEnd(double t_max, double check_dt = 1e-3) const;

 private:
  Eigen::VectorXd positionsAt(double t) const;
  Eigen::Matrix2d constraintRows(const Eigen::VectorXd& q) const;  // A(q); leaves kinematics at q
  bool insideCone(const Eigen::Vector2d& f) const;

  scene::Scene scene_;  // a copy, so the motion does not depend on the caller's
  contact::ContactPair pair_;  // the contact (the contact layer's kinematics)
  const scene::Surface& surface_;
  Eigen::Vector3d t1_, p0_;  // belt tangent along the motion; the point's position at t = 0
  mutable dynamics::Data<double> data_;
};

}  // namespace saltus::timestepper::exact
