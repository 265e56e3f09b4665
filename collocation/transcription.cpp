#include "collocation/transcription.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace saltus::collocation {

namespace {
std::string at(int n, int p) { return "[" + std::to_string(n + 1) + "," + std::to_string(p) + "]"; }
// lower ≤ y ≤ upper for a joint stop's gap y = sign·(q_i − limit), as an interval of q_i.
std::pair<double, double> stopGapAsCoordinate(const ContactPair& stop, double lower, double upper) {
  if (stop.sign > 0) return {stop.limit + lower, stop.limit + upper};
  return {stop.limit - upper, stop.limit - lower};
}
}  // namespace

std::string methodCannotTake(const Problem& problem, Method method) {
  if (method == Method::Impulsive) return "";
  auto refuse = [&](const std::string& what, double e) {
    std::ostringstream m;
    m << "the " << toString(method) << " method cannot represent restitution: " << what << " has e = " << e
      << " (> 0); use --method impulsive, or restitution 0";
    return m.str();
  };
  for (const scene::Contact& c : problem.scene.contacts)
    if (c.restitution > 0) return refuse("contact '" + c.name + "'", c.restitution);
  for (const scene::LimitStop& l : problem.scene.limits)
    if (l.restitution > 0) return refuse("joint stop '" + l.name + "'", l.restitution);
  return "";
}

Transcription::Transcription(const Problem& problem, Method method)
    : problem_(problem), method_(method), lg_(method == Method::FirstOrder ? 1 : problem.P) {
  const auto& model = problem.scene.model;
  nv_ = model.nv();
  nu_ = static_cast<int>(problem.inputs.size());
  if (nv_ > kMaxCoordinates)
    throw std::invalid_argument("collocation supports at most " + std::to_string(kMaxCoordinates) +
                                " coordinates; the model has " + std::to_string(nv_));
  if (problem.N < 1) throw std::invalid_argument("N must be ≥ 1");
  if (problem.P < 1) throw std::invalid_argument("P must be ≥ 1");
  models_ = std::make_unique<ModelSet>(model);
  buildContacts();
  restitution_.resize(contacts_.size());
  if (const std::string why = methodCannotTake(problem, method); !why.empty()) throw std::invalid_argument(why);
  buildVariables();
  for (int n = 0; n < elements(); ++n) {
    buildElementConstraints(n);
    buildContactConstraints(n);
  }
  buildProblemConstraints();
  applyBounds();
}

const std::string& Transcription::coordinate(int i) const { return problem_.scene.model.coordinate_name[i]; }

void Transcription::buildContacts() { contacts_ = contact::contactPairs(problem_.scene); }

int Transcription::addVariables(int count, double lower, double upper, const std::string& name) {
  const int first = static_cast<int>(xl_.size());
  for (int i = 0; i < count; ++i) {
    xl_.push_back(lower);
    xu_.push_back(upper);
    x_names_.push_back(count == 1 ? name : name + "." + std::to_string(i));
  }
  return first;
}

int Transcription::addBlock(std::shared_ptr<const LocalFunction> f, std::vector<int> vars, double lower,
                            double upper, const std::string& name) {
  if (static_cast<int>(vars.size()) != f->inputs())
    throw std::logic_error("block " + name + ": " + std::to_string(vars.size()) + " variables for " +
                           std::to_string(f->inputs()) + " inputs");
  Block b;
  b.row = static_cast<int>(gl_.size());
  for (int r = 0; r < f->outputs(); ++r) {
    gl_.push_back(lower);
    gu_.push_back(upper);
    g_names_.push_back(f->outputs() == 1 ? name : name + "." + std::to_string(r));
  }
  b.f = std::move(f);
  b.vars = std::move(vars);
  blocks_.push_back(std::move(b));
  return static_cast<int>(blocks_.size()) - 1;
}

void Transcription::addCost(std::shared_ptr<const LocalFunction> f, std::vector<int> vars, CostGroup group) {
  Block b;
  b.f = std::move(f);
  b.vars = std::move(vars);
  b.cost_group = group;
  blocks_.push_back(std::move(b));
}

int Transcription::addProduct(const std::vector<int>& a_vars, const Eigen::VectorXd& a, double a0,
                              const std::vector<int>& b_vars, const Eigen::VectorXd& b, double b0,
                              const std::string& name, double weight) {
  const int eps = addVariables(1, 0, kInf, "eps." + name);
  epsilon_.push_back(eps);
  penalty_weights_.push_back(weight);
  std::vector<int> vars = a_vars;
  vars.insert(vars.end(), b_vars.begin(), b_vars.end());
  vars.push_back(eps);
  const int blk = addBlock(std::make_shared<ComplementarityProduct>(a, a0, b, b0), vars, -kInf, 0, name);
  product_blocks_.push_back(blk);
  return blk;
}

void Transcription::addLinearEquality(const std::vector<int>& vars, const Eigen::VectorXd& c, double rhs,
                                      const std::string& name) {
  addBlock(std::make_shared<LinearFunction>(c), vars, rhs, rhs, name);
}

void Transcription::buildVariables() {
  const bool first_order = method_ == Method::FirstOrder;
  const bool impulsive = method_ == Method::Impulsive;
  const int steps_per_element = first_order ? problem_.first_order_steps_per_element : 1;
  const int elements = problem_.N * steps_per_element;
  const double h_max = problem_.h_max / steps_per_element;
  const int P = first_order ? 1 : problem_.P;
  layout_.resize(elements);
  for (int n = 0; n < elements; ++n) {
    ElementLayout& L = layout_[n];
    L.h = addVariables(1, problem_.h_min_ratio * h_max, h_max, "h" + at(n, 0));
    L.tau.push_back(0);
    if (first_order) {
      L.tau.push_back(1);
      L.collocation = {1};
      L.end = 1;
    } else {
      for (int p = 0; p < P; ++p) L.tau.push_back(lg_.tau[p]), L.collocation.push_back(p + 1);
      L.tau.push_back(1);
      L.end = P + 1;
    }
    const int npts = static_cast<int>(L.tau.size());
    L.points.resize(npts);
    for (int p = 0; p < npts; ++p) {
      auto& pt = L.points[p];
      pt.q = addVariables(nv_, -kInf, kInf, "q" + at(n, p));
      pt.v = addVariables(nv_, -kInf, kInf, "v" + at(n, p));
    }
    for (int p : L.collocation) {
      L.points[p].accel_or_jump = addVariables(nv_, -kInf, kInf, "a" + at(n, p));
      if (nu_ > 0) L.points[p].u = addVariables(nu_, -kInf, kInf, "u" + at(n, p));
    }
    const bool jump = impulsive && n > 0;
    if (jump) L.points[0].accel_or_jump = addVariables(nv_, -kInf, kInf, "dv" + at(n, 0));
    L.contacts.resize(contacts_.size());
    for (std::size_t c = 0; c < contacts_.size(); ++c) {
      const ContactPair& cp = contacts_[c];
      auto& C = L.contacts[c];
      const std::string tag = cp.name;
      C.y.assign(npts, -1);
      C.rn.assign(npts, -1);
      C.tangential.assign(npts, -1);
      C.gamma.assign(npts, -1);
      C.psi.assign(npts, -1);
      C.slip_block.assign(npts, -1);
      C.s.assign(npts, -1);
      C.d_plus.assign(npts, -1);
      C.d_minus.assign(npts, -1);
      if (cp.isStop()) {  // y = sign·(q_i − limit) ≥ 0 (gap): the coordinate's bound
        const auto [lower, upper] = stopGapAsCoordinate(cp, 0, kInf);
        for (const auto& pt : L.points) {
          const int qi = pt.q + cp.position;
          xl_[qi] = std::max(xl_[qi], lower);
          xu_[qi] = std::min(xu_[qi], upper);
        }
      } else {
        for (int p = 0; p < npts; ++p) C.y[p] = addVariables(1, 0, kInf, "y." + tag + at(n, p));
      }
      std::vector<int> force_points = L.collocation;
      if (jump) force_points.insert(force_points.begin(), 0);
      for (int p : force_points) {
        C.rn[p] = addVariables(1, 0, kInf, (p == 0 ? "pn." : "rn.") + tag + at(n, p));
        if (cp.k() > 0) {
          C.tangential[p] = addVariables(cp.k(), 0, first_order ? kInf : 1.0, (first_order ? "beta." : "alpha.") + tag + at(n, p));
          C.gamma[p] = addVariables(1, 0, kInf, "gamma." + tag + at(n, p));
        }
        if (cp.freePoint()) {
          const int m = cp.freeAxes();
          for (int i = 0; i < m; ++i) {
            const int axis = cp.free_axes[i];
            const int v = addVariables(1, -cp.extent[axis], cp.extent[axis],
                                       "s." + tag + at(n, p) + (m == 1 ? "" : "." + std::to_string(i)));
            if (i == 0) C.s[p] = v;
          }
          C.d_plus[p] = addVariables(m, 0, kInf, "d+." + tag + at(n, p));
          C.d_minus[p] = addVariables(m, 0, kInf, "d-." + tag + at(n, p));
        }
      }
      if (jump) {
        C.a_plus = addVariables(1, 0, kInf, "a+." + tag + at(n, 0));
        C.a_minus = addVariables(1, 0, kInf, "a-." + tag + at(n, 0));
      }
    }
  }
  if (problem_.cost.max_coordinate >= 0) x_max_ = addVariables(1, -kInf, kInf, "x_max");
}

static std::vector<int> range(int first, int count) {
  std::vector<int> v(count);
  for (int i = 0; i < count; ++i) v[i] = first + i;
  return v;
}

void Transcription::buildElementConstraints(int n) {
  const ElementLayout& L = layout_[n];
  const bool first_order = method_ == Method::FirstOrder;
  const int P = static_cast<int>(L.collocation.size());
  auto integrate = [&](int target, const Eigen::VectorXd& c, const std::string& name) {
    const auto f = std::make_shared<AdFunction<Integration>>(Integration{c});
    for (int i = 0; i < nv_; ++i)
      for (int kind = 0; kind < 2; ++kind) {  // q from q̇, q̇ from q̈
        auto var = [&](int p) { return kind == 0 ? L.points[p].q + i : L.points[p].v + i; };
        auto rate = [&](int p) { return kind == 0 ? L.points[p].v + i : L.points[p].accel_or_jump + i; };
        std::vector<int> vars = {var(target), var(0), L.h};
        for (int p : L.collocation) vars.push_back(rate(p));
        addBlock(f, vars, 0, 0, std::string(kind == 0 ? "int.q" : "int.v") + name + "." + coordinate(i));
      }
  };
  if (first_order) {
    integrate(1, Eigen::VectorXd::Ones(1), at(n, 1));  // backward Euler
  } else {
    for (int p = 0; p < P; ++p) integrate(L.collocation[p], lg_.Omega.row(p).transpose(), at(n, p + 1));  // (3)
    integrate(L.end, lg_.b, at(n, L.end));                                                             // (4)
  }
  // Continuity (5).
  if (n > 0) {
    const ElementLayout& prev = layout_[n - 1];
    for (int i = 0; i < nv_; ++i) {
      addLinearEquality({L.points[0].q + i, prev.points[prev.end].q + i}, Eigen::Vector2d(1, -1), 0,
                        "cont.q" + at(n, 0) + "." + coordinate(i));
      if (L.points[0].accel_or_jump >= 0)
        addLinearEquality({L.points[0].v + i, prev.points[prev.end].v + i, L.points[0].accel_or_jump + i},
                          Eigen::Vector3d(1, -1, -1), 0, "jump.v" + at(n, 0) + "." + coordinate(i));
      else
        addLinearEquality({L.points[0].v + i, prev.points[prev.end].v + i}, Eigen::Vector2d(1, -1), 0,
                          "cont.v" + at(n, 0) + "." + coordinate(i));
    }
  }
  // Equations of motion at the collocation points, and (6) at an impulsive [n, 0].
  const FrictionForm form = frictionForm();
  auto eom = [&](int p, bool with_dynamics) {
    // One function per kind, shared by every point (its work arrays are sized once).
    auto& f = with_dynamics ? eom_with_dynamics_ : eom_impulsive_;
    if (!f)
      f = std::make_shared<AdFunction<EquationOfMotion>>(
          EquationOfMotion{models_.get(), &contacts_, problem_.inputs, with_dynamics, form, constantInput()});
    std::vector<int> vars = range(L.points[p].q, nv_);
    if (with_dynamics) {
      const auto v = range(L.points[p].v, nv_);
      vars.insert(vars.end(), v.begin(), v.end());
    }
    const auto a = range(L.points[p].accel_or_jump, nv_);
    vars.insert(vars.end(), a.begin(), a.end());
    if (with_dynamics && nu_ > 0) {
      const auto u = range(L.points[p].u, nu_);
      vars.insert(vars.end(), u.begin(), u.end());
    }
    for (std::size_t c = 0; c < contacts_.size(); ++c) {
      vars.push_back(L.contacts[c].rn[p]);
      for (int i = 0; i < contacts_[c].k(); ++i) vars.push_back(L.contacts[c].tangential[p] + i);
      for (int i = 0; i < contacts_[c].freeAxes(); ++i) vars.push_back(L.contacts[c].s[p] + i);
    }
    const std::string name = (with_dynamics ? "eom" : "impulse") + at(n, p);
    const int row = blocks_[addBlock(f, vars, 0, 0, name)].row;
    for (int i = 0; i < nv_; ++i) g_names_[row + i] = name + "." + coordinate(i);  // a row per coordinate
  };
  for (int p : L.collocation) eom(p, true);
  if (L.points[0].accel_or_jump >= 0) eom(0, false);
}

void Transcription::buildContactConstraints(int n) {
  if (contacts_.empty()) return;
  ElementLayout& L = layout_[n];
  const bool first_order = method_ == Method::FirstOrder;
  const int npts = static_cast<int>(L.points.size());
  const int nc = static_cast<int>(contacts_.size());
  // Gap variables at every point.
  GapDefinition gap_definition{models_.get(), &contacts_, {}};
  for (int c = 0; c < nc; ++c)
    if (!contacts_[c].isStop()) gap_definition.pairs.push_back(c);
  if (!gap_definition.pairs.empty()) {
    const auto gap = std::make_shared<AdFunction<GapDefinition>>(gap_definition);
    for (int p = 0; p < npts; ++p) {
      std::vector<int> vars = range(L.points[p].q, nv_);
      for (int c : gap_definition.pairs) vars.push_back(L.contacts[c].y[p]);
      addBlock(gap, vars, 0, 0, "gap" + at(n, p));
    }
  }
  // A plane fixed in a body is a rectangle (a deck, a cart's top): the point stays over it,
  // |s_i| ≤ extent_i at every point of the mesh (point 0 of a later element is the previous
  // end), so that the gap of the unbounded plane is its gap. A motion that leaves the rectangle
  // (off the end of a deck) is outside what the transcription represents: its solve is infeasible.
  // A free contact point instead keeps its contact point s over the rectangle (its bounds) and A
  // at s while the contact carries a reaction, along its free axes; along the other (a planar
  // model's t2) the point stays over the rectangle as here.
  for (int c = 0; c < nc; ++c) {
    const ContactPair& cp = contacts_[c];
    if (!contact::hasExtent(cp)) continue;
    for (int axis = 0; axis < 2; ++axis) {
      if (!std::isfinite(cp.extent[axis])) continue;
      if (std::find(cp.free_axes.begin(), cp.free_axes.end(), axis) != cp.free_axes.end()) continue;
      const auto s = std::make_shared<AdFunction<PlaneCoordinate>>(PlaneCoordinate{models_.get(), &cp, axis});
      for (int p = n == 0 ? 0 : 1; p < npts; ++p)
        addBlock(s, range(L.points[p].q, nv_), -cp.extent[axis], cp.extent[axis],
                 "extent." + cp.name + "." + std::to_string(axis + 1) + at(n, p));
    }
  }
  for (int c = 0; c < nc; ++c) {
    const ContactPair& cp = contacts_[c];
    auto& C = L.contacts[c];
    const std::string tag = cp.name;
    // (9) at an impulsive [n, 0].
    if (C.a_plus >= 0) {
      const ElementLayout& prev = layout_[n - 1];
      const ElementLayout::Point &after = L.points[0], &before = prev.points[prev.end];
      std::vector<int> vars;
      if (cp.isStop()) {
        // ẏ = sign·q̇_i (contact::normalVelocity of a stop): (9a) is linear in four variables.
        vars = {after.v + cp.coordinate, before.v + cp.coordinate};
        if (!restitution_[c])
          restitution_[c] = std::make_shared<LinearFunction>(
              Eigen::Vector4d(-cp.sign, -cp.restitution * cp.sign, 1.0, -1.0));
      } else {
        const bool with_before = cp.restitution != 0;
        vars = range(after.q, nv_);
        for (int v : range(after.v, nv_)) vars.push_back(v);
        if (with_before) {
          for (int v : range(before.q, nv_)) vars.push_back(v);
          for (int v : range(before.v, nv_)) vars.push_back(v);
        }
        if (!restitution_[c])
          restitution_[c] = std::make_shared<AdFunction<RestitutionBalance>>(
              RestitutionBalance{models_.get(), &contacts_[c], with_before});
      }
      vars.push_back(C.a_plus);  // a⁺, a⁻ last (Transcription::seed reads them there)
      vars.push_back(C.a_minus);
      layout_[n].contacts[c].restitution_block = addBlock(restitution_[c], vars, 0, 0, "restitution." + tag + at(n, 0));
      // (9b) as two products, r_n ⊥ y and r_n ⊥ a⁺ + a⁻ (the same complementarity: every factor
      // is ≥ 0), so that an impulse in mid-air (the penalty's local minimum from a cold seed) is
      // penalised on its own, with kMidAirImpulseWeight.
      const Affine y0 = gap(n, c, 0);
      addProduct({C.rn[0]}, Eigen::VectorXd::Ones(1), 0, y0.vars, y0.c, y0.c0, "impact_gap." + tag + at(n, 0),
                 kMidAirImpulseWeight);
      addProduct({C.rn[0]}, Eigen::VectorXd::Ones(1), 0, {C.a_plus, C.a_minus}, Eigen::Vector2d::Ones(), 0,
                 "impact." + tag + at(n, 0));
      // a⁺ ⊥ a⁻, so that a⁺ + a⁻ = |ẏ[n,0] + e ẏ[n−1,P+1]|: without it the pair is free whenever
      // the contact is open and the barrier drives both to huge values.
      addProduct({C.a_plus}, Eigen::VectorXd::Ones(1), 0, {C.a_minus}, Eigen::VectorXd::Ones(1), 0,
                 "split." + tag + at(n, 0));
    }
    // A free point: s_A(q) − s = d⁺ − d⁻, r_n ⊥ Σ (d⁺ + d⁻), d⁺ ⊥ d⁻ where there is a reaction.
    if (cp.freePoint()) {
      const int m = cp.freeAxes();
      const auto offset = std::make_shared<AdFunction<FreePointOffset>>(FreePointOffset{models_.get(), &contacts_[c]});
      for (int p = 0; p < npts; ++p) {
        if (C.s[p] < 0) continue;
        std::vector<int> vars = range(L.points[p].q, nv_);
        for (int first : {C.s[p], C.d_plus[p], C.d_minus[p]})
          for (int i = 0; i < m; ++i) vars.push_back(first + i);
        addBlock(offset, vars, 0, 0, "offset." + tag + at(n, p));
        std::vector<int> d = range(C.d_plus[p], m);
        for (int i = 0; i < m; ++i) d.push_back(C.d_minus[p] + i);
        addProduct({C.rn[p]}, Eigen::VectorXd::Ones(1), 0, d, Eigen::VectorXd::Ones(2 * m), 0,
                   "on_point." + tag + at(n, p), method_ == Method::Impulsive && p == 0 ? kMidAirImpulseWeight : 1.0);
        for (int i = 0; i < m; ++i)
          addProduct({C.d_plus[p] + i}, Eigen::VectorXd::Ones(1), 0, {C.d_minus[p] + i}, Eigen::VectorXd::Ones(1), 0,
                     "offset_split." + tag + at(n, p) + (m == 1 ? "" : "." + std::to_string(i)));
      }
    }
    // (10), or Posa's φ(q[k+1]) ⊥ λ_n.
    for (int p : L.collocation) {
      Affine y = gap(n, c, p);
      if (!first_order) {  // Σ_i y[n, i]
        y = Affine{{}, Eigen::VectorXd(0), 0};
        for (int i = 0; i < npts; ++i) {
          const Affine yi = gap(n, c, i);
          y.vars.insert(y.vars.end(), yi.vars.begin(), yi.vars.end());
          y.c.conservativeResize(y.c.size() + yi.c.size());
          y.c.tail(yi.c.size()) = yi.c;
          y.c0 += yi.c0;
        }
      }
      addProduct({C.rn[p]}, Eigen::VectorXd::Ones(1), 0, y.vars, y.c, y.c0, "contact." + tag + at(n, p));
    }
    if (cp.k() == 0) continue;
    // Friction at the points with reactions: slip slacks ψ (12), then (13) or Posa's cone.
    std::vector<int> force_points;
    for (int p = 0; p < npts; ++p)
      if (C.rn[p] >= 0) force_points.push_back(p);
    std::vector<int> gammas;
    for (int p : force_points) gammas.push_back(C.gamma[p]);
    const int element = first_order ? n / problem_.first_order_steps_per_element : n;
    for (int p : force_points) {
      const int psi = addVariables(cp.k(), 0, kInf, "psi." + tag + at(n, p));
      SlipSlack s{models_.get(), &contacts_[c], surfaceVelocity(cp.surface, element),
                  frictionForm()};
      std::vector<int> vars = range(L.points[p].q, nv_);
      for (int v : range(L.points[p].v, nv_)) vars.push_back(v);
      for (int i = 0; i < cp.freeAxes(); ++i) vars.push_back(C.s[p] + i);
      vars.push_back(C.gamma[p]);
      for (int i = 0; i < cp.k(); ++i) vars.push_back(psi + i);
      C.psi[p] = psi;
      C.slip_block[p] = addBlock(std::make_shared<AdFunction<SlipSlack>>(s), vars, 0, 0, "slip." + tag + at(n, p));
      for (int i = 0; i < cp.k(); ++i)
        addProduct({C.tangential[p] + i}, Eigen::VectorXd::Ones(1), 0, {psi + i}, Eigen::VectorXd::Ones(1), 0,
                   "direction." + tag + at(n, p) + "." + std::to_string(i));
      const std::vector<int> t = range(C.tangential[p], cp.k());
      if (first_order) {
        // μ λ_n − Σ β_i ≥ 0 ⊥ γ.
        std::vector<int> cone = {C.rn[p]};
        cone.insert(cone.end(), t.begin(), t.end());
        Eigen::VectorXd c_cone = -Eigen::VectorXd::Ones(cp.k() + 1);
        c_cone[0] = cp.friction;
        addBlock(std::make_shared<LinearFunction>(c_cone), cone, 0, kInf, "cone." + tag + at(n, p));
        addProduct({C.gamma[p]}, Eigen::VectorXd::Ones(1), 0, cone, c_cone, 0, "sliding." + tag + at(n, p));
      } else {
        // Σ α_i ≤ 1, and (13): Σ_p γ[n, p] ⊥ 1 − Σ_i α_i[n, p].
        addBlock(std::make_shared<LinearFunction>(Eigen::VectorXd::Ones(cp.k())), t, -kInf, 1.0,
                 "cone." + tag + at(n, p));
        addProduct(gammas, Eigen::VectorXd::Ones(gammas.size()), 0, t, -Eigen::VectorXd::Ones(cp.k()), 1.0,
                   "sliding." + tag + at(n, p));
      }
    }
  }
}

void Transcription::buildProblemConstraints() {
  // Total time.
  if (problem_.total_time_kind != TotalTime::Free) {
    std::vector<int> hs;
    for (const auto& L : layout_) hs.push_back(L.h);
    const double T = problem_.total_time;
    addBlock(std::make_shared<LinearFunction>(Eigen::VectorXd::Ones(hs.size())), hs, T,
             problem_.total_time_kind == TotalTime::Equal ? T : kInf, "total_time");
  }
  // Penalty Σ ε (paper eq. 8).
  if (!epsilon_.empty())
    addCost(std::make_shared<LinearFunction>(Eigen::Map<const Eigen::VectorXd>(penalty_weights_.data(), penalty_weights_.size())),
            epsilon_, kPenaltyCost);
  // Task terms.
  const CostTerms& cost = problem_.cost;
  if (cost.effort_weight != 0 && nu_ > 0) {
    const auto f = std::make_shared<AdFunction<Effort>>(
        Effort{method_ == Method::FirstOrder ? Eigen::VectorXd::Ones(1) : lg_.b, nu_});
    for (const auto& L : layout_) {
      std::vector<int> vars = {L.h};
      for (int p : L.collocation)
        for (int i = 0; i < nu_; ++i) vars.push_back(L.points[p].u + i);
      addCost(std::make_shared<ScaledFunction>(f, cost.effort_weight), vars, kTaskCost);
    }
  }
  if (x_max_ >= 0) {
    const int i = cost.max_coordinate;  // tightenMaxVariable: the same points
    for (int n = 0; n < elements(); ++n)
      for (std::size_t p = 0; p < layout_[n].points.size(); ++p)
        addBlock(std::make_shared<LinearFunction>(Eigen::Vector2d(1, -1)), {layout_[n].points[p].q + i, x_max_},
                 -kInf, 0, "max" + at(n, static_cast<int>(p)));
    addCost(std::make_shared<LinearFunction>(Eigen::VectorXd::Constant(1, cost.max_weight)), {x_max_}, kTaskCost);
  }
}

void Transcription::applyBounds() {
  x_lower_ = Eigen::Map<Eigen::VectorXd>(xl_.data(), xl_.size());
  x_upper_ = Eigen::Map<Eigen::VectorXd>(xu_.data(), xu_.size());
  g_lower_ = Eigen::Map<Eigen::VectorXd>(gl_.data(), gl_.size());
  g_upper_ = Eigen::Map<Eigen::VectorXd>(gu_.data(), gu_.size());
  const scene::Scene& s = problem_.scene;
  // Initial state at [0, 0].
  const auto& p0 = layout_[0].points[0];
  auto free = [](const std::vector<int>& list, int i) { return std::find(list.begin(), list.end(), i) != list.end(); };
  for (int i = 0; i < nv_; ++i) {
    if (!free(problem_.initial_free_q, i)) x_lower_[p0.q + i] = x_upper_[p0.q + i] = s.q0[i];
    if (!free(problem_.initial_free_v, i)) x_lower_[p0.v + i] = x_upper_[p0.v + i] = s.v0[i];
  }
  // Inputs.
  for (const auto& L : layout_)
    for (int p : L.collocation)
      for (int i = 0; i < nu_; ++i) {
        x_lower_[L.points[p].u + i] = problem_.input_lower.size() ? problem_.input_lower[i] : -kInf;
        x_upper_[L.points[p].u + i] = problem_.input_upper.size() ? problem_.input_upper[i] : kInf;
      }
  // Point bounds: the problem's elements map onto first-order steps (element n ↔ steps
  // steps_per_element·n … steps_per_element·n + steps_per_element − 1; its mesh points to the first step's start and the last step's end).
  const int steps_per_element = method_ == Method::FirstOrder ? problem_.first_order_steps_per_element : 1;
  auto apply = [&](const PointBound& b, Eigen::VectorXd& lo, Eigen::VectorXd& hi) {
    auto one = [&](int n, int p) {
      const auto& L = layout_[n];
      const auto& pt = L.points[p];
      int var = -1;
      switch (b.quantity.kind) {
        case Quantity::Kind::Position: var = pt.q + b.quantity.index; break;
        case Quantity::Kind::Velocity: var = pt.v + b.quantity.index; break;
        case Quantity::Kind::Input: var = pt.u >= 0 ? pt.u + b.quantity.index : -1; break;
        case Quantity::Kind::Gap: {
          const ContactPair& cp = contacts_[b.quantity.index];
          var = L.contacts[b.quantity.index].y[p];
          if (cp.isStop()) {  // on q_i
            var = pt.q + cp.position;
            const auto [lower, upper] = stopGapAsCoordinate(cp, b.lower, b.upper);
            lo[var] = std::max(lo[var], lower);
            hi[var] = std::min(hi[var], upper);
            return;
          }
          break;
        }
      }
      if (var < 0) return;  // inputs exist at the collocation points only
      lo[var] = std::max(lo[var], b.lower);
      hi[var] = std::min(hi[var], b.upper);
    };
    for (int n = 0; n < elements(); ++n) {
      const int problem_element = n / steps_per_element;  // the problem's element
      if (b.element >= 0 && b.element != problem_element) continue;
      const int npts = static_cast<int>(layout_[n].points.size());
      for (int p = 0; p < npts; ++p) {
        if (b.point >= 0) {
          if (steps_per_element == 1) {
            if (p != b.point) continue;
          } else {  // first order: the element's start, end, or (collocation points) every step end
            const bool start = p == 0 && n % steps_per_element == 0, end = p == 1 && n % steps_per_element == steps_per_element - 1;
            if (b.point == 0 ? !start : b.point == problem_.P + 1 ? !end : p != 1) continue;
          }
        }
        one(n, p);
      }
    }
  };
  for (const PointBound& b : problem_.bounds) apply(b, x_lower_, x_upper_);
  x_lower_hint_ = x_lower_;
  x_upper_hint_ = x_upper_;
  for (const PointBound& b : problem_.hints) apply(b, x_lower_hint_, x_upper_hint_);
  for (int i = 0; i < variables(); ++i)
    if (x_lower_[i] > x_upper_[i] || x_lower_hint_[i] > x_upper_hint_[i])
      throw std::invalid_argument("the bounds on " + x_names_[i] + " are contradictory: [" +
                                  std::to_string(x_lower_hint_[i]) + ", " + std::to_string(x_upper_hint_[i]) + "]");
}

Transcription::Affine Transcription::gap(int n, int c, int p) const {
  const ContactPair& cp = contacts_[c];
  if (!cp.isStop()) return Affine{{layout_[n].contacts[c].y[p]}, Eigen::VectorXd::Ones(1), 0};
  return Affine{{layout_[n].points[p].q + cp.position}, Eigen::VectorXd::Constant(1, cp.sign), -cp.sign * cp.limit};
}

double Transcription::gapValue(const Eigen::VectorXd& x, int n, int c, int p) const {
  const Affine y = gap(n, c, p);
  double value = y.c0;
  for (std::size_t i = 0; i < y.vars.size(); ++i) value += y.c[i] * x[y.vars[i]];
  return value;
}

Eigen::Vector3d Transcription::surfaceVelocity(int surface, int element) const {
  if (surface < 0) return Eigen::Vector3d::Zero();  // a plane on a body: no prescribed motion
  const auto it = problem_.surface_steps.find(surface);
  if (it == problem_.surface_steps.end() || it->second.empty())
    return problem_.scene.surfaces.at(surface).velocity(0.0);
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (const SurfaceStep& s : it->second)
    if (s.element <= element) v = s.velocity;
  return v;
}

double Transcription::largestProduct(const Eigen::VectorXd& x, std::string* where) const {
  double worst = 0;
  Eigen::VectorXd local;
  for (int b : product_blocks_) {
    const Block& blk = blocks_[b];
    local.resize(blk.vars.size());
    for (std::size_t i = 0; i < blk.vars.size(); ++i) local[i] = x[blk.vars[i]];
    const double product = static_cast<const ComplementarityProduct&>(*blk.f).product(local.data());
    if (product > worst) {
      worst = product;
      if (where) *where = g_names_[blk.row];
    }
  }
  return worst;
}

}  // namespace saltus::collocation
