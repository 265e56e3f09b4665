#include "cli/simulation.hpp"

#include <charconv>
#include <cmath>
#include <ctime>
#include <stdexcept>

#include "cli/common.hpp"
#include "scene/scenario.hpp"

namespace saltus::cli {

timestepper::LcpMethod parseSolverOption(const std::string& value) {
  if (value == "lemke") return timestepper::LcpMethod::Lemke;
  if (value == "pgs") return timestepper::LcpMethod::Pgs;
  throw UsageError("--solver: expected lemke or pgs, got '" + value + "'");
}

const char* solverName(timestepper::LcpMethod method) {
  return method == timestepper::LcpMethod::Lemke ? "lemke" : "pgs";
}

void checkStepOptions(const std::string& dt_option, double dt, double theta) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw UsageError(dt_option + ": expected a positive time step [s], got " + formatNumber(dt));
  if (!(theta >= 0.5 && theta <= 1))
    throw UsageError("--theta: expected a number in [0.5, 1] (0.5: Moreau midpoint, 1: Stewart-Trinkle), got " +
                     formatNumber(theta));
}

std::map<std::string, double> parseSetOptions(const std::vector<std::string>& assignments) {
  try {
    return scene::parseOverrides(assignments);
  } catch (const scene::ScenarioError& e) {
    throw UsageError(e.what());  // the message starts with "--set '<item>'"
  }
}

std::vector<double> parseNumberList(const std::string& option, const std::string& text, bool positive) {
  std::vector<double> values;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    std::string token = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto b = token.find_first_not_of(" \t"), e = token.find_last_not_of(" \t");
    token = b == std::string::npos ? "" : token.substr(b, e - b + 1);
    double x = 0;
    const char* first = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(first, token.data() + token.size(), x);
    if (token.empty() || ec != std::errc() || end != token.data() + token.size() || !std::isfinite(x))
      throw UsageError(option + ": '" + token + "' is not a number (expected a comma-separated list, e.g. " + option +
                       " 1e-2,5e-3)");
    if (positive ? !(x > 0) : x < 0)
      throw UsageError(option + ": '" + token + "' must be " + (positive ? "positive" : "non-negative"));
    values.push_back(x);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return values;
}

double cpuSeconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace saltus::cli
