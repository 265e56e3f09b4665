// Fuzzes the problem file reader: collocation::loadProblem on the input written to
// /tmp/saltus_fuzz_problem_<pid>/tests/data/problems/input.yaml (the scene keys through
// scene::readScene, then mesh, inputs, conditions, constraints, hints, surface velocities, cost,
// solve and ipopt; URDF files named by relative path resolve into the source tree: see
// fuzz_support.hpp). Documented failure for bad input: scene::ScenarioError. Anything else is a
// finding.
#include <cstddef>
#include <cstdint>

#include "collocation/problem_file.hpp"
#include "scene/yaml_reader.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = saltus::fuzz::yamlInputPath("problem", "problems", "input.yaml");
  saltus::fuzz::writeFile(path, data, size);
  try {
    (void)saltus::collocation::loadProblem(path.string());
  } catch (const saltus::scene::ScenarioError&) {
  }
  return 0;
}
