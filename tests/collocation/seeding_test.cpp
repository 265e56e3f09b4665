// The starting points of a solve by seed kind (collocation/seeding.hpp): the simulation seed is
// exact and warm in attempt 0 and perturbed in later attempts; the perturbed kinds add uniform
// values in [0, seed_scale] to the positions and normal reactions only, the same for the same
// random seed and different for another; without a perturbation there is nothing to restart from;
// an earlier solution is warm, perturbed or not.
#include "collocation/seeding.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "collocation/problem_file.hpp"
#include "collocation/solution.hpp"
#include "tests/support/drop_checks.hpp"
#include "tests/support/errors.hpp"
#include "tests/support/files.hpp"
#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace {

TEST(Seeding, SimulationIsExactAndWarmFirstThenPerturbed) {
  Problem p = testing::pointMassDrop(0.5);
  p.seed_kind = SeedKind::Simulation;
  p.random_seed = 7;
  const Transcription t(p, Method::Impulsive);
  const Seeding s = makeSeeding(t);
  EXPECT_TRUE(s.fallback.empty()) << s.fallback;
  EXPECT_EQ(s.restarts, p.restarts);
  ASSERT_FALSE(s.simulation.events.empty());
  const Seed first = s.seed(0);
  EXPECT_TRUE(first.warm);
  EXPECT_TRUE(first.x.isApprox(seedFromSimulation(t, nullptr)));
  const Seed second = s.seed(1);
  EXPECT_FALSE(second.warm);
  EXPECT_GT((second.x - first.x).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(Seeding, PerturbedSimulationPerturbsEveryAttemptReproducibly) {
  Problem p = testing::pointMassDrop(0.5);
  p.seed_kind = SeedKind::PerturbedSimulation;
  p.seed_scale = 0.1;
  p.random_seed = 3;
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd simulation = seedFromSimulation(t, nullptr);
  const Seeding a = makeSeeding(t);
  const Seed a0 = a.seed(0);
  EXPECT_FALSE(a0.warm);
  EXPECT_GT((a0.x - simulation).cwiseAbs().maxCoeff(), 1e-3) << "attempt 0 is perturbed";
  EXPECT_EQ(a0.x, makeSeeding(t).seed(0).x) << "the same random seed, the same point";
  // The mesh (element lengths) is the simulation's: only positions and reactions move, and they
  // by at most seed_scale before makeConsistent (the gaps and auxiliaries follow them).
  for (const ElementLayout& L : t.layout()) EXPECT_DOUBLE_EQ(a0.x[L.h], simulation[L.h]);
  const int nv = p.scene.model.nv();
  for (const ElementLayout& L : t.layout())
    for (const auto& pt : L.points)
      for (int i = 0; i < nv; ++i) {
        EXPECT_GE(a0.x[pt.q + i] - simulation[pt.q + i], -1e-12);
        EXPECT_LE(a0.x[pt.q + i] - simulation[pt.q + i], p.seed_scale + 1e-12);
      }
  // Another random seed, another point.
  p.random_seed = 4;
  const Transcription t4(p, Method::Impulsive);
  EXPECT_GT((makeSeeding(t4).seed(0).x - a0.x).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(Seeding, NullWithoutScaleHasNothingToRestartFrom) {
  Problem p = testing::pointMassDrop(0.0);
  p.seed_kind = SeedKind::Null;
  p.seed_scale = 0;
  const Transcription t(p, Method::Impulsive);
  const Seeding s = makeSeeding(t);
  EXPECT_EQ(s.restarts, 0);
  EXPECT_EQ(s.seed(0).x, t.nullSeed());
  EXPECT_FALSE(s.seed(0).warm);
  // With a scale, attempt 0 is still the null point and the restarts are perturbed.
  p.seed_scale = 0.1;
  const Transcription u(p, Method::Impulsive);
  const Seeding r = makeSeeding(u);
  EXPECT_EQ(r.restarts, p.restarts);
  EXPECT_EQ(r.seed(0).x, u.nullSeed());
  EXPECT_NE(r.seed(1).x, u.nullSeed());
}

TEST(Seeding, SeedKindNamesReadBack) {
  for (SeedKind k : {SeedKind::Null, SeedKind::Perturbed, SeedKind::Solution, SeedKind::Simulation,
                     SeedKind::PerturbedSimulation})
    EXPECT_EQ(parseSeedKind(toString(k)), k);
  try {
    parseSeedKind("perturbed-simulatoin");
    ADD_FAILURE() << "accepted a misspelt seed kind";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'perturbed-simulation'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace scheduled_seeding_test {

// An input schedule drives the simulation seed from its file; a bad file is an error naming
// where the schedule was given (not the null seed's fallback), and a schedule beside a seed
// kind that does not simulate is refused.
TEST(Seeding, AnInputScheduleIsReadForTheSimulationSeedOnly) {
  Problem p = testing::pointMassDrop(0.0);
  p.inputs = {0};
  p.input_lower = Eigen::VectorXd::Constant(1, -30);
  p.input_upper = Eigen::VectorXd::Constant(1, 30);
  const testing::ScratchDir dir("seeding", "schedule");
  const std::string good = (dir / "good.csv").string(), bad = (dir / "bad.csv").string();
  std::ofstream(good) << "t,u.z\n0,19.62\n0.05,0\n0.4,0\n";
  std::ofstream(bad) << "t,u.z\n0,19.62\n0.05,99\n0.4,0\n";
  p.seed_kind = SeedKind::Simulation;
  p.seed_inputs = good;
  p.seed_inputs_origin = "--seed-inputs";
  {
    const Transcription t(p, Method::Impulsive);
    const Seeding s = makeSeeding(t);
    EXPECT_TRUE(s.fallback.empty()) << s.fallback;
    const auto& first = t.layout()[0];
    EXPECT_DOUBLE_EQ(s.seed(0).x[first.points[1].u], 19.62);  // pushed up at the start
    EXPECT_NEAR(s.simulation.mesh_times.back(), 0.4, 0.5 * 0.4 / p.N + 1e-12);
  }
  p.seed_inputs = bad;
  {
    const Transcription t(p, Method::Impulsive);
    const std::string m = testing::expectedMessageOf<InputScheduleError>([&] { makeSeeding(t); });
    EXPECT_EQ(m.rfind("--seed-inputs: " + bad + ": row 2", 0), 0u) << m;
  }
  p.seed_inputs = good;
  p.seed_kind = SeedKind::Perturbed;
  {
    const Transcription t(p, Method::Impulsive);
    const std::string m = testing::expectedMessageOf<std::invalid_argument>([&] { makeSeeding(t); });
    EXPECT_NE(m.find("an input schedule drives a simulation seed"), std::string::npos) << m;
    EXPECT_NE(m.find("the seed is 'perturbed'"), std::string::npos) << m;
  }
}

}  // namespace scheduled_seeding_test
}  // namespace saltus::collocation

namespace saltus::collocation {
namespace solution_seeding_test {

// An earlier solution seeds its solve warm (Ipopt's small barrier parameter) whether perturbed or
// not, in every attempt: the inelastic drop's saved solution perturbed by up to 0.1 (0.1 m on a
// 0.1 m fall) comes back to the analytic landing; unperturbed it is the saved point itself.
TEST(Seeding, AnEarlierSolutionIsWarmPerturbedOrNot) {
  Problem p = loadProblem("point_mass_drop", {{"restitution", 0}});
  p.seed_kind = SeedKind::Solution;
  p.seed_solution = std::string(SALTUS_SOURCE_DIR) + "/tests/data/solutions/point_mass_drop_inelastic";
  p.random_seed = 2;
  p.seed_scale = 0;
  const Transcription exact(p, Method::Impulsive);
  const Seeding e = makeSeeding(exact);
  EXPECT_TRUE(e.seed(0).warm);
  EXPECT_EQ(e.restarts, 0) << "nothing to restart from without a perturbation";
  EXPECT_LE(exact.largestProduct(e.seed(0).x), p.complementarity_tolerance) << "the saved solution itself";

  p.seed_scale = 0.1;
  const Transcription t(p, Method::Impulsive);
  const Seeding s = makeSeeding(t);
  const Seed first = s.seed(0), second = s.seed(1);
  EXPECT_TRUE(first.warm);
  EXPECT_TRUE(second.warm);
  EXPECT_GT((first.x - e.seed(0).x).cwiseAbs().maxCoeff(), 1e-3) << "attempt 0 is perturbed";
  EXPECT_GT((second.x - first.x).cwiseAbs().maxCoeff(), 1e-3) << "another attempt, another point";
  SolveOptions o;
  o.restarts = 0;
  testing::Solved solved;
  solved.report = solve(t, s.seed, o);
  solved.rows = trajectory(t, solved.report.x);
  testing::checkDrop(solved, 0.0);
}

}  // namespace solution_seeding_test
}  // namespace saltus::collocation
