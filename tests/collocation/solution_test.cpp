// The paper's mean local error (collocation/solution.hpp, §V.D, Fig. 7) on trajectories whose
// error is known in closed form: a point mass in free flight above the ground (no reaction), its
// polynomials built by hand on elements of different lengths. A parabola is a collocation
// polynomial, so free fall has no error; an acceleration off by δ leaves h·|δ| on each element
// (the error integrated in time), relative to the largest speed there; the first-order method's
// backward-Euler step leaves h²·g/2 in the position, relative to the largest height.
#include "collocation/solution.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/support/problems.hpp"

namespace saltus::collocation {
namespace {

constexpr double kHeight = 10.0;  // far above the ground over the whole trajectory

// Element n lasts 0.01 (n + 1) s: different lengths, so that a missing or extra factor h shows.
double elementLength(int n) { return 0.01 * (n + 1); }

// x for the collocation methods: z(t) = kHeight + a t² / 2 at every point, q̈ = a at the
// collocation points, no jump and no reaction.
Eigen::VectorXd parabola(const Transcription& t, double a) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(t.variables());
  double t0 = 0;
  for (const ElementLayout& L : t.layout()) {
    const double h = elementLength(static_cast<int>(&L - t.layout().data()));
    x[L.h] = h;
    for (std::size_t p = 0; p < L.points.size(); ++p) {
      const double tp = t0 + L.tau[p] * h;
      x[L.points[p].q] = kHeight + a * tp * tp / 2;
      x[L.points[p].v] = a * tp;
    }
    for (int p : L.collocation) x[L.points[p].accel_or_jump] = a;
    t0 += h;
  }
  return x;
}

// The expected mean when only q̈ is off, by δ: (1/2) × mean over elements of h |δ| / max |q̇|
// (two state variables, z and ż, and ż's polynomial exact in q).
double expectedVelocityError(const Transcription& t, const Eigen::VectorXd& x, double delta) {
  double v_max = 0;
  for (const ElementLayout& L : t.layout())
    for (const auto& pt : L.points) v_max = std::max(v_max, std::abs(x[pt.v]));
  double sum = 0;
  for (const ElementLayout& L : t.layout()) {
    double sv = 0;
    for (const auto& pt : L.points) sv = std::max(sv, std::abs(x[pt.v]));
    sum += x[L.h] * std::abs(delta) / std::max(sv, 0.01 * v_max);
  }
  return sum / (2.0 * t.elements());
}

class MeanLocalError : public ::testing::TestWithParam<Method> {};

TEST_P(MeanLocalError, FreeFallIsExactAndAnAccelerationErrorCountsOverTime) {
  const collocation::Problem p = testing::pointMassDrop(0.0, kHeight, 5, 3);
  const Transcription t(p, GetParam());
  const double g = -p.scene.model.gravity.z();
  EXPECT_LT(meanLocalError(t, parabola(t, -g)), 1e-12);
  for (double delta : {0.5, -2.0}) {
    const Eigen::VectorXd x = parabola(t, -g + delta);
    const double expected = expectedVelocityError(t, x, delta);
    EXPECT_NEAR(meanLocalError(t, x), expected, 1e-9 * expected) << "delta " << delta;
  }
}

INSTANTIATE_TEST_SUITE_P(CollocationMethods, MeanLocalError, ::testing::Values(Method::Impulsive, Method::Continuous),
                         [](const auto& info) { return std::string(toString(info.param)); });

TEST(MeanLocalErrorFirstOrder, TheBackwardEulerStepLeavesHalfGhSquaredInThePosition) {
  const collocation::Problem p = testing::pointMassDrop(0.0, kHeight, 5, 3);
  const Transcription t(p, Method::FirstOrder);
  const double g = -p.scene.model.gravity.z();
  // Backward Euler steps of free fall: v1 = v0 − g h, z1 = z0 + h v1 (its dynamics exact).
  Eigen::VectorXd x = Eigen::VectorXd::Zero(t.variables());
  double z = kHeight, v = 0, expected = 0;
  for (const ElementLayout& L : t.layout()) {
    const double h = elementLength(static_cast<int>(&L - t.layout().data()));
    ASSERT_EQ(L.points.size(), 2u);
    x[L.h] = h;
    x[L.points[0].q] = z;
    x[L.points[0].v] = v;
    const double v1 = v - g * h, z1 = z + h * v1;
    x[L.points[1].q] = z1;
    x[L.points[1].v] = v1;
    x[L.points[1].accel_or_jump] = -g;
    // q̇ on the step is v1 against the linear ż(s) = v + (v1 − v) s: ∫ |v1 − ż| dt = h² g / 2.
    expected += h * h * g / 2 / std::max(std::abs(z), std::abs(z1));
    z = z1;
    v = v1;
  }
  expected /= 2.0 * t.elements();
  EXPECT_NEAR(meanLocalError(t, x), expected, 1e-9 * expected);
}

}  // namespace
}  // namespace saltus::collocation
