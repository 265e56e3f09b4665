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

}  // namespace saltus::timestepper::analytic
