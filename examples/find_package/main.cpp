// Drops a ball on the ground with Saltus' time-stepper, through the library API, and prints its
// first rebound apex (Newton's restitution: e² h = 0.25 m for e = 0.5, h = 1 m).
#include <algorithm>
#include <cstdio>

#include "saltus/saltus.hpp"

int main() {
  const saltus::scene::Scene scene = saltus::loadScene("ball_drop", {{"restitution", 0.5}});
  const saltus::Simulation run = saltus::simulate(scene, {.dt = 1e-3, .duration = 1.5});
  double apex = 0;
  for (Eigen::Index k = 0; k < run.t.size(); ++k)
    if (run.t[k] > 0.5) apex = std::max(apex, run.q(k, 0));
  std::printf("first apex %.4f m\n", apex);
  saltus::writeTrajectoryCsv("ball_drop.csv", run);
}
