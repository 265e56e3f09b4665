// The collocation polynomials as functions of time (collocation/interpolation.hpp): they pass
// through the solved variables, follow the exact motion between the points, have the
// acceleration as the derivative of the velocity, and show the impulsive method's jumps.
#include "collocation/interpolation.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "collocation/solver.hpp"
#include "tests/support/pendulum.hpp"
#include "tests/support/rk4.hpp"

namespace saltus::collocation {
namespace {

// A pendulum swinging freely (smooth), N = 4 elements of P = 3 with fixed lengths.
struct SwingFixture : ::testing::Test {
  void SetUp() override {
    problem.scene.model = testing::pendulumModel({1.0}, {0.5});
    problem.scene.q0 = Eigen::VectorXd::Constant(1, 1.0);
    problem.scene.v0 = Eigen::VectorXd::Zero(1);
    problem.N = 4;
    problem.P = 3;
    problem.h_max = 0.1;
    problem.h_min_ratio = 1.0;
    t = std::make_unique<Transcription>(problem, Method::Impulsive);
    SolveOptions o;
    o.ipopt["tol"] = "1e-12";
    const SolveReport r = solve(*t, t->nullSeed(), o);
    ASSERT_TRUE(r.stages[0].succeeded) << r.stages[0].status;
    x = r.x;
  }
  Problem problem;
  std::unique_ptr<Transcription> t;
  Eigen::VectorXd x;
};

TEST_F(SwingFixture, PassesThroughTheVariablesAtEveryPoint) {
  const CollocationTrajectory traj(*t, x);
  ASSERT_EQ(traj.elements(), 4);
  EXPECT_NEAR(traj.endTime(), 0.4, 1e-12);
  for (int n = 0; n < 4; ++n) {
    const ElementLayout& L = t->layout()[n];
    for (std::size_t p = 0; p < L.points.size(); ++p) {
      const double time = traj.meshTimes()[n] + x[L.h] * L.tau[p];
      const Side side = static_cast<int>(p) == L.end ? Side::Before : Side::After;
      const TrajectoryPoint e = traj.at(time, side);
      EXPECT_NEAR(e.q[0], x[L.points[p].q], 1e-9) << "[" << n << ", " << p << "]";
      EXPECT_NEAR(e.v[0], x[L.points[p].v], 1e-9) << "[" << n << ", " << p << "]";
      if (p > 0 && static_cast<int>(p) != L.end) {
        EXPECT_NEAR(e.a[0], x[L.points[p].accel_or_jump], 1e-9);
      }
    }
  }
}

TEST_F(SwingFixture, FollowsTheExactMotionBetweenPoints) {
  const CollocationTrajectory traj(*t, x);
  for (double time : {0.013, 0.071, 0.15, 0.2317, 0.333, 0.399}) {
    const auto [q, v] = testing::rk4Reference(problem.scene.model, problem.scene.q0, problem.scene.v0,
                                              Eigen::VectorXd::Zero(1), time, 4000);
    const TrajectoryPoint e = traj.at(time);
    // Between the points the polynomial is accurate to O(h^(P+1)) (not the 2P of mesh points).
    EXPECT_NEAR(e.q[0], q[0], 1e-4) << "t = " << time;
    EXPECT_NEAR(e.v[0], v[0], 1e-3) << "t = " << time;
  }
}

// q̈(t) is the derivative of the velocity polynomial everywhere; the position polynomial's
// derivative is the velocity at the collocation points (eq. 3), not in between (the two state
// polynomials are separate).
TEST_F(SwingFixture, AccelerationIsTheDerivativeOfVelocityAndVelocityOfPosition) {
  const CollocationTrajectory traj(*t, x);
  const double d = 1e-6;
  for (double time : {0.02, 0.13, 0.26, 0.37}) {
    const TrajectoryPoint a = traj.at(time - d), b = traj.at(time + d), c = traj.at(time);
    EXPECT_NEAR((b.v[0] - a.v[0]) / (2 * d), c.a[0], 1e-6) << "t = " << time;
  }
  for (int n = 0; n < traj.elements(); ++n) {
    const ElementLayout& L = t->layout()[n];
    for (int p : L.collocation) {
      const double time = traj.meshTimes()[n] + x[L.h] * L.tau[p];
      const TrajectoryPoint a = traj.at(time - d), b = traj.at(time + d);
      EXPECT_NEAR((b.q[0] - a.q[0]) / (2 * d), x[L.points[p].v], 1e-6) << "[" << n << ", " << p << "]";
    }
  }
}

TEST_F(SwingFixture, OutsideTheTrajectoryIsAnError) {
  const CollocationTrajectory traj(*t, x);
  EXPECT_THROW(traj.at(-0.01), std::out_of_range);
  EXPECT_THROW(traj.at(0.41), std::out_of_range);
  EXPECT_NO_THROW(traj.at(0.4));
  EXPECT_EQ(traj.elementAt(0.1, Side::Before), 0);
  EXPECT_EQ(traj.elementAt(0.1, Side::After), 1);
  EXPECT_EQ(traj.elementAt(0.4, Side::After), 3);
}

TEST_F(SwingFixture, AJumpShowsAsTwoLimits) {
  // Put a velocity jump of 0.7 at [2, 0] by hand: the left limit is the previous element's end,
  // the right limit that plus the jump, and jumps() lists it.
  Eigen::VectorXd y = x;
  const auto& L = t->layout()[2];
  y[L.points[0].accel_or_jump] = 0.7;
  y[L.points[0].v] += 0.7;
  const CollocationTrajectory traj(*t, y);
  const double tm = traj.meshTimes()[2];
  EXPECT_NEAR(traj.at(tm, Side::After).v[0] - traj.at(tm, Side::Before).v[0], 0.7, 1e-9);
  EXPECT_NEAR(traj.at(tm, Side::After).q[0], traj.at(tm, Side::Before).q[0], 1e-9);
  const auto jumps = traj.jumps(1e-3);
  ASSERT_EQ(jumps.size(), 1u);
  EXPECT_EQ(jumps[0].element, 2);
  EXPECT_NEAR(jumps[0].t, tm, 1e-12);
  EXPECT_NEAR(jumps[0].dv[0], 0.7, 1e-12);
}

}  // namespace
}  // namespace saltus::collocation
