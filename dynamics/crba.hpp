// Composite-rigid-body algorithm for the joint-space inertia matrix M(q) (RBDA Table 6.2), in
// body coordinates: the composite inertia of each subtree is carried to the parent with
// I^c_λ += ^iX_λᵀ I^c_i ^iX_λ (RBDA 6.18); the column F = I^c_i S_i of coordinate k of body i is
// carried up the path to the root with F ← ^jX_λ(j)ᵀ F, and M_kl = S_jᵀ F for the coordinates l
// of each body j on the way (RBDA 6.19, 6.20).
//
// M(q) does not depend on the coordinates each body's quantities are expressed in, so the
// recursion runs in the turned body frames B'_i of model.turned_frame (model.hpp, TurnedFrame), in
// which a revolute joint about ±e_K whose X_T rotation is a signed permutation (as URDF rpy of
// multiples of π/2 give) has no X_T rotation. For such an axis joint (joint.hpp) S_i picks a column
// or a component: I^c_i S_i is a column of the composite inertia and S_jᵀ F a component of F, and
// ^iX_λ acts as a plane rotation and a cross product.
#pragma once

#include <type_traits>

#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::dynamics {

namespace detail {
// I_λ += ^iX_λᵀ I ^iX_λ: a body-i inertia added in parent coordinates (RBDA Table 2.5), for the
// transform forms of withJoint. For X = rot(E) xlt(r), with h' = Eᵀ h and Ī' = Eᵀ Ī E:
//   h_λ = h' + m r,  Ī_λ = Ī' − h' rᵀ − r h_λᵀ + (2 r·h' + m r·r) 1   (RigidInertia::transformedBy).
// Eᵀ Ī E is formed as Eᵀ (Eᵀ Ī)ᵀ, which for an axis transform is two sets of plane rotations.
// The sums go straight into I_λ, entry by entry.
template <class S, class XForm>
SALTUS_INLINE void addInertiaToParent(const XForm& X, const RigidInertia<S>& I, RigidInertia<S>& I_parent) {
  const Vec3<S>& r = X.r;
  const Vec3<S> h1 = X.rotateInverse(I.h);
  const Vec3<S> h = add3(h1, scale3(r, I.m));
  Vec3<S> EtI[3];  // rows of Eᵀ Ī, as the columns of its transpose Ī E
  for (int c = 0; c < 3; ++c) {
    const Vec3<S> col = X.rotateInverse(Vec3<S>(I.I(0, c), I.I(1, c), I.I(2, c)));  // column c of Eᵀ Ī
    EtI[0][c] = col[0], EtI[1][c] = col[1], EtI[2][c] = col[2];
  }
  const S diag = S(2) * dot3(r, h1) + I.m * dot3(r, r);
  I_parent.m += I.m;
  addTo3(I_parent.h, h);
  for (int c = 0; c < 3; ++c) {
    Vec3<S> col;  // column c of Eᵀ Ī E, from row c down
    if constexpr (std::is_same_v<XForm, GeneralTransform<S>>) {
      for (int k = c; k < 3; ++k) col[k] = X.X.E(0, k) * EtI[c][0] + X.X.E(1, k) * EtI[c][1] + X.X.E(2, k) * EtI[c][2];
    } else {
      col = X.rotateInverse(EtI[c]);
    }
    for (int k = c; k < 3; ++k) {
      S x = col[k] - h1[k] * r[c] - r[k] * h[c];
      if (k == c) x += diag;
      I_parent.I(k, c) += x;
      if (k != c) I_parent.I(c, k) += x;
    }
  }
}
}  // namespace detail

// Fills data.M (both triangles), data.X_up (in the body frames, for the other algorithms),
// data.Ic (composite inertias) and data.F_column (both in the turned frames B'_i) and, for a
// multi-coordinate joint, its S_i(q) in data.S_joint. data.X_world is not set (use
// forwardKinematics for the poses). Entries between bodies on different branches are
// structurally zero: Data sets them once.
//
// The columns travel up together: at body j, every column F_k of j's subtree (bodies numbered
// depth first: [j, subtree_end[j])) gives M_jk = S_jᵀ F_k and moves on to λ(j). The columns are
// independent, so this inner loop has no dependency chain, and the switch on j's joint form is
// taken once per body.
template <class S>
const MatX<S>& crba(const Model<S>& model, Data<S>& data, const VecRef<S>& q) {
  checkConfigurationSize(model, q.size(), "crba", "q");
  const int nb = model.nbodies();
  const int b = nb > 0 && model.num_coordinates[0] > 1 ? 1 : 0;  // first one-coordinate body
  const int off = model.nv() - nb;                                // its coordinate k = i + off
  // Joint transforms (jcalc) in a loop of their own (its libm calls would otherwise spill the
  // registers of the loop below); I^c_i starts as I_i.
  if (b) updateJointTransform(model, data, 0, q);
  updateOneCoordinateJointTransforms(model, data, q);
  for (int i = 0; i < nb; ++i) data.Ic[i] = model.turned_frame[i].inertia;
  MatX<S>& M = data.M;
  Force<S>* F = data.F_column.data();
  // Leaves to root.
  for (int i = nb - 1; i >= b; --i) {
    const int p = model.parent[i], k = i + off, end = model.subtree_end[i];
    withTurnedJoint(model, data.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
      F[i] = Si.inertiaTimes(data.Ic[i]);  // F = I^c_i S_i (RBDA 6.19)
      M(k, k) = Si.project(F[i]);
      for (int j = i + 1; j < end; ++j) M(k, j + off) = M(j + off, k) = Si.project(F[j]);  // RBDA 6.20
      if (p >= 0) {
        detail::addInertiaToParent(X, data.Ic[i], data.Ic[p]);  // RBDA 6.18
        for (int j = i; j < end; ++j) F[j] = X.applyTranspose(F[j]);
      }
    });
  }
  if (b) {  // the base: M_0k = S_0ᵀ F_k, and the block S_0ᵀ I^c_0 S_0
    const int nc = model.num_coordinates[0];
    const Motion<S>* S0 = data.S_joint.data();
    for (int j = 1; j < nb; ++j) {
      S column[6];
      multiJointProject(model, 0, S0, F[j], column);
      for (int c = 0; c < nc; ++c) M(j + off, c) = M(c, j + off) = column[c];
    }
    const RigidInertia<S>& I0 = data.Ic[0];
    if (model.joint_type[0] == JointType::Free || model.joint_type[0] == JointType::FreeQuaternion) {
      // Translation columns s_c = (0; t_c), rotation columns s_c = (w_c; 0) (joint.hpp):
      // I s = (h × t; m t) and (Ī w; −h × w), and each product with a column is a 3-vector dot.
      Force<S> F0[6];
      for (int c = 0; c < 3; ++c) F0[c] = {cross3(I0.h, S0[c].v), scale3(S0[c].v, I0.m)};
      for (int c = 3; c < 6; ++c) F0[c] = {mulSym3(I0.I, S0[c].w), cross3(S0[c].w, I0.h)};
      for (int c = 0; c < 6; ++c)
        for (int r = c; r < 6; ++r) M(r, c) = M(c, r) = r < 3 ? dot3(S0[r].v, F0[c].f) : dot3(S0[r].w, F0[c].n);
    } else {
      for (int c = 0; c < nc; ++c) {
        const Force<S> Fc = I0 * S0[c];
        for (int r = c; r < nc; ++r) M(r, c) = M(c, r) = dot(S0[r], Fc);
      }
    }
  }
  return M;
}

}  // namespace saltus::dynamics
