// The problem-file error tests' one step: a fixture of tests/data/problems loaded, and its error
// checked at the line the fixture marks (expectMarkedError).
#pragma once

#include <string>
#include <vector>

#include "collocation/problem_file.hpp"
#include "saltus/build_paths.hpp"
#include "scene/scenario.hpp"
#include "tests/support/errors.hpp"

namespace saltus::testing {

inline const std::string kProblemDataDir = std::string(SALTUS_SOURCE_DIR) + "/tests/data/problems/";

// Loads tests/data/problems/<fixture>, expects a ScenarioError at its marked line naming
// key_path and containing every one of `parts`; returns the message.
inline std::string expectProblemError(const std::string& fixture, const std::string& key_path,
                                      const std::vector<std::string>& parts) {
  const std::string path = kProblemDataDir + fixture;
  return expectMarkedError<scene::ScenarioError>(path, [&] { collocation::loadProblem(path); }, key_path, parts);
}

}  // namespace saltus::testing
