#include "collocation/legendre_gauss.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace saltus::collocation {

void gaussLegendre(int P, Eigen::VectorXd& x, Eigen::VectorXd& w) {
  if (P < 1) throw std::invalid_argument("Legendre–Gauss order P must be ≥ 1, got " + std::to_string(P));
  x.resize(P);
  w.resize(P);
  for (int i = 0; i < P; ++i) {
    // Initial guess (Tricomi), then Newton on P_P(x) with P_P' from the recurrence.
    double z = std::cos(std::numbers::pi * (i + 0.75) / (P + 0.5));
    double dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;  // P_0, P_1
      for (int k = 2; k <= P; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      // p1 = P_P(z), p0 = P_{P−1}(z); P_P' = P (z P_P − P_{P−1}) / (z² − 1).
      dp = P * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    x[P - 1 - i] = z;  // increasing order
    w[P - 1 - i] = 2 / ((1 - z * z) * dp * dp);
  }
}

LegendreGauss::LegendreGauss(int P_) : P(P_) {
  gaussLegendre(P, x, w);
  tau = (x.array() + 1) / 2;
  b = basisIntegral(1.0);
  Omega.resize(P, P);
  for (int p = 0; p < P; ++p) Omega.row(p) = basisIntegral(tau[p]).transpose();
}

Eigen::VectorXd LegendreGauss::basis(double s) const {
  Eigen::VectorXd l(P);
  for (int j = 0; j < P; ++j) {
    double v = 1;
    for (int m = 0; m < P; ++m)
      if (m != j) v *= (s - tau[m]) / (tau[j] - tau[m]);
    l[j] = v;
  }
  return l;
}

Eigen::VectorXd LegendreGauss::basisIntegral(double s) const {
  // ℓ_j has degree P − 1: the P-point Gauss rule on [0, s] integrates it exactly.
  Eigen::VectorXd integral = Eigen::VectorXd::Zero(P);
  for (int m = 0; m < P; ++m) integral += (s / 2) * w[m] * basis(s * (x[m] + 1) / 2);
  return integral;
}

}  // namespace saltus::collocation
