#include "timestepper/analytic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace saltus::timestepper::analytic {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

double ballApex(double h0, double e, int k) { return std::pow(e, 2 * k) * h0; }

double ballImpactSpeed(double h0, double e, int k, double g) { return std::pow(e, k) * std::sqrt(2 * g * h0); }

double ballRestTime(double h0, double e, double g) {
  if (e >= 1) return kInf;
  return std::sqrt(2 * h0 / g) * (1 + e) / (1 - e);
}

bool slideSticks(double mu, double alpha) { return std::tan(alpha) <= mu; }

double slideAcceleration(double mu, double alpha, double g) {
  return g * (std::sin(alpha) - mu * std::cos(alpha));
}

double slideStopTime(double v0, double mu, double alpha, double g) {
  const double a = slideAcceleration(mu, alpha, g);
  return a < 0 ? v0 / -a : kInf;
}

double slideStopDistance(double v0, double mu, double alpha, double g) {
  const double a = slideAcceleration(mu, alpha, g);
  return a < 0 ? v0 * v0 / (-2 * a) : kInf;
}

double slidePosition(double v0, double mu, double alpha, double g, double t) {
  const double a = slideAcceleration(mu, alpha, g);
  const double t_stop = slideStopTime(v0, mu, alpha, g);
  const double tau = std::min(t, t_stop);
  return v0 * tau + 0.5 * a * tau * tau;
}

double firstApex(const std::vector<double>& z, const std::vector<double>& pn) {
  if (z.size() != pn.size()) throw std::invalid_argument("firstApex: z and pn differ in length");
  const std::size_t n = z.size();
  std::size_t i = 0;
  while (i < n && !(pn[i] > 0)) ++i;
  if (i == n) return std::numeric_limits<double>::quiet_NaN();
  double apex = z[i];
  while (i < n && pn[i] > 0) apex = std::max(apex, z[i++]);  // the first impact
  for (; i < n && !(pn[i] > 0); ++i) apex = std::max(apex, z[i]);  // flight until the second
  return apex;
}

std::vector<double> cradleVelocities(double e, double v) {
  return {(1 - 2 * e) * v / 3, (1 + e) * v / 3, (1 + e) * v / 3};
}

std::vector<double> spinFlipTimes(double I1, double I2, double I3, double w2, double w3, double t_end) {
  const double E2 = I2 * w2 * w2 + I3 * w3 * w3, M2 = I2 * I2 * w2 * w2 + I3 * I3 * w3 * w3;  // 2E, M²
  const double lambda = std::sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3));
  const double k2 = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1));
  const double K = std::comp_ellint_1(std::sqrt(k2));
  std::vector<double> t;
  for (double x = K / lambda; x <= t_end; x += 2 * K / lambda) t.push_back(x);
  return t;
}

double rockingImpactRatio(double b, double h) {
  const double s = std::sin(std::atan2(b, h));
  return 1 - 1.5 * s * s;
}

double rockingReturnSpeed(double b, double h, double theta0, double g) {
  const double alpha = std::atan2(b, h), R = std::hypot(b, h);
  return std::sqrt(3 * g / (2 * R) * (std::cos(alpha - theta0) - std::cos(alpha)));
}

double rockingTilt(double b, double h, double omega, double g) {
  const double alpha = std::atan2(b, h), R = std::hypot(b, h);
  return alpha - std::acos(std::cos(alpha) + 2 * R / (3 * g) * omega * omega);
}

double rockingFirstTilt(const std::vector<double>& theta) {
  const std::size_t n = theta.size();
  std::size_t i = 1;
  while (i < n && !(theta[i - 1] * theta[i] <= 0 && theta[i - 1] != theta[i])) ++i;  // the first flat
  if (i >= n) return std::numeric_limits<double>::quiet_NaN();
  double tilt = std::abs(theta[i]);
  for (++i; i < n && !(theta[i - 1] * theta[i] <= 0 && theta[i - 1] != theta[i]); ++i) tilt = std::max(tilt, std::abs(theta[i]));
  return tilt;
}

}  // namespace saltus::timestepper::analytic
