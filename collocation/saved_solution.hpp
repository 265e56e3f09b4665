// A solved transcription on disk, and read back: DIR/variables.csv holds every decision variable
// by name after a few '# key: value' lines that say how to rebuild the transcription (the
// problem's source, its parameters, the method, N and P). `saltus replay`, `saltus render` and a
// solve seeded from an earlier solution (Problem::seed_kind == SeedKind::Solution) start here.
//
//   # saltus solution: decision variables by name
//   # source: builtin:point_mass_drop
//   # method: impulsive
//   # N: 20
//   # P: 4
//   # parameter.height: 0.1
//   name,value
//   h[1,0],0.0123
//   ...
#pragma once

#include <memory>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

#include "collocation/interpolation.hpp"
#include "collocation/transcription.hpp"

namespace saltus::collocation {

// A file that cannot be read as a solution; the message starts with the file (and line).
class SolutionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Writes DIR/variables.csv (temporary file, then rename). Throws SolutionError when it cannot.
void writeSolution(const std::string& dir, const Transcription& t, const Eigen::VectorXd& x);

struct SavedSolution {
  std::string file;  // the variables.csv it came from
  std::unique_ptr<Problem> problem;              // rebuilt from source + parameters, remeshed to N, P
  std::unique_ptr<Transcription> transcription;  // refers to *problem
  Eigen::VectorXd x;
  // Not empty when the problem file, its model file or the parameters no longer give the
  // fingerprint saved with the solution: what changed, to be shown to the user (checkSameProblem).
  std::string problem_changed;
  CollocationTrajectory trajectory() const { return CollocationTrajectory(*transcription, x); }
};

// Reads a solution from its directory (or from a file in it: trajectory.csv, summary.json,
// variables.csv). Throws SolutionError naming the file and line for a missing file, a missing
// or malformed key, a variable that is missing, repeated or unknown to the rebuilt
// transcription, or a value that is not a finite number, or a problem that cannot be rebuilt
// (its source or parameters; the problem file's own message follows).
SavedSolution loadSolution(const std::string& path);

// A solution whose problem changed since it was saved (problem_changed not empty) answers
// questions about another problem: unless `allow_changed_problem`, throws SolutionError saying
// what changed and how to go on.
void checkSameProblem(const SavedSolution& solution, bool allow_changed_problem);

// The variables.csv a solution path names: PATH/variables.csv for a folder, PATH itself when it is
// named variables.csv. Throws SolutionError naming PATH as given when it is neither or is missing.
std::filesystem::path solutionFile(const std::string& path);

// A starting point for `target` from an earlier solution. With the same method and the same
// variables (same mesh, scene and contacts) the values are copied by name; otherwise states,
// accelerations and inputs are sampled from the earlier collocation polynomials at the target's
// points (the earlier element lengths when the element counts match, else T / N; clamped to
// their bounds), velocity jumps at the target's mesh
// points taken from the earlier trajectory, reactions left at zero. Gaps are recomputed and
// every value projected into its bounds (Transcription::makeConsistent).
Eigen::VectorXd seedFromSolution(const Transcription& target, const SavedSolution& earlier);
// The same from a solution x of `earlier` in memory (a solve just made); `origin` names it in
// the error.
Eigen::VectorXd seedFromSolution(const Transcription& target, const Transcription& earlier, const Eigen::VectorXd& x,
                                 const std::string& origin);

}  // namespace saltus::collocation
