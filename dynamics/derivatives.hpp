// Derivatives of inverse and forward dynamics by forward-mode automatic differentiation
// through the same scalar-templated algorithms (rnea.hpp, aba.hpp).
//
// Directions are propagated in chunks of N at a time with fixed-size derivative vectors
// (Eigen::AutoDiffScalar<Matrix<double, N, 1>>), so no heap is touched inside a call: generic
// dynamic-size AD is what makes AD dynamics slow (Drake issue #8482: ~140× for M(q)).
#pragma once

#include "dynamics/aba.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/data.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/tangent.hpp"

#include <unsupported/Eigen/AutoDiff>  // after Eigen/Core

#include <algorithm>
#include <vector>

namespace saltus::dynamics {

template <int N>
using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;

inline const Model<double>& checkedForDerivatives(const Model<double>& model) {
  if (model.base == BaseType::FreeQuaternion)
    throw std::invalid_argument("derivatives of model '" + model.name +
                                "': a free_quaternion base has no orientation coordinates to differentiate along; "
                                "use the Euler-angle base 'free' (away from pitch ±π/2)");
  return model;
}

// Workspace for the derivative algorithms: the model cast to dual numbers once, its Data, and
// the results. Derivatives are taken along the coordinates, so a FreeQuaternion base (whose
// orientation has no coordinates of its own) is refused: the optimiser keeps the Euler base.
template <int N = 8>
struct DerivativeData {
  explicit DerivativeData(const Model<double>& model)
      : model_dual(checkedForDerivatives(model).template cast<Dual<N>>()),
        data_dual(model_dual),
        data(model),
        q(model.nv()), v(model.nv()), w(model.nv()),
        dtau_dq(MatX<double>::Zero(model.nv(), model.nv())), dtau_dv(MatX<double>::Zero(model.nv(), model.nv())),
        dqdd_dq(model.nv(), model.nv()), dqdd_dv(model.nv(), model.nv()), dqdd_dtau(model.nv(), model.nv()),
        dv(model.nbodies()), da(model.nbodies()), df(model.nbodies()),
        seed_q(model.nv(), -1), seed_v(model.nv(), -1), Iv(model.nbodies()), touched(model.nbodies(), false),
        active(model.nbodies(), false) {
    // The directions of rneaDerivatives in coordinate order, q_k then q̇_k, N to a chunk. The base
    // translation coordinates (x, y, z of a free base; x, z of a planar one) have none: RNEA does
    // not depend on where the robot is (uniform gravity) nor, by Galilean invariance, on the
    // world velocity ṗ of the base origin (ṗ drops out of every classical acceleration), so
    // those columns of ∂τ/∂q and ∂τ/∂q̇ are zero.
    const bool floating = model.nbodies() > 0 && model.parent[0] < 0 &&
                          (model.joint_type[0] == JointType::Free || model.joint_type[0] == JointType::Planar);
    const int invariant = floating ? (model.joint_type[0] == JointType::Free ? 3 : 2) : 0;
    Chunk chunk;
    auto add = [&](int k, bool velocity) {
      chunk.coordinate[chunk.size] = k;
      chunk.velocity[chunk.size] = velocity;
      if (++chunk.size == N) chunks.push_back(chunk), chunk = Chunk{};
    };
    for (int d = 0; d < N; ++d) unit[d] = tangent::Row<N>::Unit(d);
    for (int k = invariant; k < model.nv(); ++k) {
      add(k, false);
      add(k, true);
    }
    if (chunk.size > 0) chunks.push_back(chunk);
  }

  // A chunk of rneaDerivatives: directions (coordinate, q or q̇), consecutive in coordinate order.
  struct Chunk {
    int size = 0;
    int coordinate[N] = {};
    bool velocity[N] = {};
  };
  std::vector<Chunk> chunks;

  Model<Dual<N>> model_dual;
  Data<Dual<N>> data_dual;
  Data<double> data;            // double workspace (M for ∂τ/∂q̈)
  VecX<Dual<N>> q, v, w;        // seeded inputs (w: q̈ for RNEA, τ for ABA)
  // RNEA: ∂τ/∂q, ∂τ/∂q̇ (∂τ/∂q̈ = M is data.M). rneaDerivatives writes the entries a chunk
  // reaches, the same ones at every call; the others are structurally zero and set once here.
  MatX<double> dtau_dq, dtau_dv;
  MatX<double> dqdd_dq, dqdd_dv, dqdd_dtau;    // ABA: ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ (= M⁻¹)

  // rneaDerivatives' scratch. Per body: the tangents of the current chunk
  // (tangent.hpp) of v_i, a_i and the force f_i; per coordinate: the chunk's direction of q_k
  // and of q̇_k (−1: none).
  std::vector<tangent::MotionTangent<N>, Eigen::aligned_allocator<tangent::MotionTangent<N>>> dv, da;
  std::vector<tangent::ForceTangent<N>, Eigen::aligned_allocator<tangent::ForceTangent<N>>> df;
  std::vector<int> seed_q, seed_v;
  std::vector<Force<double>> Iv;  // I_i v_i of the double pass
  tangent::Row<N> unit[N];        // unit[d] = e_dᵀ
  std::vector<bool> touched;  // an ancestor of the chunk's bodies whose df holds a force tangent
  std::vector<bool> active;   // body reached by the current chunk
};

namespace detail {
// Sets the inputs' values and seeds directions [first, first + N) of the stacked input
// (x0; x1; x2), each of size n.
template <int N>
void seed(VecX<Dual<N>>& x0, VecX<Dual<N>>& x1, VecX<Dual<N>>& x2, const VecRef<double>& v0,
          const VecRef<double>& v1, const VecRef<double>& v2, int first) {
  const int n = static_cast<int>(x0.size());
  VecX<Dual<N>>* xs[3] = {&x0, &x1, &x2};
  const VecRef<double>* vs[3] = {&v0, &v1, &v2};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < n; ++i) {
      Dual<N>& d = (*xs[k])[i];
      d.value() = (*vs[k])[i];
      d.derivatives().setZero();
      const int dir = k * n + i - first;
      if (dir >= 0 && dir < N) d.derivatives()[dir] = 1.0;
    }
}

// Copies the derivative columns [first, first + N) of y into the stacked Jacobian blocks.
template <int N>
void extract(const VecX<Dual<N>>& y, int first, int ndir, MatX<double>* blocks[3]) {
  const int n = static_cast<int>(y.size());
  for (int c = 0; c < N && first + c < ndir; ++c) {
    const int dir = first + c;
    MatX<double>& J = *blocks[dir / n];
    for (int i = 0; i < n; ++i) J(i, dir % n) = y[i].derivatives()[c];
  }
}

// The floating base's outward step in rneaDerivatives (body 0, whose S_0(q) and c_J depend on
// q: joint.hpp), in scalar dual numbers seeded with the chunk's directions on its coordinates:
// the tangents of v_0 = S_0 q̇_0 and a_0 = ^0X_world a_world + S_0 q̈_0 + c_J into dd.dv[0],
// dd.da[0]. S_0 stays in dd.data_dual.S_joint for floatingBaseInward.
template <int N>
void floatingBaseForward(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                         const VecRef<double>& v, const VecRef<double>& a) {
  using D = Dual<N>;
  const Model<D>& mdual = dd.model_dual;
  D qi[6], qdi[6], qddi[6];
  for (int c = 0; c < model.num_coordinates[0]; ++c) {
    qi[c] = D(q[c]), qdi[c] = D(v[c]), qddi[c] = D(a[c]);
    if (dd.seed_q[c] >= 0) qi[c].derivatives()[dd.seed_q[c]] = 1.0;
    if (dd.seed_v[c] >= 0) qdi[c].derivatives()[dd.seed_v[c]] = 1.0;
  }
  Motion<D>* S0 = dd.data_dual.S_joint.data();
  const Transform<D> X = multiJointTransformUp(mdual, 0, qi, S0);
  const Motion<D> vJ = multiJointVelocity(mdual, 0, S0, qdi);
  const Motion<D> a_world{Vec3<D>::Zero(), -mdual.gravity};
  const Motion<D> a0 = X.apply(a_world) + multiJointVelocity(mdual, 0, S0, qddi) + multiJointBias(mdual, 0, S0, qdi, vJ);
  for (int r = 0; r < 3; ++r) {
    dd.dv[0].w.row(r) = vJ.w[r].derivatives().transpose();
    dd.dv[0].v.row(r) = vJ.v[r].derivatives().transpose();
    dd.da[0].w.row(r) = a0.w[r].derivatives().transpose();
    dd.da[0].v.row(r) = a0.v[r].derivatives().transpose();
  }
}

// The floating base's inward step: the derivative rows of τ_0 = S_0(q)ᵀ f_0 into rows[0 .. n_0),
// with the value of f_0 from dd.data and its tangent from dd.df[0].
template <int N>
void floatingBaseInward(const Model<double>& model, DerivativeData<N>& dd, tangent::Row<N>* rows) {
  using D = Dual<N>;
  const Force<double>& f = dd.data.f[0];
  Force<D> fd;
  for (int r = 0; r < 3; ++r) {
    fd.n[r] = D(f.n[r], dd.df[0].n.row(r).transpose());
    fd.f[r] = D(f.f[r], dd.df[0].f.row(r).transpose());
  }
  D tau[6];
  multiJointForce(dd.model_dual, 0, dd.data_dual.S_joint.data(), fd, tau);
  for (int c = 0; c < model.num_coordinates[0]; ++c) rows[c] = tau[c].derivatives().transpose();
}
}  // namespace detail

// ∂τ/∂q and ∂τ/∂q̇ of τ = RNEA(q, q̇, q̈) into dd.dtau_dq, dd.dtau_dv; ∂τ/∂q̈ = M(q) into
// dd.data.M (CRBA: RNEA is linear in q̈).
//
// Forward-mode AD of RNEA (RBDA Table 5.1) with the spatial operations as elementary operations
// (tangent.hpp): one double RNEA pass gives every value, then each chunk of N directions
// (dd.chunks: q_j and q̇_j of consecutive coordinates) runs RNEA's recursions on tangents only.
// A direction q_j or q̇_j changes the outward recursion only in the subtree of j's body and the
// inward one only there and along its ancestors, so a chunk visits those bodies alone. The
// floating base's joint, whose S_i(q) and c_J depend on q, goes through the scalar dual numbers
// of aba() instead (model_dual), once per chunk that moves it.
template <int N>
void rneaDerivatives(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                     const VecRef<double>& v, const VecRef<double>& a) {
  checkArgumentSize(model, q.size(), "rneaDerivatives", "q");
  checkArgumentSize(model, v.size(), "rneaDerivatives", "v");
  checkArgumentSize(model, a.size(), "rneaDerivatives", "a");
  using MotionT = tangent::MotionTangent<N>;
  using ForceT = tangent::ForceTangent<N>;
  using RowN = tangent::Row<N>;
  Data<double>& dat = dd.data;
  rnea(model, dat, q, v, a);  // values of every body; dat.f[i] is the total force across joint i
  for (int i = 0; i < model.nbodies(); ++i) dd.Iv[i] = model.inertia[i] * dat.v[i];
  const Motion<double> a_world{Vec3<double>::Zero(), -model.gravity};  // a_0 = −a_g
  for (const auto& chunk : dd.chunks) {
    // Bodies [b0, b1] hold the chunk's coordinates; the active bodies are those and their
    // subtrees, [b0, end) less the bodies below an ancestor of b0 (their derivatives are zero).
    const int b0 = model.coordinate_body[chunk.coordinate[0]];
    const int b1 = model.coordinate_body[chunk.coordinate[chunk.size - 1]];
    int end = b1 + 1;
    for (int b = b0; b <= b1; ++b) end = std::max(end, model.subtree_end[b]);
    for (int d = 0; d < chunk.size; ++d) (chunk.velocity[d] ? dd.seed_v : dd.seed_q)[chunk.coordinate[d]] = d;
    auto store = [&](int k, const RowN& dtau) {
      for (int d = 0; d < chunk.size; ++d) (chunk.velocity[d] ? dd.dtau_dv : dd.dtau_dq)(k, chunk.coordinate[d]) = dtau[d];
    };

    // Outward: tangents of v_i, a_i and of the body force I_i a_i + v_i ×* I_i v_i (RBDA 5.7–5.9).
    for (int i = b0; i < end; ++i) {
      const int p = model.parent[i];
      const bool parent_active = p >= b0 && dd.active[p];
      dd.active[i] = i <= b1 || parent_active;
      if (!dd.active[i]) continue;
      MotionT& dv = dd.dv[i];
      MotionT& da = dd.da[i];
      if (model.num_coordinates[i] > 1) {
        detail::floatingBaseForward(model, dd, q, v, a);
      } else {
        const int k = model.first_coordinate[i], dq = dd.seed_q[k], dqd = dd.seed_v[k];
        withEvaluatedJoint(model, dat.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
          if (parent_active) {
            dv = tangent::apply(X, dd.dv[p]);
            da = tangent::apply(X, dd.da[p]);
          } else {
            dv.setZero();
            da.setZero();
          }
          const Motion<double> S = motionSubspace(model, i);
          if (dq >= 0) {  // ∂(^iX_λ m)/∂q_i = −S_i × ^iX_λ m = ^iX_λ m × S_i, with m = v_λ and a_λ
            if (p >= 0) dv.addColumn(dd.unit[dq], X.apply(dat.v[p]).cross(S));
            da.addColumn(dd.unit[dq], X.apply(p < 0 ? a_world : dat.a_gf[p]).cross(S));
          }
          if (dqd >= 0) dv.addColumn(dd.unit[dqd], S);  // ∂(S_i q̇_i)/∂q̇_i
          // a_i += v_i × S_i q̇_i: its tangent dv_i × S_i q̇_i, and v_i × S_i along q̇_i.
          const MotionT dc = tangent::crossJointVelocity(dv, Si, v[k]);
          da.w += dc.w;
          da.v += dc.v;
          if (dqd >= 0) da.addColumn(dd.unit[dqd], dat.v[i].cross(S));
        });
      }
      ForceT& df = dd.df[i];
      if (model.massless[i]) {
        df.setZero();
      } else {
        const RigidInertia<double>& I = model.inertia[i];
        df = tangent::inertiaTimes(I, da);
        df += tangent::crossForceBoth(dat.v[i], dv, dd.Iv[i], tangent::inertiaTimes(I, dv));
      }
    }

    // Inward over the same bodies: τ_i = S_iᵀ f_i and f_λ += ^iX_λᵀ f_i. The tangent of the force
    // passed to an ancestor of b0 collects in dd.df of that ancestor (dd.touched).
    for (int i = end - 1; i >= b0; --i) {
      if (!dd.active[i]) continue;
      const int p = model.parent[i];
      if (model.num_coordinates[i] > 1) {  // the floating base (i = 0): no parent
        RowN rows[6];
        detail::floatingBaseInward(model, dd, rows);
        for (int c = 0; c < model.num_coordinates[i]; ++c) store(c, rows[c]);
        continue;
      }
      const int k = model.first_coordinate[i], dq = dd.seed_q[k];
      withEvaluatedJoint(model, dat.X_up[i], i, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
        store(k, tangent::project(Si, dd.df[i]));
        if (p < 0) return;
        ForceT up = tangent::applyTranspose(X, dd.df[i]);
        // ∂(^iX_λᵀ f)/∂q_i = ^iX_λᵀ (S_i ×* f)
        if (dq >= 0) up.addColumn(dd.unit[dq], X.applyTranspose(motionSubspace(model, i).crossForce(dat.f[i])));
        if (p >= b0 || dd.touched[p]) {
          dd.df[p] += up;
        } else {
          dd.df[p] = up;
          dd.touched[p] = true;
        }
      });
    }

    // Ancestors of b0: their joints are constant, so ∂τ_p = S_pᵀ ∂f_p and ∂f_λ(p) += ^pX_λᵀ ∂f_p.
    for (int p = b0 - 1; p >= 0; --p) {
      if (!dd.touched[p]) continue;
      dd.touched[p] = false;
      const int pp = model.parent[p];
      if (model.num_coordinates[p] > 1) {
        for (int c = 0, k = model.first_coordinate[p]; c < model.num_coordinates[p]; ++c, ++k)
          store(k, tangent::project(dat.S_joint[k], dd.df[p]));
        continue;  // the base: no parent
      }
      withEvaluatedJoint(model, dat.X_up[p], p, [&](const auto& X, const auto& Si) SALTUS_LAMBDA_INLINE {
        store(model.first_coordinate[p], tangent::project(Si, dd.df[p]));
        if (pp < 0) return;
        const ForceT up = tangent::applyTranspose(X, dd.df[p]);
        if (dd.touched[pp]) {
          dd.df[pp] += up;
        } else {
          dd.df[pp] = up;
          dd.touched[pp] = true;
        }
      });
    }
    for (int d = 0; d < chunk.size; ++d) (chunk.velocity[d] ? dd.seed_v : dd.seed_q)[chunk.coordinate[d]] = -1;
  }
  crba(model, dat, q);  // the base translation columns of dtau_dq, dtau_dv stay zero (DerivativeData)
}

// ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ of q̈ = ABA(q, q̇, τ), all by AD through aba().
template <int N>
void abaDerivatives(const Model<double>& model, DerivativeData<N>& dd, const VecRef<double>& q,
                    const VecRef<double>& v, const VecRef<double>& tau) {
  checkArgumentSize(model, q.size(), "abaDerivatives", "q");
  checkArgumentSize(model, v.size(), "abaDerivatives", "v");
  checkArgumentSize(model, tau.size(), "abaDerivatives", "tau");
  const int n = model.nv();
  MatX<double>* blocks[3] = {&dd.dqdd_dq, &dd.dqdd_dv, &dd.dqdd_dtau};
  for (int first = 0; first < 3 * n; first += N) {
    detail::seed<N>(dd.q, dd.v, dd.w, q, v, tau, first);
    aba(dd.model_dual, dd.data_dual, dd.q, dd.v, dd.w);
    detail::extract<N>(dd.data_dual.qdd, first, 3 * n, blocks);
  }
}

extern template struct DerivativeData<8>;
extern template void rneaDerivatives<8>(const Model<double>&, DerivativeData<8>&, const VecRef<double>&,
                                        const VecRef<double>&, const VecRef<double>&);
extern template void abaDerivatives<8>(const Model<double>&, DerivativeData<8>&, const VecRef<double>&,
                                       const VecRef<double>&, const VecRef<double>&);

}  // namespace saltus::dynamics
