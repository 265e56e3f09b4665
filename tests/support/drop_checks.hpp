// The point-mass drop's analytic solution (paper Fig. 3) as checks on a solved trajectory, shared
// by the solver's tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "collocation/problem.hpp"
#include "collocation/solution.hpp"
#include "collocation/solver.hpp"
#include "collocation/transcription.hpp"

namespace saltus::testing {

struct Solved {
  collocation::Problem problem;
  std::unique_ptr<collocation::Transcription> t;
  collocation::SolveReport report;
  std::vector<collocation::Sample> rows;
};

// The point-mass drop: free flight exact for the polynomial, the impact at an element boundary at
// t = √(2h/g) with v⁺ = −e v⁻, no penetration.
inline void checkDrop(const Solved& s, double e) {
  ASSERT_TRUE(s.report.feasible) << s.report.stages.back().status << ", largest product " << s.report.largest_product;
  const double g = 9.81, h0 = 0.1, t_impact = std::sqrt(2 * h0 / g), v_impact = -std::sqrt(2 * g * h0);
  const double tol = 1e-3;  // complementarity products ≤ 1e-4 leave the contact this loose
  int impact_row = -1;
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    const collocation::Sample& r = s.rows[i];
    EXPECT_GT(r.contacts[0].gap, -1e-8) << "penetration at t = " << r.t;
    if (impact_row < 0 && r.contacts[0].pn > 1e-3) impact_row = static_cast<int>(i);
    if (impact_row < 0 && r.t < t_impact - tol) {  // free flight: exact at every point
      // The relaxation A·B ≤ ε leaves forces of up to ε / Σy in flight: at the problem file's
      // Ipopt tol 1e-8 the free fall is exact to 1e-7 m/s (4e-6 at tol 1e-6).
      EXPECT_NEAR(r.q[0], h0 - g * r.t * r.t / 2, 1e-6) << "t = " << r.t;
      EXPECT_NEAR(r.v[0], -g * r.t, 1e-6) << "t = " << r.t;
    }
  }
  ASSERT_GT(impact_row, 0) << "no impulse";
  const collocation::Sample& after = s.rows[impact_row];
  const collocation::Sample& before = s.rows[impact_row - 1];
  EXPECT_EQ(after.point, 0) << "the impulse acts at a mesh point [n, 0]";
  EXPECT_DOUBLE_EQ(before.t, after.t) << "a velocity jump gives two rows at the same time";
  EXPECT_NEAR(after.t, t_impact, tol);
  EXPECT_NEAR(before.v[0], v_impact, 5 * tol);
  EXPECT_NEAR(after.v[0], -e * before.v[0], 0.01);
  EXPECT_NEAR(after.contacts[0].pn, after.v[0] - before.v[0], 1e-6) << "impulse = m Δv (eq. 6)";
}

}  // namespace saltus::testing
