// Recursive Newton–Euler inverse dynamics, τ = M(q) q̈ + C(q, q̇) q̇ + g(q)  (RBDA Table 5.1).
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

// The outward step of RNEA for body i, given ^iX_λ in data.X_up, its joint's v_J, the acceleration
// terms a_i so far and its parent's velocity v_λ: fills v[i], a_gf[i] (a_i offset by −g) and the
// body force f[i] (RBDA 5.7–5.9):
//   v_i = ^iX_λ v_λ + S_i q̇_i,  a_i = ^iX_λ a_λ + S_i q̈_i + c_J + v_i × S_i q̇_i,
//   f_i = I_i a_i + v_i ×* I_i v_i.
// v_parent == nullptr means the parent is the fixed world.
template <class S>
SALTUS_INLINE void rneaForwardStep(const Model<S>& model, Data<S>& data, int i, const Motion<S>& vJ, Motion<S> ai,
                                   const Motion<S>* v_parent) {
  if (v_parent) {
    data.v[i] = data.X_up[i].apply(*v_parent) + vJ;
    ai += data.v[i].cross(vJ);
  } else {
    data.v[i] = vJ;
  }
  data.a_gf[i] = ai;
  const RigidInertia<S>& I = model.inertia[i];
  if (model.massless[i])  // an intermediate link of a multi-axis mechanism carries no force of its own
    data.f[i] = Force<S>::Zero();
  else
    data.f[i] = I * ai + data.v[i].crossForce(I * data.v[i]);
}
// The same for a one-coordinate joint whose ^iX_λ is in data.X_up (withJoint), with its
// transform and motion subspace in the forms of its kernel, given the parent's acceleration
// a_λ. qd, qdd are the joint's coordinate; qdd == nullptr means q̈_i = 0.
template <class S>
SALTUS_INLINE void rneaForwardStep(const Model<S>& model, Data<S>& data, int i, const S& qd,
                                   const S* qdd, const Motion<S>* v_parent, const Motion<S>& a_parent) {
  withEvaluatedJoint(model, data.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
    Motion<S> vi, ai = X.apply(a_parent);
    if (v_parent) {
      vi = X.apply(*v_parent);
      Si.addTo(vi, qd);
      ai += Si.crossVelocity(vi, qd);  // v_i × S_i q̇_i
    } else {
      vi = Si.velocity(qd);
    }
    if (qdd) Si.addTo(ai, *qdd);
    data.v[i] = vi;
    data.a_gf[i] = ai;
    const RigidInertia<S>& I = model.inertia[i];
    if (model.massless[i])
      data.f[i] = Force<S>::Zero();
    else
      data.f[i] = I * ai + vi.crossForce(I * vi);
  });
}
// The same for a multi-coordinate joint, out of line: it runs once per call (the base), and
// inlined it slows the loop over the one-coordinate joints.
// q == nullptr: data.X_up[i] and the joint's S_i columns in data.S_joint are current.
template <class S>
[[gnu::noinline]] void rneaMultiForwardStep(const Model<S>& model, Data<S>& data, int i, const S* q, const S* qd,
                                            const S* qdd, const Motion<S>* v_parent, const Motion<S>& a_parent) {
  Motion<S>* Scol = &data.S_joint[model.first_coordinate[i]];
  if (q) data.X_up[i] = multiJointTransformUp(model, i, q, Scol);
  const Motion<S> vJ = multiJointVelocity(model, i, Scol, qd);
  Motion<S> ai = data.X_up[i].apply(a_parent) + multiJointBias(model, i, Scol, qd, vJ);
  if (qdd) ai += multiJointVelocity(model, i, Scol, qdd);
  rneaForwardStep(model, data, i, vJ, ai, v_parent);
}

// τ_i = S_iᵀ f_i into tau[first_coordinate[i] ...] (RBDA Table 5.1, inward loop).
template <class S>
SALTUS_INLINE void jointForces(const Model<S>& model, const Data<S>& data, int i, const Force<S>& f, S* tau) {
  if (model.num_coordinates[i] == 1)
    *tau = jointForce(model, i, f);
  else
    multiJointForce(model, i, &data.S_joint[model.first_coordinate[i]], f, tau);
}

namespace detail {
// RNEA; a == nullptr means q̈ = 0 (the bias forces h = C q̇ + g); q == nullptr means the joint
// transforms in data (X_up, and S_joint of a multi-coordinate joint) are current.
template <class S>
const VecX<S>& rnea(const Model<S>& model, Data<S>& data, const VecRef<S>* q, const VecRef<S>& v,
                    const VecRef<S>* a) {
  const int nb = model.nbodies();
  const Motion<S> a0{Vec3<S>::Zero(), -model.gravity};  // a_0 = −a_g: gravity as a base acceleration
  // A multi-coordinate joint can only be body 0's (model.hpp); the loops take the others.
  const int b = nb > 0 && model.num_coordinates[0] > 1 ? 1 : 0;
  if (b) rneaMultiForwardStep<S>(model, data, 0, q ? q->data() : nullptr, v.data(), a ? a->data() : nullptr, nullptr, a0);
  const int off = model.nv() - nb;  // coordinate k = i + off of body i ≥ b
  // Joint transforms (jcalc) in a loop of their own: its libm calls would otherwise spill the
  // registers of the loop below.
  if (q) updateOneCoordinateJointTransforms(model, data, *q);
  for (int i = b; i < nb; ++i) {
    const int p = model.parent[i], k = i + off;
    rneaForwardStep(model, data, i, v[k], a ? a->data() + k : nullptr, p < 0 ? nullptr : &data.v[p],
                    p < 0 ? a0 : data.a_gf[p]);
  }
  for (int i = nb - 1; i >= b; --i) {
    const int p = model.parent[i];
    withEvaluatedJoint(model, data.X_up[i], i, [&](const auto& X, const auto& Si) {
      data.tau[i + off] = Si.project(data.f[i]);
      if (p >= 0) data.f[p] += X.applyTranspose(data.f[i]);
    });
  }
  if (b) multiJointForce(model, 0, data.S_joint.data(), data.f[0], data.tau.data());
  return data.tau;
}
}  // namespace detail

// τ = ID(q, q̇, q̈), gravity from model.gravity. Result in data.tau.
template <class S>
const VecX<S>& rnea(const Model<S>& model, Data<S>& data, const VecRef<S>& q, const VecRef<S>& v,
                    const VecRef<S>& a) {
  checkConfigurationSize(model, q.size(), "rnea", "q");
  checkArgumentSize(model, v.size(), "rnea", "v");
  checkArgumentSize(model, a.size(), "rnea", "a");
  return detail::rnea(model, data, &q, v, &a);
}

// h(q, q̇) = C(q, q̇) q̇ + g(q): RNEA with q̈ = 0. Result in data.tau.
template <class S>
const VecX<S>& nonLinearEffects(const Model<S>& model, Data<S>& data, const VecRef<S>& q, const VecRef<S>& v) {
  checkConfigurationSize(model, q.size(), "nonLinearEffects", "q");
  checkArgumentSize(model, v.size(), "nonLinearEffects", "v");
  return detail::rnea<S>(model, data, &q, v, nullptr);
}

// h(q, q̇) at the q of the last call that evaluated the joint transforms (forwardKinematics,
// forwardVelocities, crba, rnea, nonLinearEffects, aba): their X_up and S_joint are reused, so a
// caller that needs M(q) and h at several velocities pays for jcalc once (timestepper/stepper.cpp).
template <class S>
const VecX<S>& nonLinearEffectsAtCurrentPoses(const Model<S>& model, Data<S>& data, const VecRef<S>& v) {
  checkArgumentSize(model, v.size(), "nonLinearEffectsAtCurrentPoses", "v");
  return detail::rnea<S>(model, data, nullptr, v, nullptr);
}

}  // namespace saltus::dynamics
