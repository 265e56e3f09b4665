// Jacobians of bodies and of points on bodies (RBDA 4.6 / 8.1): columns are the motion of
// each ancestor joint's coordinates, carried to world coordinates. The motion subspace columns
// come from data.S_joint (S_i(q) of a multi-coordinate joint, set by forwardKinematics).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

// Spatial Jacobian of body b in world coordinates: J q̇ = ^0X_b v_b, the body's spatial velocity
// (ω; velocity of the body point at the world origin), all in world coordinates. J is 6 × nv;
// columns of coordinates that do not support b are zero. Needs forwardKinematics(q).
template <class S>
void bodyJacobianWorld(const Model<S>& model, const Data<S>& data, int body,
                       MatOut<Mat6X<S>> J) {
  checkArgumentSize(model, J.cols(), "bodyJacobianWorld", "J's columns");
  J.setZero();
  for (int j = body; j >= 0; j = model.parent[j])
    for (int k = model.first_coordinate[j]; k < model.first_coordinate[j] + model.num_coordinates[j]; ++k) {
      const Motion<S> s = data.X_world[j].applyInverse(data.S_joint[k]);  // ^0X_j S_j
      J.col(k) << s.w, s.v;
    }
}

// Jacobian of a point fixed on body b (p_BP in body coordinates): J q̇ = v_WP, the point's world
// linear velocity. J is 3 × nv. Needs forwardKinematics(q).
template <class S>
void pointJacobian(const Model<S>& model, const Data<S>& data, int body, const Vec3<S>& p_BP,
                   MatOut<Mat3X<S>> J) {
  checkArgumentSize(model, J.cols(), "pointJacobian", "J's columns");
  J.setZero();
  if (body < 0) return;
  const Vec3<S> p_WP = pointPosition(data, body, p_BP);
  for (int j = body; j >= 0; j = model.parent[j])
    for (int k = model.first_coordinate[j]; k < model.first_coordinate[j] + model.num_coordinates[j]; ++k) {
      const Motion<S> s = data.X_world[j].applyInverse(data.S_joint[k]);
      J.col(k) = s.v + s.w.cross(p_WP);  // velocity of the world point at p_WP
    }
}

// J̇ q̇ of a point is pointAccelerationBias (kinematics.hpp): the point's acceleration at q̈ = 0.

}  // namespace saltus::dynamics
