// A scene contact as a reference engine reports it after a step (bullet_world.hpp,
// mujoco_world.hpp): gap and velocities from saltus' contact layer at the engine's (q, v), so
// that every engine is measured alike; impulses from the engine's own contact solution.
#pragma once

#include <vector>

#include "contact/pair.hpp"
#include "dynamics/data.hpp"
#include "scene/scene.hpp"

namespace saltus::verify {

struct MeasuredContact {
  bool active = false;  // the engine had this contact in its solution in the last step
  // gap, normal and tangential velocity (relative to the surface, basis t1, t2 of
  // Surface::tangents) at the end of the step; impulses over the step on the point's body
  // (friction projected on t1, t2).
  double gap = 0, vn = 0, vt1 = 0, vt2 = 0, pn = 0, pt1 = 0, pt2 = 0;
};

// Fills gap, vn, vt1, vt2 of each scene contact (the first scene.contacts.size() pairs) from the
// kinematics in `data` (forwardKinematics at q, v done by the caller; a world surface's velocity
// at t), clears `active` and the impulses. Returns the largest −gap (over a body's plane only
// within its extent: beyond its edge a point below it is not penetrating).
double measureContactKinematics(const scene::Scene& scene, const std::vector<contact::ContactPair>& pairs,
                                const dynamics::Data<double>& data, const double* q, double t,
                                std::vector<MeasuredContact>& reports);

}  // namespace saltus::verify
