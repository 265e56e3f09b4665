// Legendre–Gauss collocation on the unit element [0, 1] for any order P (paper §II.C, after
// Biegler 2010 ch. 10): the roots τ_1 … τ_P of the shifted Legendre polynomial, the integration
// matrix Ω of eq. (3) and the quadrature weights of eq. (4), computed rather than tabulated.
//
//   x[n, p]     = x[n, 0] + h[n] Σ_j Ω(p, j) ẋ[n, j]     p = 1 … P    (3)
//   x[n, P + 1] = x[n, 0] + h[n] Σ_j b_j ẋ[n, j]                       (4), b_j = w_j / 2
//
// with Ω(p, j) = ∫_0^{τ_p} ℓ_j(s) ds and b_j = ∫_0^1 ℓ_j(s) ds, ℓ_j the Lagrange basis
// polynomials through the roots (the paper's w_j are the weights on [−1, 1], which sum to 2).
#pragma once

#include <Eigen/Core>

namespace saltus::collocation {

struct LegendreGauss {
  explicit LegendreGauss(int P);

  int P;
  Eigen::VectorXd tau;    // roots in (0, 1), increasing
  Eigen::MatrixXd Omega;  // P × P, eq. (3)
  Eigen::VectorXd b;      // P quadrature weights on [0, 1], eq. (4); they sum to 1
  Eigen::VectorXd x, w;   // the P-point Gauss–Legendre rule on [−1, 1] (tau = (x + 1) / 2)

  // Lagrange basis through the roots at s ∈ [0, 1]: ℓ_j(s), j = 0 … P − 1 (the polynomial of
  // degree P − 1 through the values at the collocation points, e.g. ẋ or an input).
  Eigen::VectorXd basis(double s) const;
  // ∫_0^s ℓ_j: x(s) = x[n, 0] + h Σ_j integral(s)_j ẋ[n, j] is the state polynomial (degree P).
  Eigen::VectorXd basisIntegral(double s) const;
};

// Roots and weights of the P-point Gauss–Legendre rule on [−1, 1] (Newton's method on the
// three-term recurrence of P_n; exact for polynomials of degree ≤ 2P − 1).
void gaussLegendre(int P, Eigen::VectorXd& x, Eigen::VectorXd& w);

}  // namespace saltus::collocation
