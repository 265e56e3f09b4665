// The paper's two built-in problems built in C++ (the same as models/problems/*.yaml), so the
// collocation tests do not depend on the problem-file reader.
#pragma once

#include "collocation/problem.hpp"
#include "tests/support/scenes.hpp"

namespace saltus::testing {

// Fig. 3: a point mass dropped from `height` onto the ground, penalty cost only.
inline collocation::Problem pointMassDrop(double e, double height = 0.1, int N = 20, int P = 4) {
  collocation::Problem p;
  p.name = "point_mass_drop";
  p.scene = ballDrop(height, e);
  p.N = N;
  p.P = P;
  p.h_max = 0.02;
  p.total_time_kind = collocation::TotalTime::AtLeast;
  p.total_time = 0.2;
  return p;
}

// Fig. 4: the pendulum whose tip rests on a belt that steps to `belt_speed` at [6, 0].
inline collocation::Problem pendulumConveyor(double mu = 2.0, double belt_speed = 0.5, int P = 4) {
  collocation::Problem p;
  p.name = "pendulum_conveyor";
  p.scene = testing::pendulumConveyor(mu, belt_speed, 0.0);
  p.scene.surfaces[0].velocity_schedule.clear();
  p.surface_steps[0] = {{5, Eigen::Vector3d(belt_speed, 0, 0)}};
  p.N = 10;
  p.P = P;
  p.h_max = 0.02;
  p.total_time_kind = collocation::TotalTime::AtLeast;
  p.total_time = 0.1;
  return p;
}

// A ball dropped onto a paddle that turns about the y axis (tests/support/scenes.hpp): contact
// between two moving bodies, the plane's frame turning with q.
inline collocation::Problem ballOnPaddleProblem(double e, double mu, int N = 3, int P = 3) {
  collocation::Problem p;
  p.name = "ball_on_paddle";
  p.scene = testing::ballOnPaddle(e, mu);
  p.N = N;
  p.P = P;
  p.h_max = 0.05;
  p.total_time_kind = collocation::TotalTime::AtLeast;
  p.total_time = 0.1;
  return p;
}

// The same with its contact point free along the paddle (ContactPair::free_axes): on t1 alone
// (the planar scene's), or on both axes as a spatial plane's would be.
inline collocation::Problem ballOnPaddleFreePoint(double e, double mu, std::vector<int> axes, int N = 3, int P = 3) {
  collocation::Problem p = ballOnPaddleProblem(e, mu, N, P);
  p.scene.contacts.at(0).free_axes = std::move(axes);
  return p;
}

}  // namespace saltus::testing
