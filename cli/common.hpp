// What the subcommands of the `saltus` program share: how they register, how they report bad
// input, and how they read models and vectors from the command line.
//
// Exit codes: 0 success, 1 a model or run-time error ("saltus: <message>"), 2 a usage error
// (bad option or argument: "saltus: <message>" and a pointer to --help). On any error nothing is
// written to standard output.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "dynamics/model.hpp"
#include "saltus/saltus.hpp"

namespace saltus::cli {

// Bad command-line input; the message names the option or argument and what was expected.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The library API's message "field_name: …" as "--field-name: …" (its option on the command line).
UsageError optionError(const std::exception& e);

// A usage error's message about an option ("--dt: expected a positive time step [s], got inf")
// with the option's value as it was written on the command line ("1e400") when the message does
// not already show it: a check sees the value after conversion (1e400 as inf, 1e-400 as 0).
// `command` is the subcommand that ran (its own subcommands are searched too).
std::string withValueAsWritten(const CLI::App& command, const std::string& message);

// The items of a comma-separated list, each trimmed of blanks ("a, b" -> {"a", "b"}; "" -> {""}).
std::vector<std::string> splitCommaList(const std::string& text);

// What an output option names (checkOutputTarget).
enum class OutputTarget {
  File,          // a file written in one stream (CSV, JSON): a device or a pipe is written into
  RegularFile,   // a file another program writes, then renamed into place (a video): regular only
  Folder,        // a folder, made with its missing parents
};

// Checks an output target before any work, naming the option: a file must not be a folder, nor
// a symlink to anything but a device or a pipe (File), and its folder must exist; a folder must
// be one if it exists. A file is then created and removed where the output will go, so an
// unwritable place (/proc/x, a read-only mount) is refused at once, not after a long run.
// Throws UsageError ("--out x: is a folder; expected a file").
void checkOutputTarget(const std::string& option, const std::string& path, OutputTarget kind);

// A subcommand: its CLI11 parser and what runs when it was given. run() returns the exit code
// and throws UsageError, dynamics::ModelError or other std::exceptions on failure.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

// One function per subcommand, each in its own file (inspect.cpp, ...).
Command addInspectCommand(CLI::App& saltus);
Command addSimulateCommand(CLI::App& saltus);  // simulate.cpp
Command addBenchCommand(CLI::App& saltus);     // bench.cpp: work-precision, stability
Command addOptimizeCommand(CLI::App& saltus);  // optimize.cpp: trajectory optimisation through contact
Command addRenderCommand(CLI::App& saltus);    // render.cpp: trajectory -> MP4 / PNG frames (off-screen)
Command addReplayCommand(CLI::App& saltus);    // replay.cpp: optimised inputs replayed in the stepper / Bullet
Command addRunCommand(CLI::App& saltus);       // run.cpp: the main job (optimize, replay, render, charts, report)
Command addSweepCommand(CLI::App& saltus);     // sweep.cpp: a grid of seeded solves with statistics

// The --base option's value: fixed, planar or free.
dynamics::BaseType parseBaseOption(const std::string& option, const std::string& value);

// Reads a URDF model (the library API's); throws dynamics::ModelError naming the file and element.
using saltus::loadModel;

// A comma-separated list of numbers, one per model coordinate (coordinate order), e.g.
// "--q=0,0.785". Throws UsageError naming the option and the offending token.
Eigen::VectorXd parseCoordinateVector(const std::string& option, const std::string& text,
                                      const std::vector<std::string>& coordinates);

}  // namespace saltus::cli
