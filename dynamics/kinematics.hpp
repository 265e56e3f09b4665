// Forward kinematics: body poses, velocities and accelerations (RBDA 4.4 / Table 5.1, first
// loop), and poses, velocities and accelerations of points on bodies.
#pragma once

#include <type_traits>

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"

namespace saltus::dynamics {

// ^iX_λ(i) for body i; for a multi-coordinate joint also its S_i(q) columns into data.S_joint.
template <class S>
SALTUS_INLINE const Transform<S>& updateJointTransform(const Model<S>& model, Data<S>& data, int i, const VecRef<S>& q) {
  const int k = model.first_coordinate[i], kq = model.first_position[i];
  data.X_up[i] = model.num_coordinates[i] == 1 ? jointTransformUp(model, i, q[kq])
                                               : multiJointTransformUp(model, i, q.data() + kq, &data.S_joint[k]);
  return data.X_up[i];
}

// jcalc (RBDA 4.4) for the one-coordinate joints, bodies b ≤ i < nb after a multi-coordinate root
// (b = 1) or all (b = 0): ^iX_λ into data.X_up in the forms of withJoint. For double the cos and
// sin of their coordinates (contiguous, q index i + nq − nb) are computed together first
// (sinCosMany) into data.cos_q, data.sin_q. RNEA, CRBA and ABA share it, so their X_up agree to
// the last bit.
template <class S>
void updateOneCoordinateJointTransforms(const Model<S>& model, Data<S>& data, const VecRef<S>& q) {
  const int nb = model.nbodies();
  const int b = nb > 0 && model.num_coordinates[0] > 1 ? 1 : 0;
  const int off = model.nq() - nb;
  const auto none = [](const auto&, const auto&) SALTUS_LAMBDA_INLINE {};
  if constexpr (std::is_same_v<S, double>) {
    sinCosMany(q.data() + b + off, nb - b, data.sin_q.data() + b, data.cos_q.data() + b);
    for (int i = b; i < nb; ++i) withJointAt(model, data.X_up[i], i, q[i + off], data.cos_q[i], data.sin_q[i], none);
  } else {
    for (int i = b; i < nb; ++i) withJoint(model, data.X_up[i], i, q[i + off], none);
  }
}

// v_J = S_i q̇_i and c_J = Ṡ_i q̇_i (zero for one-coordinate joints). Needs updateJointTransform.
template <class S>
SALTUS_INLINE Motion<S> jointVelocity(const Model<S>& model, const Data<S>& data, int i, const VecRef<S>& v,
                                      Motion<S>* cJ) {
  const int k = model.first_coordinate[i];
  if (model.num_coordinates[i] == 1) {
    *cJ = Motion<S>::Zero();
    return jointVelocity(model, i, v[k]);
  }
  const Motion<S> vJ = multiJointVelocity(model, i, &data.S_joint[k], v.data() + k);
  *cJ = multiJointBias(model, i, &data.S_joint[k], v.data() + k, vJ);
  return vJ;
}

// S_i q̈_i. Needs updateJointTransform.
template <class S>
SALTUS_INLINE Motion<S> jointAcceleration(const Model<S>& model, const Data<S>& data, int i, const VecRef<S>& a) {
  const int k = model.first_coordinate[i];
  if (model.num_coordinates[i] == 1) return jointVelocity(model, i, a[k]);
  return multiJointVelocity(model, i, &data.S_joint[k], a.data() + k);
}

// World poses ^iX_0 = ^iX_λ ^λX_0 composed from the joint transforms already in data.X_up (left
// there by updateJointTransform, RNEA or CRBA), parents before children.
template <class S>
void composeWorldPoses(const Model<S>& model, Data<S>& data) {
  for (int i = 0; i < model.nbodies(); ++i) {
    const int p = model.parent[i];
    data.X_world[i] = p < 0 ? data.X_up[i] : data.X_up[i] * data.X_world[p];
  }
}

// Poses: data.X_up, data.X_world.
template <class S>
void forwardKinematics(const Model<S>& model, Data<S>& data, const VecRef<S>& q) {
  checkConfigurationSize(model, q.size(), "forwardKinematics", "q");
  for (int i = 0; i < model.nbodies(); ++i) updateJointTransform(model, data, i, q);
  composeWorldPoses(model, data);
}

// Poses and velocities; also data.a_bias, the body accelerations when q̈ = 0 (the J̇v terms).
template <class S>
void forwardKinematics(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                       const VecRef<S>& v) {
  checkConfigurationSize(model, q.size(), "forwardKinematics", "q");
  checkArgumentSize(model, v.size(), "forwardKinematics", "v");
  for (int i = 0; i < model.nbodies(); ++i) {
    updateJointTransform(model, data, i, q);
    const int p = model.parent[i];
    Motion<S> cJ;
    const Motion<S> vJ = jointVelocity(model, data, i, v, &cJ);
    if (p < 0) {
      data.X_world[i] = data.X_up[i];
      data.v[i] = vJ;
      data.a_bias[i] = cJ;
    } else {
      data.X_world[i] = data.X_up[i] * data.X_world[p];
      data.v[i] = data.X_up[i].apply(data.v[p]) + vJ;
      data.a_bias[i] = data.X_up[i].apply(data.a_bias[p]) + cJ + data.v[i].cross(vJ);  // RBDA 5.7
    }
  }
}

// Poses and velocities only (data.X_up, data.X_world, data.v; data.a_bias is left as it was):
// the first loop of RBDA Table 5.1 without the c_J and v_i × S q̇ terms, for callers that need
// point velocities alone (the collocation's slip and restitution functions, evaluated in nested
// duals where those unused terms cost as much as the velocities).
template <class S>
void forwardVelocities(const Model<S>& model, Data<S>& data, const VecRef<S>& q, const VecRef<S>& v) {
  checkConfigurationSize(model, q.size(), "forwardVelocities", "q");
  checkArgumentSize(model, v.size(), "forwardVelocities", "v");
  for (int i = 0; i < model.nbodies(); ++i) {
    updateJointTransform(model, data, i, q);
    const int p = model.parent[i], k = model.first_coordinate[i];
    const Motion<S> vJ = model.num_coordinates[i] == 1 ? jointVelocity(model, i, v[k])
                                                        : multiJointVelocity(model, i, &data.S_joint[k], v.data() + k);
    if (p < 0) {
      data.X_world[i] = data.X_up[i];
      data.v[i] = vJ;
    } else {
      data.X_world[i] = data.X_up[i] * data.X_world[p];
      data.v[i] = data.X_up[i].apply(data.v[p]) + vJ;
    }
  }
}

// Poses, velocities and accelerations a_i = ^iX_λ a_λ + S q̈ + c_J + v_i × S q̇ (RBDA 5.7).
template <class S>
void forwardKinematics(const Model<S>& model, Data<S>& data, const VecRef<S>& q,
                       const VecRef<S>& v, const VecRef<S>& a) {
  checkArgumentSize(model, a.size(), "forwardKinematics", "a");
  forwardKinematics(model, data, q, v);
  for (int i = 0; i < model.nbodies(); ++i) {
    const int p = model.parent[i];
    Motion<S> cJ;
    const Motion<S> vJ = jointVelocity(model, data, i, v, &cJ);
    const Motion<S> aJ = jointAcceleration(model, data, i, a) + cJ;
    data.a[i] = p < 0 ? aJ : data.X_up[i].apply(data.a[p]) + aJ + data.v[i].cross(vJ);
  }
}

// Pose of body b in the world (body = −1 is the world itself).
template <class S>
Mat3<S> bodyRotation(const Data<S>& data, int body) {  // R_WB
  return body < 0 ? Mat3<S>::Identity() : Mat3<S>(data.X_world[body].E.transpose());
}
template <class S>
Vec3<S> bodyPosition(const Data<S>& data, int body) {  // p_WB
  return body < 0 ? Vec3<S>::Zero() : data.X_world[body].r;
}

// World position of a point fixed on body b, given in body coordinates (p_BP).
// Needs forwardKinematics(q).
template <class S>
SALTUS_INLINE Vec3<S> pointPosition(const Data<S>& data, int body, const Vec3<S>& p_BP) {
  if (body < 0) return p_BP;
  const Transform<S>& X = data.X_world[body];
  return X.r + X.E.transpose() * p_BP;
}

// World linear velocity of a point fixed on body b (v_WP). Needs forwardKinematics(q, v).
template <class S>
SALTUS_INLINE Vec3<S> pointVelocity(const Data<S>& data, int body, const Vec3<S>& p_BP) {
  if (body < 0) return Vec3<S>::Zero();
  const Motion<S>& vb = data.v[body];
  return data.X_world[body].E.transpose() * (vb.v + vb.w.cross(p_BP));
}

// Classical (not spatial) linear acceleration of a point from a body spatial acceleration:
// a_P = a_O + α × p + ω × (v_O + ω × p)  (RBDA 2.11 / 2.12).
template <class S>
Vec3<S> classicalPointAcceleration(const Data<S>& data, int body, const Motion<S>& ab,
                                   const Vec3<S>& p_BP) {
  const Motion<S>& vb = data.v[body];
  const Vec3<S> a_B = ab.v + ab.w.cross(p_BP) + vb.w.cross(vb.v + vb.w.cross(p_BP));
  return data.X_world[body].E.transpose() * a_B;
}

// World linear acceleration of a point (a_WP). Needs forwardKinematics(q, v, a).
template <class S>
Vec3<S> pointAcceleration(const Data<S>& data, int body, const Vec3<S>& p_BP) {
  if (body < 0) return Vec3<S>::Zero();
  return classicalPointAcceleration(data, body, data.a[body], p_BP);
}

// J̇(q, v) v for a point: its acceleration when q̈ = 0. Needs forwardKinematics(q, v).
template <class S>
Vec3<S> pointAccelerationBias(const Data<S>& data, int body, const Vec3<S>& p_BP) {
  if (body < 0) return Vec3<S>::Zero();
  return classicalPointAcceleration(data, body, data.a_bias[body], p_BP);
}

}  // namespace saltus::dynamics
