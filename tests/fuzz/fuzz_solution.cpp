// Fuzzes the saved-solution reader: collocation::loadSolution on a folder holding the input as
// its variables.csv (/tmp/saltus_fuzz_solution_<pid>/solution/variables.csv): the '# key: value'
// header, the problem it names (loadProblem: built-in names resolve to models/problems), remesh
// to N and P, the rebuilt Transcription and the 'name,value' rows.
// Documented failures for bad input: collocation::SolutionError, scene::ScenarioError (from
// loading the problem), and std::invalid_argument, which Transcription's constructor throws
// deliberately for a problem the method cannot take. Anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "collocation/saved_solution.hpp"
#include "scene/yaml_reader.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto dir = [] {
    const auto d = saltus::fuzz::tempDir("solution") / "solution";
    saltus::fuzz::fs::create_directories(d);
    return d;
  }();
  saltus::fuzz::writeFile(dir / "variables.csv", data, size);
  try {
    (void)saltus::collocation::loadSolution(dir.string());
  } catch (const saltus::collocation::SolutionError&) {
  } catch (const saltus::scene::ScenarioError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
