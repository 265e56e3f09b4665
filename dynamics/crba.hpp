// Composite-rigid-body algorithm for the joint-space inertia matrix M(q) (RBDA Table 6.2),
// evaluated in world coordinates: with every body's inertia and joint axis expressed in the
// world frame, composite inertias add without transforms (I^c_λ += I^c_i) and each entry is
// one scalar product, M_ij = S_jᵀ (I^c_i S_i) for j an ancestor of i (RBDA 6.20 with all
// quantities in frame 0).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"

namespace saltus::dynamics {

// Fills data.M (both triangles), data.X_up, data.X_world, data.Ic (world coordinates) and
// data.S_world. Entries between bodies on different branches are structurally zero: Data
// sets them once.
template <class S>
const MatX<S>& crba(const Model<S>& model, Data<S>& data, const VecRef<S>& q) {
  const int n = model.nv();
  for (int i = 0; i < n; ++i) {
    const int p = model.parent[i];
    data.X_up[i] = jointTransformUp(model, i, q[i]);
    data.X_world[i] = p < 0 ? data.X_up[i] : data.X_up[i] * data.X_world[p];
    data.Ic[i] = model.massless[i] ? RigidInertia<S>::Zero()
                                   : model.inertia[i].transformedBy(data.X_world[i]);  // I_i in world coordinates
    data.S_world[i] = data.X_world[i].applyInverse(motionSubspace(model, i));  // ^0X_i S_i
  }
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.parent[i];
    if (p >= 0) data.Ic[p] += data.Ic[i];
  }
  for (int i = 0; i < n; ++i) {
    const Force<S> F = data.Ic[i] * data.S_world[i];  // F = I^c_i S_i
    data.M(i, i) = dot(data.S_world[i], F);
    for (int j = model.parent[i]; j >= 0; j = model.parent[j])
      data.M(i, j) = data.M(j, i) = dot(data.S_world[j], F);
  }
  return data.M;
}

}  // namespace saltus::dynamics
