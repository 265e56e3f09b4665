// What `saltus simulate` and `saltus bench` share: the stepper options from the command line,
// the number of steps for a duration, clocks, files written by temp file + rename, and the chart
// script (scripts/charts.py) run through python3.
#pragma once

#include <map>
#include <string>
#include <vector>

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

// Whether the scene is driven from outside (a surface that moves at some time, or a non-zero
// input): then its energy is not expected to decrease.
bool hasMovingSurfaceOrInput(const timestepper::Scene& scene);

// Steps that cover `duration`: round(duration/dt) when that is within 1e-9 relative of an
// integer, else the next integer up. At least 1.
long stepCount(double duration, double dt);

// CPU time of this process [s] (CLOCK_PROCESS_CPUTIME_ID).
double cpuSeconds();

// Files are written by temporary file and rename (scene/atomic_file.hpp).
using scene::writeFileAtomically;

// Runs `python3 scripts/charts.py KIND CSV --png PNG --svg SVG` (the interpreter: $SALTUS_PYTHON
// when set, else /usr/bin/python3 when it exists, else python3 from PATH; MPLBACKEND=Agg; the
// script's standard output goes to standard error). Throws std::runtime_error when the script
// cannot be started or fails.
// This process's environment with MPLBACKEND=Agg (matplotlib without a display), for child processes.
std::vector<std::string> chartEnvironment();
void runChartScript(const std::string& kind, const std::string& csv, const std::string& png, const std::string& svg);
// The command line runChartScript runs (interpreter, script, KIND, CSV, --png, PNG, --svg, SVG).
std::vector<std::string> chartScriptCommand(const std::string& kind, const std::string& csv, const std::string& png,
                                            const std::string& svg);

// CSV-quotes a field when it holds a comma, quote or newline.
std::string csvField(const std::string& s);

// %.6g, "nan", "inf".
std::string formatNumber(double x, int digits = 6);

}  // namespace saltus::cli
