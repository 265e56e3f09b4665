// What `saltus simulate` and `saltus bench` share: the stepper options from the command line,
// the CPU clock, and the library API's step count, charts and number formats.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "saltus/format.hpp"
#include "saltus/saltus.hpp"
#include "scene/atomic_file.hpp"
#include "scene/scene.hpp"
#include "timestepper/stepper.hpp"

namespace saltus::cli {

// --solver: lemke or pgs. Throws UsageError naming the option.
timestepper::LcpMethod parseSolverOption(const std::string& value);
const char* solverName(timestepper::LcpMethod method);

// Checks --dt (> 0, finite) and --theta (in [½, 1]); throws UsageError naming the option.
void checkStepOptions(const std::string& dt_option, double dt, double theta);

// --set assignments; a malformed one is a UsageError ("--set 'x': expected name=value").
// An unknown parameter name is only found by loadScene (a ScenarioError, exit 1).
std::map<std::string, double> parseSetOptions(const std::vector<std::string>& assignments);

// A comma-separated list of positive numbers, e.g. "--dts 1e-2,5e-3"; throws UsageError.
std::vector<double> parseNumberList(const std::string& option, const std::string& text, bool positive);

// CPU time of this process [s] (CLOCK_PROCESS_CPUTIME_ID).
double cpuSeconds();

// Files are written by temporary file and rename (scene/atomic_file.hpp).
using scene::writeFileAtomically;

// What the library API provides (saltus/saltus.hpp, saltus/format.hpp).
using saltus::chartCommand;
using saltus::chartEnvironment;
using saltus::csvField;
using saltus::drawChart;
using saltus::formatNumber;
using saltus::isDriven;
using saltus::stepCount;

}  // namespace saltus::cli
