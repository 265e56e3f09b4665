// Fuzzes the scenario file reader: scene::loadScene on the input written to
// /tmp/saltus_fuzz_scenario_<pid>/tests/data/scenes/input.yaml (yaml-cpp, the YamlReader's type
// checks, parameters and their muparser expressions, the models: point masses, rigid bodies and
// URDF files named by relative path, which resolve into the source tree: see fuzz_support.hpp).
// Documented failure for bad input: scene::ScenarioError ("every error is a ScenarioError").
// Anything else is a finding.
#include <cstddef>
#include <cstdint>

#include "scene/scenario.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = saltus::fuzz::yamlInputPath("scenario", "scenes", "input.yaml");
  saltus::fuzz::writeFile(path, data, size);
  try {
    (void)saltus::scene::loadScene(path.string());
  } catch (const saltus::scene::ScenarioError&) {
  }
  return 0;
}
