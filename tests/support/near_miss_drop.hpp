// The near-miss drop shared by the solver's tests (tests/collocation/solver_*_test.cpp): the
// inelastic point-mass drop whose feasibility stage ends just above the tolerance, a task cost on
// it, and the check that a tightening stage made it feasible.
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "collocation/problem.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/solution.hpp"
#include "collocation/solver.hpp"
#include "collocation/transcription.hpp"
#include "tests/support/drop_checks.hpp"

namespace saltus::testing {

// The inelastic drop from the perturbed simulation seed 5: a near miss of the feasibility stage.
inline collocation::Problem nearMissDrop() {
  collocation::Problem p = collocation::loadProblem("point_mass_drop");
  p.seed_kind = collocation::SeedKind::PerturbedSimulation;
  p.random_seed = 5;
  return p;
}

// A task cost on the drop: the lowest largest height (x_m, the variable x_max), weight 1.
inline void withHeightCost(collocation::Problem& p) {
  p.cost.max_coordinate = 0;
  p.cost.max_weight = 1.0;
}

// The inelastic drop with that task cost.
inline collocation::Problem heightCostDrop() {
  collocation::Problem p = collocation::loadProblem("point_mass_drop");
  withHeightCost(p);
  return p;
}

// A solve whose tightening stage (its second) made the drop feasible: it lands at the analytic time.
inline void expectTightenedDrop(const collocation::Transcription& t, const collocation::SolveReport& r) {
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[1].name, "tighten");
  EXPECT_TRUE(r.feasible) << r.stages[1].status << ", largest product " << r.largest_product;
  EXPECT_LE(r.largest_product, t.problem().complementarity_tolerance);
  Solved s;
  s.report = r;
  s.rows = collocation::trajectory(t, r.x);
  checkDrop(s, 0.0);
}

// The point x of t as a point of task (t's problem with a cost on the largest height), carried
// over by variable name, with x_m the largest height in it.
inline Eigen::VectorXd withMaxVariable(const collocation::Transcription& t, const Eigen::VectorXd& x,
                                       const collocation::Transcription& task) {
  std::map<std::string, int> index;
  const auto names = t.variableNames();
  for (int i = 0; i < t.variables(); ++i) index[names[i]] = i;
  EXPECT_EQ(index.size(), names.size());
  Eigen::VectorXd task_x = Eigen::VectorXd::Zero(task.variables());
  const auto task_names = task.variableNames();
  for (int i = 0; i < task.variables(); ++i) {
    const auto it = index.find(task_names[i]);
    if (it != index.end()) {
      task_x[i] = x[it->second];
    } else {
      EXPECT_EQ(task_names[i], "x_max");
    }
  }
  task.tightenMaxVariable(task_x);
  return task_x;
}

}  // namespace saltus::testing
