// Dynamics kernels on the standard benchmark models (models/benchmark: iiwa 7 DoF fixed base,
// HyQ 12 DoF and Atlas 30 DoF on a free base), over a pool of random states as in the peers'
// figures (Pinocchio 3, RBDL 3.3, MuJoCo 2.2.2 and DART 6.12, measured on this project's 2-core
// machine: 100k random samples, gravity 0).
// Run: build/bench/saltus_bench  (or scripts/bench.sh for the table against the peers).
#include <benchmark/benchmark.h>

#include <map>
#include <random>
#include <string>
#include <vector>

#include "dynamics/derivatives.hpp"
#include "dynamics/dynamics.hpp"
#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"

namespace {

using namespace saltus::dynamics;

struct Fixture {
  Model<double> model;
  std::vector<Eigen::VectorXd> q, v, a;
  int point_body;  // the last body: a hand or foot
};

const Fixture& fixture(const std::string& name) {
  static std::map<std::string, Fixture> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  const BaseType base = name == "iiwa" ? BaseType::Fixed : BaseType::Free;
  Fixture f{loadUrdfFile(std::string(SALTUS_SOURCE_DIR) + "/models/benchmark/" + name + ".urdf", base), {}, {}, {}, 0};
  f.model.gravity.setZero();
  std::mt19937 rng(2024);  // fixed seed: the same states every run
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = f.model.nv();
  for (int k = 0; k < 1024; ++k) {
    Eigen::VectorXd q(n), v(n), a(n);
    for (int i = 0; i < n; ++i) q[i] = u(rng), v[i] = u(rng), a[i] = u(rng);
    f.q.push_back(q), f.v.push_back(v), f.a.push_back(a);
  }
  f.point_body = f.model.nbodies() - 1;
  return cache.emplace(name, std::move(f)).first->second;
}

void BM_RNEA(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
  Data<double> data(f.model);
  size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(rnea(f.model, data, f.q[k], f.v[k], f.a[k]).data());
    k = (k + 1) & 1023;
  }
}

void BM_CRBA(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
  Data<double> data(f.model);
  size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(crba(f.model, data, f.q[k]).data());
    k = (k + 1) & 1023;
  }
}

void BM_ABA(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
  Data<double> data(f.model);
  size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(aba(f.model, data, f.q[k], f.v[k], f.a[k]).data());
    k = (k + 1) & 1023;
  }
}

// Forward kinematics plus the 3 × nv Jacobian of a point on the last body.
void BM_PointJacobian(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
  Data<double> data(f.model);
  Mat3X<double> J(3, f.model.nv());
  const Eigen::Vector3d p(0.05, 0.02, -0.1);
  size_t k = 0;
  for (auto _ : state) {
    forwardKinematics(f.model, data, f.q[k]);
    pointJacobian(f.model, data, f.point_body, p, J);
    benchmark::DoNotOptimize(J.data());
    k = (k + 1) & 1023;
  }
}

// ∂τ/∂q, ∂τ/∂q̇ by forward-mode AD (chunks of 8) and ∂τ/∂q̈ = M.
void BM_RNEA_AD_Jacobian(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
  DerivativeData<8> dd(f.model);
  size_t k = 0;
  for (auto _ : state) {
    rneaDerivatives(f.model, dd, f.q[k], f.v[k], f.a[k]);
    benchmark::DoNotOptimize(dd.dtau_dq.data());
    k = (k + 1) & 1023;
  }
}

void BM_ABA_AD_Jacobian(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
  DerivativeData<8> dd(f.model);
  size_t k = 0;
  for (auto _ : state) {
    abaDerivatives(f.model, dd, f.q[k], f.v[k], f.a[k]);
    benchmark::DoNotOptimize(dd.dqdd_dq.data());
    k = (k + 1) & 1023;
  }
}

#define SALTUS_BENCH_ALL(fn)                                          \
  BENCHMARK_CAPTURE(fn, iiwa, std::string("iiwa"))->Unit(benchmark::kMicrosecond); \
  BENCHMARK_CAPTURE(fn, hyq, std::string("hyq"))->Unit(benchmark::kMicrosecond);   \
  BENCHMARK_CAPTURE(fn, atlas, std::string("atlas"))->Unit(benchmark::kMicrosecond)

SALTUS_BENCH_ALL(BM_RNEA);
SALTUS_BENCH_ALL(BM_CRBA);
SALTUS_BENCH_ALL(BM_ABA);
SALTUS_BENCH_ALL(BM_PointJacobian);
SALTUS_BENCH_ALL(BM_RNEA_AD_Jacobian);
SALTUS_BENCH_ALL(BM_ABA_AD_Jacobian);

}  // namespace
