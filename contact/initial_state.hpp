// An initial state that starts inside a surface or beyond a joint stop is a mistake in the input,
// not a state to simulate from: the time-stepper would push the body out in one step and report
// energy gained from nowhere. The contact layer measures each pair's gap at the state and names
// the pairs below −tolerance, with the depth in the unit of their gap (m for a point, m or rad
// for a stop on a length or an angle).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "scene/scene.hpp"

namespace saltus::contact {

struct Penetration {
  std::string name;     // the contact or the stop
  std::string against;  // "surface 'ground'", "the plane of link 'deck'", "its lower limit 0.5 rad"
  double depth = 0;     // −gap, in `unit`
  std::string unit;     // "m" or "rad"
};

// The pairs whose gap at q is below −tolerance (the tolerance in the pair's unit), deepest first;
// a point beyond its body plane's extent touches nothing and is not counted.
std::vector<Penetration> penetrations(const scene::Scene& scene, const Eigen::VectorXd& q, double tolerance);

// Throws std::invalid_argument when the scene's initial state penetrates: "<where>: the initial
// state puts contact 'ball' 1 m inside surface 'ground' (tolerance 1e-3 m); ...", every pair named.
constexpr double kInitialPenetrationTolerance = 1e-3;  // [m] or [rad]
void checkInitialState(const scene::Scene& scene, const std::string& where);

}  // namespace saltus::contact
