#include "verify/run_outcome.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace saltus::verify {
namespace {
std::string number(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}
}  // namespace

bool RunRecord::addEnergy(double e) {
  if (!std::isfinite(e)) return energy_finite = false;
  if (std::isnan(energy_start)) energy_start = e;
  energy_max = std::max(energy_max, e);
  energy_min = std::min(energy_min, e);
  return true;
}

double RunRecord::energyGain() const {
  if (std::isnan(energy_start)) return 0;
  const double scale = energy_start != 0 ? std::abs(energy_start) : 1.0;
  return std::max(0.0, (energy_max - energy_start) / scale);
}

double RunRecord::energyDrift() const {
  if (std::isnan(energy_start)) return 0;
  const double scale = energy_start != 0 ? std::abs(energy_start) : 1.0;
  return std::max(energy_max - energy_start, energy_start - energy_min) / scale;
}

RunOutcome classifyRun(const RunRecord& run, const RunCriteria& criteria) {
  if (run.end == RunEnd::NotFinite || !run.energy_finite)
    return {"nan", run.message.empty() ? "the state or the energy is not finite" : run.message};
  if (run.end == RunEnd::LcpFailure) return {"lcp_failure", run.message};
  if (run.end == RunEnd::OtherError) return {"error", run.message};
  if (run.max_penetration > criteria.penetration_limit)
    return {"penetration", "largest penetration " + number(run.max_penetration) + " m"};
  if (criteria.conservative) {
    if (run.energyDrift() > criteria.drift_tolerance)
      return {"drift", "energy left E_0 by " + number(run.energyDrift()) + " (relative)"};
  } else if (criteria.energy_checked && run.energyGain() > criteria.energy_tolerance) {
    return {"energy_gain", "energy rose above E_0 by " + number(run.energyGain()) + " (relative)"};
  }
  if (criteria.fallbacks_fail && run.solver_fallbacks > 0)
    return {"solver_fallback", std::to_string(run.solver_fallbacks) + " MLCP solves fell back to sequential impulse"};
  return {"ok", ""};
}

}  // namespace saltus::verify
