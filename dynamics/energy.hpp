// Centre of mass and mechanical energy.
#pragma once

#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

// Total mass and world position of the centre of mass into data.mass, data.com.
// Needs forwardKinematics(q).
template <class S>
const Vec3<S>& centerOfMass(const Model<S>& model, Data<S>& data) {
  data.mass = S(0);
  data.com.setZero();
  for (int i = 0; i < model.nbodies(); ++i) {
    const RigidInertia<S>& I = model.inertia[i];
    data.mass += I.m;
    // m c_W = m p_WB + R_WB h
    data.com += I.m * data.X_world[i].r + data.X_world[i].E.transpose() * I.h;
  }
  data.com /= data.mass;
  return data.com;
}

// T = ½ Σ v_iᵀ I_i v_i (RBDA 2.67). Needs forwardKinematics(q, v).
template <class S>
S kineticEnergy(const Model<S>& model, const Data<S>& data) {
  S T(0);
  for (int i = 0; i < model.nbodies(); ++i) T += dot(data.v[i], model.inertia[i] * data.v[i]);
  return T / S(2);
}

// V = −Σ m_i gᵀ c_i, zero at the world origin. Needs forwardKinematics(q).
template <class S>
S potentialEnergy(const Model<S>& model, const Data<S>& data) {
  S V(0);
  for (int i = 0; i < model.nbodies(); ++i) {
    const RigidInertia<S>& I = model.inertia[i];
    const Vec3<S> mc = I.m * data.X_world[i].r + data.X_world[i].E.transpose() * I.h;
    V -= model.gravity.dot(mc);
  }
  return V;
}

}  // namespace saltus::dynamics
