// A solved transcription as functions of time: the collocation polynomials of each element
// evaluated anywhere in it, for replaying the optimised inputs (verify/), drawing frames between
// points (render/) and seeding a new solve from an earlier one (saved_solution.hpp).
//
// On element n, with s = (t − t_n) / h[n] ∈ [0, 1] (paper eq. 3 with s in place of τ_p):
//   q(s) = q[n, 0] + h Σ_j ∫_0^s ℓ_j · q̇[n, j]      q̇(s) = q̇[n, 0] + h Σ_j ∫_0^s ℓ_j · q̈[n, j]
//   q̈(s) = Σ_j ℓ_j(s) q̈[n, j]                       u(s) = Σ_j ℓ_j(s) u[n, j]
// with ℓ_j the Lagrange basis through the P collocation points (q̇(s) is the same polynomial as
// Σ_j ℓ_j q̇[n, j] at the collocation points). The first-order method's steps are elements with one
// point at the end: q and q̇ linear in s with the end point's rates, u constant (backward Euler).
// At a mesh point of the impulsive method q̇ jumps by Δq̇[n]: `Side` picks the limit.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "collocation/transcription.hpp"

namespace saltus::collocation {

enum class Side { Before, After };  // the left or right limit at a mesh point

struct TrajectoryPoint {
  Eigen::VectorXd q, v, a, u;  // position, velocity, acceleration, inputs (empty without inputs)
};

class CollocationTrajectory {
 public:
  // Keeps a reference to t; x is copied.
  CollocationTrajectory(const Transcription& t, const Eigen::VectorXd& x);

  double endTime() const { return mesh_.back(); }  // the trajectory starts at t = 0
  int elements() const { return static_cast<int>(mesh_.size()) - 1; }
  const std::vector<double>& meshTimes() const { return mesh_; }  // N + 1 element boundaries

  // The element that holds t: for a mesh time, the one that starts there (Side::After) or ends
  // there (Side::Before), clamped to the first and last. Throws std::out_of_range outside [0, T].
  int elementAt(double t, Side side = Side::After) const;
  TrajectoryPoint at(double t, Side side = Side::After) const;
  // At s ∈ [0, 1] of element n.
  TrajectoryPoint atElement(int n, double s) const;

  // The impulsive method's velocity jumps Δq̇ at the mesh points [n, 0], n ≥ 1, whose largest
  // component exceeds `threshold` in magnitude.
  struct Jump {
    double t;
    int element;
    Eigen::VectorXd dv;
  };
  std::vector<Jump> jumps(double threshold = 0.0) const;

 private:
  const Transcription& t_;
  Eigen::VectorXd x_;
  std::vector<double> mesh_;
  int nv_, nu_;
};

}  // namespace saltus::collocation
