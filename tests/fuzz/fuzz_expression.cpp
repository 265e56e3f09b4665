// Fuzzes the expression evaluator of scenario and problem files: scene::YamlReader::evaluate
// (plain numbers, the check against '=' and top-level ',', then muparser with the constant pi,
// atan2 and the file's parameters) on the input as one expression, with the parameters
// height, mass, angle, restitution and n defined as a file's `parameters:` would define them.
// Documented failure for bad input: scene::ScenarioError. Anything else is a finding.
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "scene/yaml_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using saltus::scene::ScenarioError;
  using saltus::scene::YamlReader;
  static const YAML::Node root =
      YAML::Load("parameters: {height: 1.5, mass: 2, angle: pi/6, restitution: 0.5, n: 3}");
  const std::string expr(reinterpret_cast<const char*>(data), size);
  YamlReader reader("fuzz.yaml", {});  // a new parser per input: no state carried over
  try {
    reader.readParameters(root);
  } catch (const ScenarioError&) {
    __builtin_trap();  // the fixed parameters above are valid: the harness is broken
  }
  try {
    (void)reader.evaluate(expr, YAML::Node(expr), "fuzz");
  } catch (const ScenarioError&) {
  }
  return 0;
}
