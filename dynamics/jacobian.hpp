// Jacobians of bodies and of points on bodies (RBDA 4.6 / 8.1): columns are the motion of
// each ancestor joint, carried to world coordinates.
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

// Spatial Jacobian of body b in world coordinates: J q̇ = ^0X_b v_b, the body's spatial velocity
// (ω; velocity of the body point at the world origin), all in world coordinates. J is 6 × nv;
// columns of joints that do not support b are zero. Needs forwardKinematics(q).
template <class S>
void bodyJacobianWorld(const Model<S>& model, const Data<S>& data, int body,
                       MatOut<Mat6X<S>> J) {
  J.setZero();
  for (int j = body; j >= 0; j = model.parent[j]) {
    const Motion<S> s = data.X_world[j].applyInverse(motionSubspace(model, j));  // ^0X_j S_j
    J.col(j) << s.w, s.v;
  }
}

// Jacobian of a point fixed on body b (p_BP in body coordinates): J q̇ = v_WP, the point's world
// linear velocity. J is 3 × nv. Needs forwardKinematics(q).
template <class S>
void pointJacobian(const Model<S>& model, const Data<S>& data, int body, const Vec3<S>& p_BP,
                   MatOut<Mat3X<S>> J) {
  J.setZero();
  if (body < 0) return;
  const Vec3<S> p_WP = pointPosition(data, body, p_BP);
  for (int j = body; j >= 0; j = model.parent[j]) {
    const Motion<S> s = data.X_world[j].applyInverse(motionSubspace(model, j));
    J.col(j) = s.v + s.w.cross(p_WP);  // velocity of the world point at p_WP
  }
}

// J̇ q̇ of a point is pointAccelerationBias (kinematics.hpp): the point's acceleration at q̈ = 0.

}  // namespace saltus::dynamics
