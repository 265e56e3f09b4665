// Composite-rigid-body algorithm for the joint-space inertia matrix M(q) (RBDA Table 6.2),
// evaluated in world coordinates: with every body's inertia and joint axis expressed in the
// world frame, composite inertias add without transforms (I^c_λ += I^c_i) and each entry is
// one scalar product, M_kl = s_lᵀ (I^c_i s_k) for coordinate k of body i and l on the path from
// k to the root (RBDA 6.20 with all quantities in frame 0; s_k: column k of S, i.e. of the
// coordinate tree in model.parent_coordinate).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

// Fills data.M (both triangles), data.X_up, data.X_world, data.Ic (world coordinates) and
// data.S_world. Entries between bodies on different branches are structurally zero: Data
// sets them once.
template <class S>
const MatX<S>& crba(const Model<S>& model, Data<S>& data, const VecRef<S>& q) {
  const int n = model.nv(), nb = model.nbodies();
  for (int i = 0; i < nb; ++i) {
    const int p = model.parent[i], k = model.first_coordinate[i];
    updateJointTransform(model, data, i, q);
    data.X_world[i] = p < 0 ? data.X_up[i] : data.X_up[i] * data.X_world[p];
    data.Ic[i] = model.massless[i] ? RigidInertia<S>::Zero()
                                   : model.inertia[i].transformedBy(data.X_world[i]);  // I_i in world coordinates
    if (model.num_coordinates[i] == 1)
      data.S_world[k] = data.X_world[i].applyInverse(motionSubspace(model, i));  // ^0X_i S_i
    else
      for (int c = 0; c < model.num_coordinates[i]; ++c)
        data.S_world[k + c] = data.X_world[i].applyInverse(data.S_joint[k + c]);
  }
  for (int i = nb - 1; i >= 0; --i) {
    const int p = model.parent[i];
    if (p >= 0) data.Ic[p] += data.Ic[i];
  }
  for (int k = 0; k < n; ++k) {
    const Force<S> F = data.Ic[model.coordinate_body[k]] * data.S_world[k];  // F = I^c_i s_k
    data.M(k, k) = dot(data.S_world[k], F);
    for (int l = model.parent_coordinate[k]; l >= 0; l = model.parent_coordinate[l])
      data.M(k, l) = data.M(l, k) = dot(data.S_world[l], F);
  }
  return data.M;
}

}  // namespace saltus::dynamics
