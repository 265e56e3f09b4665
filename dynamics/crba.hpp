// Composite-rigid-body algorithm for the joint-space inertia matrix M(q) (RBDA Table 6.2).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"

namespace saltus::dynamics {

// Fills data.M (both triangles) and data.X_up. Entries between bodies on different branches
// are structurally zero: Data sets them once.
template <class S>
const MatX<S>& crba(const Model<S>& model, Data<S>& data, const VecRef<S>& q) {
  const int n = model.nv();
  for (int i = 0; i < n; ++i) {
    data.X_up[i] = jointTransformUp(model, i, q[i]);
    data.Ic[i] = model.inertia[i];
  }
  // Composite inertias: I^c_λ(i) += ^iX_λᵀ I^c_i ^iX_λ.
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.parent[i];
    if (p >= 0) data.Ic[p] += data.Ic[i].transformedBy(data.X_up[i]);
  }
  for (int i = 0; i < n; ++i) {
    Force<S> F = data.Ic[i] * motionSubspace(model, i);  // F = I^c_i S_i
    data.M(i, i) = jointForce(model, i, F);
    for (int j = i; model.parent[j] >= 0;) {
      F = data.X_up[j].applyTranspose(F);  // F = ^jX_λ(j)ᵀ F
      j = model.parent[j];
      data.M(i, j) = data.M(j, i) = jointForce(model, j, F);
    }
  }
  return data.M;
}

}  // namespace saltus::dynamics
