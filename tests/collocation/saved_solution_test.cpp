// Solutions on disk (collocation/saved_solution.hpp): the round trip, every malformed file named
// with its line, and seeds from an earlier solution, copied or resampled from its polynomials.
#include "collocation/saved_solution.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "collocation/problem_file.hpp"

namespace saltus::collocation {
namespace {

namespace fs = std::filesystem;
constexpr double kG = 9.81;

struct SavedSolutionTest : ::testing::Test {
  void SetUp() override {
    dir = fs::temp_directory_path() / ("saltus_saved_solution_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  // point_mass_drop (h0 = 0.15 by --set) with the exact free fall written into its variables:
  // q = h0 − g t²/2, q̇ = −g t, q̈ = −g at every point, element lengths 0.01.
  Eigen::VectorXd freeFall(const Transcription& t) const {
    Eigen::VectorXd x = t.nullSeed();
    double t0 = 0;
    for (const ElementLayout& L : t.layout()) {
      x[L.h] = 0.01;
      for (std::size_t p = 0; p < L.points.size(); ++p) {
        const double s = t0 + 0.01 * L.tau[p];
        x[L.points[p].q] = 0.15 - kG * s * s / 2;
        x[L.points[p].v] = -kG * s;
        if (L.points[p].accel_or_jump >= 0) x[L.points[p].accel_or_jump] = p == 0 ? 0.0 : -kG;
      }
      t0 += 0.01;
    }
    return x;
  }
  std::string file() const { return (dir / "variables.csv").string(); }
  void rewrite(const std::function<std::string(const std::string&)>& edit) const {
    std::ifstream in(file());
    std::stringstream ss;
    ss << in.rdbuf();
    in.close();
    std::ofstream(file()) << edit(ss.str());
  }
  fs::path dir;
};

TEST_F(SavedSolutionTest, RoundTripRebuildsTheTranscriptionAndTheValues) {
  const Problem p = loadProblem("point_mass_drop", {{"height", 0.15}});
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd x = t.perturb(t.nullSeed(), 0.1, 7);
  writeSolution(dir.string(), t, x);
  for (const fs::path& path : {dir, dir / "trajectory.csv", dir / "variables.csv"}) {
    const SavedSolution s = loadSolution(path.string());
    EXPECT_EQ(s.transcription->variableNames(), t.variableNames());
    EXPECT_EQ(s.transcription->method(), Method::Impulsive);
    EXPECT_DOUBLE_EQ(s.problem->parameters.at("height"), 0.15);
    EXPECT_EQ((s.x - x).cwiseAbs().maxCoeff(), 0.0) << "%.17g round-trips doubles";
  }
}

TEST_F(SavedSolutionTest, RemeshedAndFirstOrderSolutionsRoundTrip) {
  Problem p = loadProblem("point_mass_drop");
  remesh(p, 12, 3);
  const Transcription t(p, Method::FirstOrder);
  writeSolution(dir.string(), t, t.nullSeed());
  const SavedSolution s = loadSolution(dir.string());
  EXPECT_EQ(s.problem->N, 12);
  EXPECT_EQ(s.problem->P, 3);
  EXPECT_EQ(s.transcription->variables(), t.variables());
}

// Solutions saved while a joint stop had a gap variable ("y.STOP[n,p]", now its coordinate's
// bound, Transcription::gap) still load, those lines passed over; a point-on-plane contact's gap
// variable is still required and an unknown "y." name still refused.
TEST_F(SavedSolutionTest, AJointStopsFormerGapVariablesArePassedOver) {
  Problem p = loadProblem("biped_stop");
  remesh(p, 2, 2);
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd x = t.perturb(t.nullSeed(), 0.1, 3);
  std::string stop;
  for (const ContactPair& cp : t.contacts())
    if (cp.isStop()) stop = cp.name;
  ASSERT_FALSE(stop.empty());
  writeSolution(dir.string(), t, x);
  rewrite([&](const std::string& s) { return s + "y." + stop + "[1,0],0.25\ny." + stop + "[2,3],0\n"; });
  const SavedSolution old = loadSolution(dir.string());
  EXPECT_EQ((old.x - x).cwiseAbs().maxCoeff(), 0.0);
  for (const std::string& name : {std::string("y.foot_r[1,0]"), std::string("y.no_such_stop[1,0]")}) {
    writeSolution(dir.string(), t, x);
    rewrite([&](const std::string& s) {
      std::string out = s;
      const auto at = out.find("y.foot_r[1,0],");
      if (name == "y.foot_r[1,0]") out.erase(at, out.find('\n', at) + 1 - at);  // missing
      else out += name + ",1\n";                                                 // unknown
      return out;
    });
    try {
      loadSolution(dir.string());
      ADD_FAILURE() << "no error for " << name;
    } catch (const SolutionError& e) {
      EXPECT_NE(std::string(e.what()).find(name == "y.foot_r[1,0]" ? "'y.foot_r[1,0]' is missing" : "does not belong"),
                std::string::npos) << e.what();
    }
  }
}

TEST_F(SavedSolutionTest, MalformedFilesNameTheFileAndLine) {
  const Problem p = loadProblem("point_mass_drop");
  const Transcription t(p, Method::Impulsive);
  writeSolution(dir.string(), t, t.nullSeed());
  auto expectError = [&](const std::function<std::string(const std::string&)>& edit, const std::string& pattern) {
    writeSolution(dir.string(), t, t.nullSeed());
    rewrite(edit);
    try {
      loadSolution(dir.string());
      ADD_FAILURE() << "no error for " << pattern;
    } catch (const SolutionError& e) {
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(pattern))) << e.what();
    }
  };
  auto replace = [](const std::string& from, const std::string& to) {
    return [=](const std::string& s) {
      std::string out = s;
      out.replace(out.find(from), from.size(), to);
      return out;
    };
  };
  expectError(replace("# method: impulsive\n", ""), "variables.csv: the header lacks '# method");
  expectError(replace("# method: impulsive", "# method: implicit"), "variables.csv: method: unknown method 'implicit'");
  expectError(replace("# N: 20", "# N: twenty"), "N: expected a finite number");
  expectError(replace("name,value", "variable,value"), "variables.csv:\\d+: expected the column header");
  expectError(replace("h[1,0],", "h[99,0],"), "variables.csv:10: variable 'h\\[99,0\\]' does not belong");  // after 9 header lines
  expectError(replace("q[1,0],", "h[1,0],"), "variables.csv:11: variable 'h\\[1,0\\]' is given twice");
  expectError(replace("q[1,0],0.10000000000000001", "q[1,0],nan"), "variables.csv:11: q\\[1,0\\]: expected a finite number, got 'nan'");
  // A negative element length (the trajectory would run backwards): refused, naming the variable.
  expectError([](const std::string& s) {
    std::string out = s;
    const std::size_t at = out.find("\nh[2,0],") + 8;
    out.replace(at, out.find('\n', at) - at, "-0.01");
    return out;
  }, "variables.csv: variable 'h\\[2,0\\]': expected a positive element length \\[s\\], got -0.01");
  expectError([](const std::string& s) { return s.substr(0, s.rfind('\n', s.size() - 2) + 1); },
              "variables.csv: variable '.*' is missing");
  fs::remove(file());
  EXPECT_THROW(loadSolution(dir.string()), SolutionError);
}

TEST_F(SavedSolutionTest, SeedCopiesTheSameLayout) {
  const Problem p = loadProblem("point_mass_drop", {{"height", 0.15}});
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd x = freeFall(t);
  writeSolution(dir.string(), t, x);
  const SavedSolution s = loadSolution(dir.string());
  const Eigen::VectorXd seed = seedFromSolution(t, s);
  for (const ElementLayout& L : t.layout())
    for (const auto& pt : L.points) {
      EXPECT_DOUBLE_EQ(seed[pt.q], x[pt.q]);
      EXPECT_DOUBLE_EQ(seed[pt.v], x[pt.v]);
    }
}

TEST_F(SavedSolutionTest, SeedResamplesAnotherMeshAndMethodFromThePolynomials) {
  const Problem p = loadProblem("point_mass_drop", {{"height", 0.15}});
  const Transcription earlier(p, Method::Impulsive);
  writeSolution(dir.string(), earlier, freeFall(earlier));
  const SavedSolution s = loadSolution(dir.string());  // T = 0.2 s of free fall
  for (Method m : {Method::Impulsive, Method::FirstOrder}) {
    Problem q = loadProblem("point_mass_drop", {{"height", 0.15}});
    q.hints.clear();
    remesh(q, 16, 2);
    const Transcription target(q, m);
    const Eigen::VectorXd seed = seedFromSolution(target, s);
    double t0 = 0;
    for (const ElementLayout& L : target.layout()) {
      EXPECT_NEAR(seed[L.h], std::min(0.2 / target.elements(), target.variableUpper()[L.h]), 1e-15);
      for (std::size_t p2 = 0; p2 < L.points.size(); ++p2) {
        const double time = t0 + seed[L.h] * L.tau[p2];
        EXPECT_NEAR(seed[L.points[p2].q], 0.15 - kG * time * time / 2, 1e-12) << toString(m) << " t = " << time;
        EXPECT_NEAR(seed[L.points[p2].v], -kG * time, 1e-12);
        if (L.points[p2].accel_or_jump >= 0 && p2 > 0) {
          EXPECT_NEAR(seed[L.points[p2].accel_or_jump], -kG, 1e-12);
        }
      }
      t0 += seed[L.h];
    }
  }
}

}  // namespace
}  // namespace saltus::collocation
