// Recursive Newton–Euler inverse dynamics, τ = M(q) q̈ + C(q, q̇) q̇ + g(q)  (RBDA Table 5.1).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"

namespace saltus::dynamics {

// The outward step of RNEA for body i, given its parent's velocity v_λ and acceleration a_λ
// (offset by −g): fills X_up[i], v[i], a_gf[i] and the body force f[i] (RBDA 5.7–5.9).
// has_qdd == false means q̈_i = 0; v_parent == nullptr means the parent is the fixed world.
template <class S>
SALTUS_INLINE void rneaForwardStep(const Model<S>& model, Data<S>& data, int i, const S& q, const S& qd,
                                   bool has_qdd, const S& qdd, const Motion<S>* v_parent,
                                   const Motion<S>& a_parent) {
  data.X_up[i] = jointTransformUp(model, i, q);
  const Motion<S> vJ = jointVelocity(model, i, qd);
  Motion<S> ai = data.X_up[i].apply(a_parent);
  if (has_qdd) ai += jointVelocity(model, i, qdd);
  if (v_parent) {
    data.v[i] = data.X_up[i].apply(*v_parent) + vJ;
    ai += data.v[i].cross(vJ);
  } else {
    data.v[i] = vJ;
  }
  data.a_gf[i] = ai;
  const RigidInertia<S>& I = model.inertia[i];
  if (model.massless[i])  // a virtual base body carries no force of its own
    data.f[i] = Force<S>::Zero();
  else
    data.f[i] = I * ai + data.v[i].crossForce(I * data.v[i]);
}

namespace detail {
// RNEA; a == nullptr means q̈ = 0 (the bias forces h = C q̇ + g).
template <class S>
const VecX<S>& rnea(const Model<S>& model, Data<S>& data, const VecRef<S>& q, const VecRef<S>& v,
                    const VecRef<S>* a) {
  const int n = model.nv();
  const Motion<S> a0{Vec3<S>::Zero(), -model.gravity};  // a_0 = −a_g: gravity as a base acceleration
  for (int i = 0; i < n; ++i) {
    const int p = model.parent[i];
    rneaForwardStep(model, data, i, q[i], v[i], a != nullptr, a ? S((*a)[i]) : S(0),
                    p < 0 ? nullptr : &data.v[p], p < 0 ? a0 : data.a_gf[p]);
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
const VecX<S>& rnea(const Model<S>& model, Data<S>& data, const VecRef<S>& q, const VecRef<S>& v,
                    const VecRef<S>& a) {
  return detail::rnea(model, data, q, v, &a);
}

// h(q, q̇) = C(q, q̇) q̇ + g(q): RNEA with q̈ = 0. Result in data.tau.
template <class S>
const VecX<S>& nonLinearEffects(const Model<S>& model, Data<S>& data, const VecRef<S>& q, const VecRef<S>& v) {
  return detail::rnea<S>(model, data, q, v, nullptr);
}

}  // namespace saltus::dynamics
