// The legged benchmarks' saved solutions (biped_stop_impulsive, monopod_turn_impulsive), beyond
// the checks every saved solution passes (saved_solutions_test.cpp): the ground's impulse carrying
// the weight; replayed in Saltus' time-stepper and in Bullet with PD tracking, the deviations
// reported and tracking holding the joints closer than open loop; drawn, the robot where the
// trajectory puts it.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "collocation/solution.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/energy.hpp"
#include "tests/saltus/saved_solution_fixture.hpp"
#include "tests/support/pixels.hpp"

namespace {

using namespace saltus;
using namespace saltus::saved_solutions;
using collocation::Quantity;

class LeggedSolution : public SavedSolutionTest {};

// The feet carry the robot: over the motion the ground's vertical impulse (its impulses at the
// mesh points and its forces integrated by each element's Gauss rule) equals gravity's plus the
// change of vertical momentum, m g T + m Δċ_z, up to the collocation's own error.
TEST_P(LeggedSolution, TheGroundsImpulseCarriesTheWeight) {
  const collocation::Transcription& t = transcription();
  const Eigen::VectorXd& x = solution_->x;
  const auto& model = t.models().model<double>();
  auto& data = t.models().data<double>();
  ASSERT_EQ(t.method(), collocation::Method::Impulsive);
  double impulse = 0, duration = 0;
  for (const collocation::ElementLayout& L : t.layout()) {
    const double h = x[L.h];
    duration += h;
    for (std::size_t c = 0; c < t.contacts().size(); ++c) {
      if (t.contacts()[c].isStop()) continue;  // internal: no change of the robot's momentum
      const auto& C = L.contacts[c];
      if (C.rn[0] >= 0) impulse += x[C.rn[0]];  // the impulse at [n, 0]
      for (int j = 0; j < problem().P; ++j) impulse += h * t.lg().b[j] * x[C.rn[L.collocation[j]]];
    }
  }
  const collocation::ElementLayout& first = t.layout().front();
  const collocation::ElementLayout& last = t.layout().back();
  const int nv = model.nv();
  const double mass = model.totalMass(), g = -model.gravity.z();
  const double dvz = comVelocity(model, data, x.segment(last.points[last.end].q, nv), x.segment(last.points[last.end].v, nv)).z() -
                     comVelocity(model, data, x.segment(first.points[0].q, nv), x.segment(first.points[0].v, nv)).z();
  const double expected = mass * g * duration + mass * dvz;
  std::cout << GetParam() << ": ground's vertical impulse " << impulse << " N s against m g T + m dvz = " << expected << "\n";
  // Measured: 3 % above on the biped, 25 % on the monopod, whose 1 kg leg whips round faster
  // than its elements resolve (the momentum's rate is exact at the collocation points only).
  EXPECT_NEAR(impulse, expected, 0.3 * mass * g * duration);
}

// Tracking on the actuated joints (the base has no actuator) at 40 rad/s, critically damped, for
// the lightest of them (the smallest diagonal entry of the mass matrix at the start): the
// replay's PD forces are explicit, and gains fit for a 73 kg biped's hip would make a 1 kg
// monopod leg's step unstable (kd dt / I > 2).
verify::ReplayOptions trackingOptions(const collocation::Problem& p, verify::Feedback feedback) {
  verify::ReplayOptions o;
  o.engines = {verify::EngineKind::Saltus, verify::EngineKind::Bullet};
  o.dt = 5e-4;
  o.feedback = feedback;
  const auto& model = p.scene.model;
  dynamics::Data<double> data(model);
  const Eigen::MatrixXd M = dynamics::crba(model, data, p.scene.q0);
  double inertia = std::numeric_limits<double>::infinity();
  for (int i : p.inputs) inertia = std::min(inertia, M(i, i));
  const double omega = 40;
  o.kp = inertia * omega * omega;  // N·m/rad
  o.kd = 2 * inertia * omega;      // N·m·s/rad
  o.max_series = 200;
  return o;
}

TEST_P(LeggedSolution, ReplayedWithPdTrackingInSaltusAndBulletTheJointsStayCloserThanOpenLoop) {
  const verify::ReplayResult open = saltus::replay(solutionDir(GetParam()), trackingOptions(problem(), verify::Feedback::None));
  const verify::ReplayResult tracked = saltus::replay(solutionDir(GetParam()), trackingOptions(problem(), verify::Feedback::Pd));
  ASSERT_EQ(tracked.engines.size(), 2u);
  for (std::size_t e = 0; e < 2; ++e) {
    const verify::EngineReplay& o = open.engines[e];
    const verify::EngineReplay& r = tracked.engines[e];
    const std::string engine = verify::engineName(r.engine);
    EXPECT_TRUE(r.completed) << engine << ": " << r.message;
    EXPECT_TRUE(std::isfinite(r.max_position_deviation)) << engine;
    std::cout << GetParam() << ", " << engine << ": max position deviation open loop " << o.max_position_deviation
              << (o.completed ? "" : " (stopped: " + o.message + ")") << ", with PD tracking "
              << r.max_position_deviation << " (final " << r.final_position_deviation << "), penetration "
              << r.max_penetration << " m\n";
    // The actuated joints' deviations (the base has no actuator to hold it).
    double joints_open = 0, joints_tracked = 0;
    for (int i : problem().inputs) {
      joints_open = std::max(joints_open, o.coordinates[i].max_q);
      joints_tracked = std::max(joints_tracked, r.coordinates[i].max_q);
    }
    std::cout << "  actuated joints' largest deviation: open loop " << joints_open << ", with PD tracking " << joints_tracked << "\n";
    EXPECT_LT(joints_tracked, joints_open) << engine;
  }
}

TEST_P(LeggedSolution, DrawnFromTheSideTheRobotIsWhereTheTrajectoryPutsIt) {
  SideView view(solutionDir(GetParam()), 240, 135, 4);
  const saltus::RenderInput& input = view.input;
  const render::AnimationOptions& options = view.options;
  const render::Animation& animation = view.animation;
  const render::RenderSettings& settings = view.settings;
  render::Renderer& renderer = view.renderer;
  const int x = input.scene.model.coordinateIndex("base_x"), y = input.scene.model.coordinateIndex("base_y"),
            z = input.scene.model.coordinateIndex("base_z");
  auto base = [&](double t) {
    const Eigen::VectorXd q = input.trajectory->q(t);
    return Eigen::Vector3d(q[x], y >= 0 ? q[y] : 0.0, q[z]);
  };
  const int last = animation.frames() - 1;
  ASSERT_GE(last, 3);
  double column[2] = {0, 0}, expected[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const int frame = k == 0 ? 0 : last;
    renderer.draw(animation.camera(frame), animation.content(frame));
    const saltus::testing::Centroid drawn = saltus::testing::nonBackground(renderer.rgb(), options.width, options.height, settings.background);
    column[k] = drawn.at.x();
    EXPECT_GT(drawn.pixels, 30) << "frame " << frame << ": the robot is drawn";
    expected[k] = projectedColumn(animation.camera(frame), base(animation.time(frame)), options.width, options.height);
  }
  // The robot travels metres (the biped stops after about 4 m, the monopod hops 2.5 m along x):
  // its drawing moves across the picture with its base, up to the limbs' different poses.
  const double moved = column[1] - column[0], travelled = expected[1] - expected[0];
  EXPECT_GT(travelled, 0.3 * options.width);
  EXPECT_NEAR(moved, travelled, 0.25 * travelled);
}

INSTANTIATE_TEST_SUITE_P(Benchmarks, LeggedSolution, ::testing::Values("biped_stop_impulsive", "monopod_turn_impulsive"));

}  // namespace
