// AD derivatives of RNEA and ABA against central finite differences.
#include "dynamics/derivatives.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"
#include "tests/support/random_model.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

// Central differences of f: R^n -> R^n along each coordinate of x.
template <class F>
Eigen::MatrixXd finiteDifference(F f, const Eigen::VectorXd& x, double eps = 1e-6) {
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd J(f(x).size(), n);
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += eps;
    xm[j] -= eps;
    J.col(j) = (f(xp) - f(xm)) / (2 * eps);
  }
  return J;
}

double relativeError(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) { return (A - B).norm() / (1 + B.norm()); }

TEST(Derivatives, RneaMatchesFiniteDifferences) {
  std::mt19937 rng(71);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int nj : {1, 5, 11}) {  // 11 + 6 base coordinates: several chunks of 8 directions
      const Model<double> model = testing::randomTreeBuilder(rng, nj).build(base);
      Data<double> data(model);
      DerivativeData<8> dd(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                            a = testing::randomVector(rng, n);
      rneaDerivatives(model, dd, q, v, a);
      auto tau_q = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(rnea(model, data, x, v, a)); };
      auto tau_v = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(rnea(model, data, q, x, a)); };
      auto tau_a = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(rnea(model, data, q, v, x)); };
      EXPECT_LT(relativeError(dd.dtau_dq, finiteDifference(tau_q, q)), 1e-7) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.dtau_dv, finiteDifference(tau_v, v)), 1e-7) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.data.M, finiteDifference(tau_a, a)), 1e-7) << toString(base) << " n=" << n;
    }
  }
}

// ∂τ/∂q, ∂τ/∂q̇ by scalar dual numbers through rnea() itself (Eigen::AutoDiffScalar, every
// direction seeded, chunks of 8), an AD independent of rneaDerivatives' spatial-operation tangents
// (tangent.hpp), its chunks over subtrees and its floating-base step.
void expectRneaDerivativesMatchScalarDuals(const Model<double>& model, const Eigen::VectorXd& q,
                                           const Eigen::VectorXd& v, const Eigen::VectorXd& a, const std::string& what) {
  DerivativeData<8> dd(model);
  rneaDerivatives(model, dd, a, q, v);  // another state first: the workspace must not leak into the next call
  rneaDerivatives(model, dd, q, v, a);
  const int n = model.nv();
  Data<Dual<8>> dual(dd.model_dual);
  VecX<Dual<8>> qd(n), vd(n), ad(n);
  Eigen::MatrixXd dtau_dq(n, n), dtau_dv(n, n), dtau_da(n, n);
  MatX<double>* blocks[3] = {&dtau_dq, &dtau_dv, &dtau_da};
  for (int first = 0; first < 3 * n; first += 8) {
    detail::seed<8>(qd, vd, ad, q, v, a, first);
    detail::extract<8>(rnea(dd.model_dual, dual, qd, vd, ad), first, 3 * n, blocks);
  }
  EXPECT_LT(relativeError(dd.dtau_dq, dtau_dq), 1e-12) << what;
  EXPECT_LT(relativeError(dd.dtau_dv, dtau_dv), 1e-12) << what;
  EXPECT_LT(relativeError(dd.data.M, dtau_da), 1e-12) << what;
}

TEST(Derivatives, RneaMatchesScalarDualNumbersOnRandomTrees) {
  std::mt19937 rng(73);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int nj : {1, 4, 13}) {
      // General axes, prismatic and fixed joints; then revolute axis joints (joint.hpp's kernels).
      for (bool axis_joints : {false, true}) {
        const Model<double> model = (axis_joints ? testing::randomAxisTreeBuilder(rng, nj)
                                                 : testing::randomTreeBuilder(rng, nj)).build(base);
        const int n = model.nv();
        expectRneaDerivativesMatchScalarDuals(model, testing::randomVector(rng, n), testing::randomVector(rng, n),
                                              testing::randomVector(rng, n),
                                              std::string(toString(base)) + " n=" + std::to_string(n) + (axis_joints ? " axis" : ""));
      }
    }
  }
}

TEST(Derivatives, RneaMatchesScalarDualNumbersOnBenchmarkModels) {
  std::mt19937 rng(74);
  for (const char* name : {"iiwa", "hyq", "atlas"}) {
    const BaseType base = std::string(name) == "iiwa" ? BaseType::Fixed : BaseType::Free;
    const Model<double> model =
        loadUrdfFile(std::string(SALTUS_SOURCE_DIR) + "/models/benchmark/" + name + ".urdf", base);
    const int n = model.nv();
    expectRneaDerivativesMatchScalarDuals(model, testing::randomVector(rng, n), testing::randomVector(rng, n),
                                          testing::randomVector(rng, n), name);
  }
}

TEST(Derivatives, AbaMatchesFiniteDifferences) {
  std::mt19937 rng(72);
  for (BaseType base : {BaseType::Fixed, BaseType::Planar, BaseType::Free}) {
    for (int nj : {2, 7}) {
      const Model<double> model = testing::randomTreeBuilder(rng, nj).build(base);
      Data<double> data(model);
      DerivativeData<8> dd(model);
      const int n = model.nv();
      const Eigen::VectorXd q = testing::randomVector(rng, n), v = testing::randomVector(rng, n),
                            tau = testing::randomVector(rng, n);
      abaDerivatives(model, dd, q, v, tau);
      auto f_q = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(aba(model, data, x, v, tau)); };
      auto f_v = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(aba(model, data, q, x, tau)); };
      auto f_t = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(aba(model, data, q, v, x)); };
      EXPECT_LT(relativeError(dd.dqdd_dq, finiteDifference(f_q, q)), 1e-6) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.dqdd_dv, finiteDifference(f_v, v)), 1e-6) << toString(base) << " n=" << n;
      EXPECT_LT(relativeError(dd.dqdd_dtau, finiteDifference(f_t, tau)), 1e-6) << toString(base) << " n=" << n;
      // ∂q̈/∂τ = M⁻¹ exactly.
      EXPECT_LT(relativeError(dd.dqdd_dtau, crba(model, data, q).inverse()), 1e-10);
    }
  }
}

TEST(Derivatives, WrongArgumentSizesAreErrors) {
  testing::ArgumentSizes a;
  const auto& [model, data, ok, bad] = std::tie(a.model, a.data, a.ok, a.bad);
  auto error = [](const std::function<void()>& f) { return testing::invalidArgumentOf(f); };
  DerivativeData<8> dd(model);
  EXPECT_NE(error([&] { rneaDerivatives(model, dd, bad, ok, ok); }).find("rneaDerivatives: q has 4"), std::string::npos);
  EXPECT_NE(error([&] { abaDerivatives(model, dd, ok, ok, bad); }).find("abaDerivatives: tau has 4"), std::string::npos);
}

}  // namespace
}  // namespace saltus::dynamics
