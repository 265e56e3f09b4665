// The hostile-input corpus (tests/corpus/, written by tests/corpus/make_corpus.py): every input
// that was once crashed on or wrongly accepted goes through the reader it was given to and must be
// refused with a message holding each line of its CASE.expect ({path}: the input's path). One test
// per case, found at run time; the README's test command runs them under ASan too.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collocation/problem_file.hpp"
#include "collocation/saved_solution.hpp"
#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"
#include "scene/scenario.hpp"
#include "scene/trajectory_csv.hpp"
#include "timestepper/stepper.hpp"

namespace {

namespace fs = std::filesystem;

struct CorpusCase {
  std::string kind;   // the folder: urdf, scenario, problem, trajectory, solution
  fs::path input;     // the file (a folder for a solution)
  fs::path expected;  // CASE.expect
};

std::vector<CorpusCase> corpus() {
  std::vector<CorpusCase> cases;
  const fs::path root = fs::path(SALTUS_SOURCE_DIR) / "tests" / "corpus";
  for (const char* kind : {"urdf", "scenario", "problem", "trajectory", "solution"}) {
    std::vector<fs::path> entries;
    for (const auto& e : fs::directory_iterator(root / kind))
      if (e.path().extension() != ".expect") entries.push_back(e.path());
    std::sort(entries.begin(), entries.end());
    for (const fs::path& p : entries) {
      fs::path expect = p;
      expect.replace_extension(".expect");
      if (fs::is_directory(p)) expect = p.string() + ".expect";
      cases.push_back({kind, p, expect});
    }
  }
  return cases;
}

// The message the reader refuses the input with; "(accepted)" when it does not.
std::string refusal(const CorpusCase& c) {
  try {
    if (c.kind == "urdf") {
      saltus::dynamics::loadUrdfFile(c.input.string(), saltus::dynamics::BaseType::Fixed);
    } else if (c.kind == "scenario") {
      // as `saltus simulate` takes it: read, then the stepper's checks of the initial state
      const saltus::scene::Scene s = saltus::scene::loadScene(c.input.string());
      saltus::timestepper::TimeStepper stepper(s, saltus::timestepper::StepperOptions{});
    } else if (c.kind == "problem") {
      saltus::collocation::loadProblem(c.input.string());
    } else if (c.kind == "trajectory") {
      saltus::scene::readTrajectoryCsv(c.input.string());
    } else {
      saltus::collocation::loadSolution(c.input.string());
    }
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(accepted)";
}

class Corpus : public ::testing::TestWithParam<CorpusCase> {};

TEST_P(Corpus, IsRefusedNamingWhereAndWhat) {
  const CorpusCase& c = GetParam();
  std::ifstream in(c.expected);
  ASSERT_TRUE(in) << c.expected << " is missing";
  const std::string message = refusal(c);
  int pieces = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    for (std::size_t at; (at = line.find("{path}")) != std::string::npos;) line.replace(at, 6, c.input.string());
    EXPECT_NE(message.find(line), std::string::npos) << "expected '" << line << "' in:\n" << message;
    ++pieces;
  }
  EXPECT_GT(pieces, 0) << c.expected << " expects nothing";
}

INSTANTIATE_TEST_SUITE_P(HostileInputs, Corpus, ::testing::ValuesIn(corpus()),
                         [](const ::testing::TestParamInfo<CorpusCase>& info) {
                           return info.param.kind + "_" + info.param.input.stem().string();
                         });

}  // namespace
