// Drops a ball on the ground with Saltus' time-stepper and prints its first rebound apex
// (Newton's restitution: e² h = 0.25 m for e = 0.5, h = 1 m).
#include <algorithm>
#include <cstdio>

#include "scene/scenario.hpp"
#include "timestepper/stepper.hpp"

int main() {
  const saltus::scene::Scene scene = saltus::scene::loadScene("ball_drop", {{"restitution", 0.5}});
  saltus::timestepper::TimeStepper sim(scene, saltus::timestepper::StepperOptions{});
  double apex = 0;
  while (sim.time() < 1.5) {
    sim.step();
    if (sim.time() > 0.5) apex = std::max(apex, sim.q()[0]);
  }
  std::printf("first apex %.4f m\n", apex);
}
