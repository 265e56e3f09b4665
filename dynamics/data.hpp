// The workspace of the dynamics algorithms: everything they compute, sized once from a Model.
// Algorithms write only here, so a constant Model can be shared by any number of Data; once a
// Data exists no algorithm allocates. Floating-point entries start as NaN so that a quantity read
// before the algorithm that fills it shows up at once.
#pragma once

#include <limits>
#include <vector>

#include "dynamics/joint.hpp"

namespace saltus::dynamics {

template <class S>
struct Data {
  explicit Data(const Model<S>& model);

  // Kinematics (per body i, RBDA notation).
  // Motion subspace columns, per coordinate, body coordinates: constant for one-coordinate
  // joints (set here), S_i(q) of a multi-coordinate joint (set by every algorithm that computes
  // X_up).
  std::vector<Motion<S>> S_joint;
  std::vector<Transform<S>> X_up;     // ^iX_λ(i): parent coordinates -> body i coordinates
  VecX<S> cos_q, sin_q;               // per body: cos, sin of a one-coordinate joint's q (double kernels' jcalc)
  std::vector<Transform<S>> X_world;  // ^iX_0: world -> body i; E = R_WBᵀ, r = p_WB (origin in world)
  std::vector<Motion<S>> v;           // body spatial velocity, body coordinates
  std::vector<Motion<S>> a;           // body spatial acceleration, body coordinates (forwardKinematics)
  std::vector<Motion<S>> a_bias;      // spatial acceleration with q̈ = 0 (forwardKinematics with v)

  // Inverse dynamics (RNEA, RBDA Table 5.1).
  std::vector<Motion<S>> a_gf;  // a_i − ^iX_0 g: acceleration offset by gravity (a_0 = −g trick)
  std::vector<Force<S>> f;      // force transmitted across joint i, body coordinates
  VecX<S> tau;                  // RNEA result

  // Composite rigid bodies (CRBA, RBDA Table 6.2).
  std::vector<RigidInertia<S>> Ic;  // composite inertias, in the turned frames B'_i (Model::turned_frame)
  std::vector<Force<S>> F_column;   // per one-coordinate body i: I^c_i S_i carried up towards the root
  MatX<S> M;  // joint-space inertia matrix, both triangles filled

  // Articulated bodies (ABA, RBDA Table 7.1).
  std::vector<Mat6<S>> IA;
  std::vector<Force<S>> pA;
  std::vector<Motion<S>> c;
  std::vector<Vec6<S>> U;        // per coordinate: U = IA S (RBDA 7.43)
  VecX<S> D, u;                  // per coordinate: D = Sᵀ U (one-coordinate joints), u = τ − Sᵀ p^A
  std::vector<Mat6<S>> D_chol;   // per body: Cholesky factor L of D_i = S_iᵀ U_i (multi-coordinate joints)
  VecX<S> qdd;  // ABA result

  // Centre of mass (centerOfMass).
  S mass;
  Vec3<S> com;
};

template <class S>
Data<S>::Data(const Model<S>& model) {
  const int n = model.nv(), nb = model.nbodies();
  const S nan(std::numeric_limits<double>::quiet_NaN());
  const Vec3<S> nan3 = Vec3<S>::Constant(nan);
  const Motion<S> mnan{nan3, nan3};
  const Force<S> fnan{nan3, nan3};
  const Transform<S> Xnan{Mat3<S>::Constant(nan), nan3};
  S_joint.assign(n, mnan);
  for (int i = 0; i < nb; ++i)
    if (model.num_coordinates[i] == 1) S_joint[model.first_coordinate[i]] = motionSubspace(model, i);
  X_up.assign(nb, Xnan);
  X_world.assign(nb, Xnan);
  cos_q = VecX<S>::Constant(nb, nan);
  sin_q = VecX<S>::Constant(nb, nan);
  v.assign(nb, mnan);
  a.assign(nb, mnan);
  a_bias.assign(nb, mnan);
  a_gf.assign(nb, mnan);
  f.assign(nb, fnan);
  tau = VecX<S>::Constant(n, nan);
  Ic.assign(nb, RigidInertia<S>{nan, nan3, Mat3<S>::Constant(nan)});
  F_column.assign(nb, fnan);
  M = MatX<S>::Constant(n, n, nan);
  for (int i = 0; i < n; ++i)  // structural zeros of M: neither coordinate's body supports the other's
    for (int j = 0; j < n; ++j) {
      const int bi = model.coordinate_body[i], bj = model.coordinate_body[j];
      if (!model.isAncestor(bi, bj) && !model.isAncestor(bj, bi)) M(i, j) = S(0);
    }
  IA.assign(nb, Mat6<S>::Constant(nan));
  pA.assign(nb, fnan);
  c.assign(nb, mnan);
  U.assign(n, Vec6<S>::Constant(nan));
  D_chol.assign(nb, Mat6<S>::Constant(nan));
  D = VecX<S>::Constant(n, nan);
  u = VecX<S>::Constant(n, nan);
  qdd = VecX<S>::Constant(n, nan);
  mass = nan;
  com = nan3;
}

}  // namespace saltus::dynamics
