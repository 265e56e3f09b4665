// Recursive Newton–Euler inverse dynamics, τ = M(q) q̈ + C(q, q̇) q̇ + g(q)  (RBDA Table 5.1).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"

namespace saltus::dynamics {

namespace detail {
// One pass of RNEA; a == nullptr means q̈ = 0 (the bias forces h = C q̇ + g).
template <class S>
const VecX<S>& rnea(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                    const VecRef<S>& v, const VecRef<S>* a) {
  const int n = model.nv();
  const Motion<S> a0{Vec3<S>::Zero(), -model.gravity};  // a_0 = −a_g: gravity as a base acceleration
  for (int i = 0; i < n; ++i) {
    const int p = model.parent[i];
    data.X_up[i] = jointTransformUp(model, i, q[i]);
    const Motion<S> vJ = jointVelocity(model, i, v[i]);
    Motion<S> ai = data.X_up[i].apply(p < 0 ? a0 : data.a_gf[p]);
    if (a) ai += jointVelocity(model, i, (*a)[i]);
    if (p < 0) {
      data.v[i] = vJ;
    } else {
      data.v[i] = data.X_up[i].apply(data.v[p]) + vJ;
      ai += data.v[i].cross(vJ);
    }
    data.a_gf[i] = ai;
    const RigidInertia<S>& I = model.inertia[i];
    data.f[i] = I * ai + data.v[i].crossForce(I * data.v[i]);  // RBDA 5.9
  }
  for (int i = n - 1; i >= 0; --i) {
    data.tau[i] = jointForce(model, i, data.f[i]);
    const int p = model.parent[i];
    if (p >= 0) data.f[p] += data.X_up[i].applyTranspose(data.f[i]);
  }
  return data.tau;
}
}  // namespace detail

// τ = ID(q, q̇, q̈), gravity from model.gravity. Result in data.tau.
template <class S>
const VecX<S>& rnea(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                    const VecRef<S>& v, const VecRef<S>& a) {
  return detail::rnea(model, data, q, v, &a);
}

// h(q, q̇) = C(q, q̇) q̇ + g(q): RNEA with q̈ = 0. Result in data.tau.
template <class S>
const VecX<S>& nonLinearEffects(const Model<S>& model, Data<S>& data,
                                const VecRef<S>& q, const VecRef<S>& v) {
  return detail::rnea<S>(model, data, q, v, nullptr);
}

}  // namespace saltus::dynamics
