// The equations of motion's Hessian pairs and Jacobian columns formed without nested duals
// (equation_of_motion.hpp), and AdFunction<EquationOfMotion> instantiated here alone. Built with
// the default inlining limits, as functions.cpp (collocation/CMakeLists.txt says why).
#include "collocation/equation_of_motion.hpp"

#include <algorithm>

#include "dynamics/crba.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::collocation {

void EquationOfMotion::addHessian(const double* x, const double* lambda, double* H) const {
  const int n = nv(), N = inputs();
  const int first_acceleration = (with_dynamics ? 2 : 1) * n;  // q̈ or Δq̇
  const int first_reaction = first_acceleration + n + inputs_count();
  auto h = [H, N](int i, int j) -> double& { return H[std::max(i, j) + std::min(i, j) * N]; };
  using VecD = Eigen::Matrix<Dual, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1>;
  const auto& model_d = models->modelWithoutGravity<Dual>();
  auto& data_d = models->data<Dual>();
  bool any_point = false;
  for (const ContactPair& c : *contacts) any_point = any_point || !c.isStop();
  // The coordinates F depends on (dependsOn): the others' pairs are zero. Of those, the ones
  // M(q) and C(q, q̇) depend on (inDynamics; not a world translation).
  int depending[kMaxCoordinates], n_depending = 0, dynamic[kMaxCoordinates], n_dynamic = 0;
  for (int i = 0; i < n; ++i) {
    if (dependsOn(i)) depending[n_depending++] = i;
    if (inDynamics(i)) dynamic[n_dynamic++] = i;
  }
  // First-order passes with q seeded, a chunk of those coordinates at a time.
  VecD q(n), zero = VecD::Zero(n), l(n);
  for (int i = 0; i < n; ++i) {
    q[i] = Dual(x[i], Eigen::Matrix<double, kChunk, 1>::Zero());
    l[i] = Dual(lambda[i], Eigen::Matrix<double, kChunk, 1>::Zero());
  }
  // At least one pass: the pairs (r_n, α) and a free point's (s, r_n), (s, α) have no q (first == 0).
  for (int first = 0; first == 0 || first < n_depending; first += kChunk) {
    const int count = std::min(kChunk, n_depending - first);
    const int* seeded = depending + first;  // the chunk's coordinates: column c is q_seeded[c]
    for (int i = 0; i < n; ++i) q[i].derivatives().setZero();
    for (int c = 0; c < count; ++c) q[seeded[c]].derivatives()[c] = 1.0;
    // (q, q̈): ∂(M(q) λ)_j/∂q_i.
    const auto& Ml = dynamics::rnea(model_d, data_d, ConstMap<Dual>(q.data(), n), ConstMap<Dual>(zero.data(), n),
                                    ConstMap<Dual>(l.data(), n));
    for (int j = 0; j < n; ++j)
      for (int c = 0; c < count; ++c) h(first_acceleration + j, seeded[c]) += Ml[j].derivatives()[c];
    if (!any_point) continue;
    // (q, r) and (r_n, α): ∂f/∂r_n · w and ∂f/∂t_i · w as functions of q, w(q) = J(q) λ the
    // relative velocity at q̇ = λ; the normal and the directions carry q's derivatives when the
    // plane is on a body (constants for a world plane).
    dynamics::forwardVelocities(model_d, data_d, ConstMap<Dual>(q.data(), n), ConstMap<Dual>(l.data(), n));
    int k = first_reaction;
    for (const ContactPair& c : *contacts) {
      if (c.isStop()) {  // tau_i −= sign·r_n: no q
        k += 1;
        continue;
      }
      // A free point's w is B's material point at its plane coordinates s (constants here).
      const int m = c.freeAxes();
      Dual s[2];
      for (int i = 0; i < m; ++i) s[i] = Dual(x[k + 1 + c.k() + i], Eigen::Matrix<double, kChunk, 1>::Zero());
      const Vec3<Dual> w = m > 0 ? contact::relativeVelocityAt(c, data_d, s) : contact::relativeVelocity(c, data_d);
      const double rn = x[k];
      const double df_dt = friction == FrictionForm::Activation ? -c.friction * rn : 1.0;
      // ∂(a·w)/∂q for a = ∂f/∂r_n and a = d_i: by the product rule, a's derivatives only when the
      // plane turns with a body (for a world plane a is constant: double arithmetic, no duals).
      Eigen::Matrix<double, 3, kChunk> dw;  // ∂w/∂q over the chunk
      Eigen::Vector3d wv;
      for (int r = 0; r < 3; ++r) dw.row(r) = w[r].derivatives().transpose(), wv[r] = w[r].value();
      auto addRow = [&](int row, const Vec3<Dual>& a, double scale) {  // h(row, q) −= scale ∂(a·w)/∂q
        Eigen::Vector3d av;
        Eigen::Matrix<double, 3, kChunk> da;
        for (int r = 0; r < 3; ++r) av[r] = a[r].value(), da.row(r) = a[r].derivatives().transpose();
        const Eigen::Matrix<double, kChunk, 1> d = dw.transpose() * av + da.transpose() * wv;
        for (int col = 0; col < count; ++col) h(row, seeded[col]) -= scale * d[col];
      };
      auto addRowConstant = [&](int row, const Eigen::Vector3d& a, double scale) {
        const Eigen::Matrix<double, kChunk, 1> d = dw.transpose() * a;
        for (int col = 0; col < count; ++col) h(row, seeded[col]) -= scale * d[col];
      };
      if (c.body_b < 0) {
        Eigen::Vector3d df_drn = c.normal_B;
        if (friction == FrictionForm::Activation)
          for (int i = 0; i < c.k(); ++i) df_drn -= c.directions_B.col(i) * (c.friction * x[k + 1 + i]);
        addRowConstant(k, df_drn, 1.0);
        for (int i = 0; i < c.k(); ++i) addRowConstant(k + 1 + i, c.directions_B.col(i), df_dt);
        if (first == 0 && friction == FrictionForm::Activation)
          for (int i = 0; i < c.k(); ++i) h(k + 1 + i, k) += c.friction * c.directions_B.col(i).dot(wv);
      } else {
        Vec3<Dual> df_drn = contact::planeNormal(c, data_d);
        for (int i = 0; i < c.k(); ++i) {
          const Vec3<Dual> d = contact::frictionDirection(c, data_d, i);
          if (friction == FrictionForm::Activation) df_drn -= d * (c.friction * x[k + 1 + i]);
          addRow(k + 1 + i, d, df_dt);
          if (first == 0 && friction == FrictionForm::Activation) {
            const Eigen::Vector3d dv(d[0].value(), d[1].value(), d[2].value());
            h(k + 1 + i, k) += c.friction * dv.dot(wv);
          }
        }
        addRow(k, df_drn, 1.0);
        // A free point, φ_c = −f·w with w affine in s: ∂φ/∂s_i = −f·e_i, e_i = ∂w/∂s_i
        // (relativeVelocityAtSlope), a function of q; its pairs with r_n and α_j are
        // −(∂f/∂r_n)·e_i and −(∂f/∂α_j)·e_i, and (s, s) is zero.
        Vec3<Dual> f = Vec3<Dual>::Zero();  // the reaction, once for every free axis
        if (m > 0) {
          f = contact::planeNormal(c, data_d) * Dual(rn);
          for (int j = 0; j < c.k(); ++j) f += contact::frictionDirection(c, data_d, j) * Dual(df_dt * x[k + 1 + j]);
        }
        for (int i = 0; i < m; ++i) {
          const Vec3<Dual> e = contact::relativeVelocityAtSlope(c, data_d, i);
          const int row = k + 1 + c.k() + i;
          const Dual fe = f.dot(e);
          for (int col = 0; col < count; ++col) h(row, seeded[col]) -= fe.derivatives()[col];
          if (first != 0) continue;
          const Eigen::Vector3d ev(e[0].value(), e[1].value(), e[2].value());
          Eigen::Vector3d df_drn_v(df_drn[0].value(), df_drn[1].value(), df_drn[2].value());
          h(row, k) -= df_drn_v.dot(ev);
          for (int j = 0; j < c.k(); ++j) {
            const Vec3<Dual> d = contact::frictionDirection(c, data_d, j);
            h(row, k + 1 + j) -= df_dt * Eigen::Vector3d(d[0].value(), d[1].value(), d[2].value()).dot(ev);
          }
        }
      }
      k += 1 + c.k() + m;
    }
  }
  if (!with_dynamics) return;
  // (q̇, q̇) by polarisation of ψ(q̇) = λᵀ RNEA(q, q̇, 0) without gravity.
  const auto& model = models->modelWithoutGravity<double>();
  auto& data = models->data<double>();
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1> v = Eigen::VectorXd::Zero(n), psi(n);
  const ConstMap<double> qv(x, n), lv(lambda, n);
  auto form = [&]() { return lv.dot(dynamics::nonLinearEffects(model, data, qv, ConstMap<double>(v.data(), n))); };
  // A world translation's rate is not in C q̇ (inDynamics): its pairs are zero.
  for (int a = 0; a < n_dynamic; ++a) {
    const int i = dynamic[a];
    v[i] = 1.0;
    psi[i] = form();
    v[i] = 0.0;
    h(n + i, n + i) += 2.0 * psi[i];
  }
  for (int a = 0; a < n_dynamic; ++a)
    for (int b = 0; b < a; ++b) {
      const int i = dynamic[a], j = dynamic[b];
      v[i] = v[j] = 1.0;
      h(n + i, n + j) += form() - psi[i] - psi[j];
      v[i] = v[j] = 0.0;
    }
}

void EquationOfMotion::jacobianColumns(const double* x, double* J) const {
  const int n = nv();
  const int first_acceleration = (with_dynamics ? 2 : 1) * n;  // q̈ or Δq̇
  const auto& model = models->model<double>();
  auto& data = models->data<double>();
  // q and q̇ of the dynamics: ∂τ/∂q and ∂τ/∂q̇ of τ = RNEA(q, q̇, q̈), or of M(q) Δq̇ =
  // RNEA(q, 0, Δq̇) without gravity at a jump; zero for a world translation. Or by AD (columnByAd),
  // the others' columns zero.
  const ConstMap<double> q(x, n);
  if (qByRneaDerivatives()) {
    const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1> zero = Eigen::VectorXd::Zero(n);
    auto& derivatives = models->rneaDerivatives(with_dynamics);
    if (with_dynamics)
      dynamics::rneaDerivatives(model, derivatives, q, ConstMap<double>(x + n, n), ConstMap<double>(x + 2 * n, n));
    else
      dynamics::rneaDerivatives(models->modelWithoutGravity<double>(), derivatives, q, zero,
                                ConstMap<double>(x + n, n));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        J[i + j * n] = derivatives.dtau_dq(i, j);
        if (with_dynamics) J[i + (n + j) * n] = derivatives.dtau_dv(i, j);
      }
  } else {
    for (int i = 0; i < first_acceleration; ++i)
      if (!columnByAd(i)) std::fill(J + i * n, J + (i + 1) * n, 0.0);
  }
  // M(q): CRBA leaves data.X_up (and a multi-coordinate joint's S_i(q)); the poses the contact
  // layer needs are composed from them as in operator().
  const auto& M = dynamics::crba(model, data, q);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) J[i + (first_acceleration + j) * n] = M(i, j);
  for (int k = 0; k < inputs_count(); ++k) {
    double* column = J + (first_acceleration + n + k) * n;
    std::fill(column, column + n, 0.0);
    column[actuated[k]] = -1.0;
  }
  if (contacts->empty()) return;
  dynamics::composeWorldPoses(model, data);
  // The reaction's generalised force −J_cᵀ f_c(r_n, t) is linear in r_n for fixed t and in t for
  // fixed r_n: each column is the force of the derivative ∂f_c/∂r_n or ∂f_c/∂t_i, put through the
  // contact layer as operator() puts f_c.
  int k = first_acceleration + n + inputs_count();
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1> unit;
  for (const ContactPair& c : *contacts) {
    const double* r = x + k;
    const double* s = r + 1 + c.k();
    auto column = [&](int input, double r_n, const Vec3<double>& f_t) {
      double* out = J + (k + input) * n;
      std::fill(out, out + n, 0.0);
      if (c.freePoint())
        contact::addReactionAt(model, data, c, -r_n, Vec3<double>(-f_t), s, out);
      else
        contact::addReaction(model, data, c, -r_n, Vec3<double>(-f_t), out);
    };
    // ∂f/∂r_n = n + f_t(r_n = 1) in the Activation form (f_t = −μ r_n Σ d_i α_i); n in the Direct.
    column(0, 1.0, friction == FrictionForm::Activation ? contactForce(c, data, friction, 1.0, r + 1, true)
                                                       : Vec3<double>(Vec3<double>::Zero()));
    unit = Eigen::VectorXd::Zero(c.k());
    for (int i = 0; i < c.k(); ++i) {  // ∂f/∂t_i: f_t at t = e_i
      unit[i] = 1.0;
      column(1 + i, 0.0, contactForce(c, data, friction, r[0], unit.data(), true));
      unit[i] = 0.0;
    }
    k += 1 + c.k() + c.freeAxes();
  }
  if (qByRneaDerivatives()) addReactionColumns(x, J);
}

void EquationOfMotion::addReactionColumns(const double* x, double* J) const {
  // −∂(Σ J_cᵀ f_c)/∂q, for the q some contact's Jacobian depends on, by AD through the
  // kinematics and the contact layer (subtractReactions), kChunk columns a pass; the reactions
  // enter as constants. Nothing else of F depends on q but RNEA (jacobianColumns).
  const int n = nv(), first_reaction = (with_dynamics ? 3 : 2) * n + inputs_count();
  int columns[kMaxCoordinates], count = 0;
  for (int k = 0; k < n; ++k)
    if (inReactions(k)) columns[count++] = k;
  if (count == 0) return;
  const auto& model = models->model<Dual>();
  auto& data = models->data<Dual>();
  const auto unseeded = Eigen::Matrix<double, kChunk, 1>::Zero();
  Eigen::Matrix<Dual, Eigen::Dynamic, 1, 0, kMaxCoordinates, 1> q(n), y(n);
  for (int i = 0; i < n; ++i) q[i] = Dual(x[i], unseeded);
  reactions_dual.resize(static_cast<std::size_t>(inputs() - first_reaction));
  for (std::size_t i = 0; i < reactions_dual.size(); ++i)
    reactions_dual[i] = Dual(x[first_reaction + static_cast<int>(i)], unseeded);
  for (int first = 0; first < count; first += kChunk) {
    const int chunk = std::min(kChunk, count - first);
    for (int c = 0; c < chunk; ++c) q[columns[first + c]].derivatives()[c] = 1.0;
    dynamics::forwardKinematics(model, data, ConstMap<Dual>(q.data(), n));
    for (int i = 0; i < n; ++i) y[i] = Dual(0.0, unseeded);
    subtractReactions(model, data, reactions_dual.data(), y.data());
    for (int c = 0; c < chunk; ++c) {
      double* column = J + columns[first + c] * n;
      for (int i = 0; i < n; ++i) column[i] += y[i].derivatives()[c];
      q[columns[first + c]].derivatives()[c] = 0.0;
    }
  }
}

template class AdFunction<EquationOfMotion>;

}  // namespace saltus::collocation
