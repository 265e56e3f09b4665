// The solver's attempts (collocation/solver.hpp): restarts from the seed function after an
// infeasible end, and the chain of re-simulated attempts (SolveOptions::resimulate) before them,
// which start without the hints and from the warm start's own barrier.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "collocation/problem_file.hpp"
#include "collocation/simulation_seed.hpp"
#include "collocation/solver.hpp"

namespace saltus::collocation {
namespace {

TEST(Solver, RestartsAfterAnInfeasibleEnd) {
  const Problem p = loadProblem("point_mass_drop", {{"restitution", 0.5}});
  const Transcription t(p, Method::Impulsive);
  SolveOptions o;
  o.restarts = 3;
  std::vector<int> asked;
  const SolveReport r = solve(
      t,
      [&](int k) {
        asked.push_back(k);
        Seed s{seedFromSimulation(t), true};  // solves (PointMassDropHalfElastic)
        if (k == 0) s.x[t.layout()[3].points[1].q] = std::nan("");  // attempt 0 cannot even start
        return s;
      },
      o);
  EXPECT_EQ(asked, (std::vector<int>{0, 1}));
  ASSERT_EQ(r.attempts.size(), 2u);
  EXPECT_FALSE(r.attempts[0].feasible);
  EXPECT_TRUE(r.attempts[1].feasible);
  EXPECT_TRUE(r.feasible);
  EXPECT_EQ(r.iterations, r.attempts[0].iterations + r.attempts[1].iterations);
  EXPECT_LE(r.largest_product, p.complementarity_tolerance);
}

// After an infeasible attempt the re-simulation is asked for a point from that attempt's end,
// and the chain runs before the next restart: attempt 0 from a seed that cannot start, then its
// re-simulation (here the simulation seed, which solves) is feasible and no restart is asked for.
TEST(Solver, ResimulatesFromAnInfeasibleEndBeforeRestarting) {
  const Problem p = loadProblem("point_mass_drop", {{"restitution", 0.5}});
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd simulated = seedFromSimulation(t);
  SolveOptions o;
  o.restarts = 2;
  o.resimulations = 2;
  std::vector<Eigen::VectorXd> ends;
  o.resimulate = [&](const Eigen::VectorXd& end) -> std::optional<Seed> {
    ends.push_back(end);
    return Seed{simulated, true};
  };
  std::vector<int> asked;
  const SolveReport r = solve(
      t,
      [&](int k) {
        asked.push_back(k);
        Seed s{simulated, true};
        s.x[t.layout()[3].points[1].q] = std::nan("");  // no attempt from the seed can start
        return s;
      },
      o);
  EXPECT_EQ(asked, (std::vector<int>{0}));
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_TRUE(std::isnan(ends[0][t.layout()[3].points[1].q])) << "the re-simulation gets attempt 0's end point";
  ASSERT_EQ(r.attempts.size(), 2u);
  EXPECT_EQ(r.attempts[0].attempt, 0);
  EXPECT_EQ(r.attempts[0].resimulation, 0);
  EXPECT_FALSE(r.attempts[0].feasible);
  EXPECT_EQ(r.attempts[1].attempt, 0);
  EXPECT_EQ(r.attempts[1].resimulation, 1);
  EXPECT_TRUE(r.attempts[1].feasible);
  EXPECT_TRUE(r.feasible);
  EXPECT_LE(r.largest_product, p.complementarity_tolerance);
}

// A re-simulation that fails (std::nullopt: the time-stepper could not run) ends its chain and
// the next restart follows; re-simulations that stay infeasible run to their count.
TEST(Solver, AFailedResimulationEndsItsChain) {
  const Problem p = loadProblem("point_mass_drop", {{"restitution", 0.5}});
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd simulated = seedFromSimulation(t);
  Eigen::VectorXd broken = simulated;
  broken[t.layout()[3].points[1].q] = std::nan("");
  for (const bool simulates : {false, true}) {
    SolveOptions o;
    o.restarts = 1;
    o.resimulations = 2;
    int resimulated = 0;
    o.resimulate = [&](const Eigen::VectorXd&) -> std::optional<Seed> {
      ++resimulated;
      if (!simulates) return std::nullopt;
      return Seed{broken, true};
    };
    std::vector<int> asked;
    const SolveReport r = solve(
        t,
        [&](int k) {
          asked.push_back(k);
          return Seed{broken, true};
        },
        o);
    EXPECT_EQ(asked, (std::vector<int>{0, 1})) << simulates;
    EXPECT_FALSE(r.feasible);
    // Without a simulation: one question a restart, no attempt from it; with one: two each.
    EXPECT_EQ(resimulated, simulates ? 4 : 2);
    ASSERT_EQ(r.attempts.size(), simulates ? 6u : 2u);
    if (simulates) {
      const std::vector<std::pair<int, int>> expected = {{0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2}};
      for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(r.attempts[i].attempt, expected[i].first) << i;
        EXPECT_EQ(r.attempts[i].resimulation, expected[i].second) << i;
      }
    }
  }
}

// A re-simulated seed (Seed::hinted false, keep_warm_start true) starts without the hints and in
// the warm start's own barrier over the options given for the solve. The hint puts the dropped
// mass on the ground at [2, 1], within 0.04 s of its release from 0.1 m (it lands at 0.143 s):
// a first stage within it cannot meet the equations of motion; without it the simulation seed is
// a solution at once, and no task stage follows (the drop has no task cost; hints would call one).
TEST(Solver, AResimulatedSeedDropsTheHintsAndKeepsItsWarmStart) {
  Problem p = loadProblem("point_mass_drop", {{"restitution", 0.5}});
  p.hints.push_back({{Quantity::Kind::Gap, 0}, 1, 1, 0.0, 0.0, "test"});
  const Transcription t(p, Method::Impulsive);
  const Eigen::VectorXd simulated = seedFromSimulation(t);
  SolveOptions o;
  o.ipopt["mu_strategy"] = "adaptive";  // chosen for a cold seed
  o.ipopt["bound_push"] = "0.01";
  o.ipopt["max_iter"] = "100";  // the hinted stage cannot succeed; the unhinted one needs few
  const auto from = [&](const Seed& s) { return solve(t, [&](int) { return s; }, o); };

  const SolveReport hinted = from(Seed{simulated, true});
  ASSERT_FALSE(hinted.stages.empty());
  EXPECT_GT(hinted.stages.front().largest_violation, 1e-3) << "the hint holds in the first stage";
  EXPECT_EQ(hinted.stages.front().barrier, "adaptive") << "the options given hold over a warm seed's start";

  const SolveReport resimulated = from(Seed{simulated, true, false, true});
  ASSERT_EQ(resimulated.stages.size(), 1u) << "without the hints no task stage follows (no task cost)";
  EXPECT_EQ(resimulated.stages.front().barrier, "monotone");
  EXPECT_TRUE(resimulated.feasible);
  const auto& point = t.layout()[1].points[1];
  EXPECT_GT(resimulated.x[point.q], 0.09) << "the mass is still falling at [2, 1], off the hint";
}

}  // namespace
}  // namespace saltus::collocation
