// The LCP solvers (timestepper/lcp.hpp) on random velocity-level contact LCPs of the sizes the
// time-stepper meets (nv coordinates, m contacts with k = 4 friction directions: n = m (k + 2)),
// against Siconos Numerics' lcp_lexicolemke on the same problems (its time includes building its
// problem and options, which its API needs per call). 50 problems per size from a fixed seed.
// Run: build/bench/saltus_bench --benchmark_filter=Lcp
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "tests/support/contact_lcp.hpp"
#include "timestepper/lcp.hpp"

namespace {

using saltus::testing::ContactLcp;

struct LcpShape {
  int nv, contacts, directions;
};

const std::vector<ContactLcp>& contactProblems(const LcpShape& shape) {
  static std::vector<std::vector<ContactLcp>> cache(64);
  std::vector<ContactLcp>& problems = cache[shape.contacts];
  if (problems.empty()) {
    std::mt19937 rng(110 + shape.contacts);  // fixed seed per size
    for (int i = 0; i < 50; ++i)
      problems.push_back(saltus::testing::randomContactLcp(rng, shape.nv, shape.contacts, shape.directions));
  }
  return problems;
}

void BM_LcpLemke(benchmark::State& state, LcpShape shape) {
  const std::vector<ContactLcp>& problems = contactProblems(shape);
  const int n = static_cast<int>(problems[0].q.size());
  saltus::timestepper::LcpSolver solver(n);
  Eigen::VectorXd z(n), w(n);
  std::size_t k = 0;
  long pivots = 0;
  for (auto _ : state) {
    const ContactLcp& lcp = problems[k];
    const saltus::timestepper::LcpResult r = solver.solveLemke(lcp.M, lcp.q, z, w);
    if (r.status != saltus::timestepper::LcpStatus::Solved) state.SkipWithError("Lemke failed");
    pivots += r.iterations;
    benchmark::DoNotOptimize(z.data());
    k = (k + 1) % problems.size();
  }
  state.counters["n"] = n;
  state.counters["pivots"] = benchmark::Counter(static_cast<double>(pivots), benchmark::Counter::kAvgIterations);
}

void BM_LcpSiconosLexicoLemke(benchmark::State& state, LcpShape shape) {
  const std::vector<ContactLcp>& problems = contactProblems(shape);
  std::size_t k = 0;
  for (auto _ : state) {
    const ContactLcp& lcp = problems[k];
    const saltus::testing::SiconosSolution s = saltus::testing::siconosSolve(SICONOS_LCP_LEMKE, lcp.M, lcp.q);
    if (s.info != 0) state.SkipWithError("Siconos failed");
    benchmark::DoNotOptimize(s.z.data());
    k = (k + 1) % problems.size();
  }
  state.counters["n"] = static_cast<double>(problems[0].q.size());
}

BENCHMARK_CAPTURE(BM_LcpLemke, nv6_m2, LcpShape{6, 2, 4});
BENCHMARK_CAPTURE(BM_LcpLemke, nv12_m3, LcpShape{12, 3, 4});
BENCHMARK_CAPTURE(BM_LcpLemke, nv18_m4, LcpShape{18, 4, 4});
BENCHMARK_CAPTURE(BM_LcpLemke, nv30_m6, LcpShape{30, 6, 4});
BENCHMARK_CAPTURE(BM_LcpSiconosLexicoLemke, nv6_m2, LcpShape{6, 2, 4});
BENCHMARK_CAPTURE(BM_LcpSiconosLexicoLemke, nv12_m3, LcpShape{12, 3, 4});
BENCHMARK_CAPTURE(BM_LcpSiconosLexicoLemke, nv18_m4, LcpShape{18, 4, 4});
BENCHMARK_CAPTURE(BM_LcpSiconosLexicoLemke, nv30_m6, LcpShape{30, 6, 4});

}  // namespace
