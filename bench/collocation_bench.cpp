// The transcription's evaluations as Ipopt calls them (constraints, their Jacobian, the Hessian
// of the Lagrangian), on the built-in problems and the three methods, at a fixed random point:
// the cost of the local functions' AD and of the contact layer inside them.
// Run: build/bench/saltus_bench --benchmark_filter=Evaluate
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "collocation/nlp.hpp"
#include "collocation/problem_file.hpp"
#include "collocation/transcription.hpp"

namespace {

using namespace saltus::collocation;

enum class Evaluation { Constraints, Jacobian, Hessian };

void BM_Evaluate(benchmark::State& state, const std::string& problem_name, Method method, Evaluation what) {
  const Problem problem = loadProblem(problem_name);
  if (!methodCannotTake(problem, method).empty()) {
    state.SkipWithError("the method cannot take this problem");
    return;
  }
  const Transcription t(problem, method);
  std::mt19937 rng(2024);  // fixed seed: the same point every run
  std::uniform_real_distribution<double> u(0.0, 0.1);
  Eigen::VectorXd x = t.nullSeed();
  for (int i = 0; i < x.size(); ++i) x[i] += u(rng);
  Nlp nlp(t, Stage::Feasibility, x);
  Ipopt::Index n = 0, m = 0, nnz_jac = 0, nnz_h = 0;
  Ipopt::TNLP::IndexStyleEnum style;
  nlp.get_nlp_info(n, m, nnz_jac, nnz_h, style);
  std::vector<double> g(m), values(std::max(nnz_jac, nnz_h)), lambda(m);
  for (double& l : lambda) l = u(rng);
  for (auto _ : state) {
    switch (what) {
      case Evaluation::Constraints: nlp.eval_g(n, x.data(), true, m, g.data()); break;
      case Evaluation::Jacobian: nlp.eval_jac_g(n, x.data(), true, m, nnz_jac, nullptr, nullptr, values.data()); break;
      case Evaluation::Hessian:
        nlp.eval_h(n, x.data(), true, 1.0, m, lambda.data(), true, nnz_h, nullptr, nullptr, values.data());
        break;
    }
    benchmark::DoNotOptimize(values.data());
    benchmark::DoNotOptimize(g.data());
  }
  state.counters["variables"] = n;
  state.counters["jacobian_entries"] = nnz_jac;
  state.counters["hessian_entries"] = nnz_h;
}

#define SALTUS_EVALUATE(problem, method, what) \
  BENCHMARK_CAPTURE(BM_Evaluate, problem##_##method##_##what, #problem, Method::method, Evaluation::what) \
      ->Unit(benchmark::kMicrosecond)
#define SALTUS_EVALUATE_ALL(problem, method)    \
  SALTUS_EVALUATE(problem, method, Constraints); \
  SALTUS_EVALUATE(problem, method, Jacobian);    \
  SALTUS_EVALUATE(problem, method, Hessian)

SALTUS_EVALUATE_ALL(pendulum_conveyor, Impulsive);
SALTUS_EVALUATE_ALL(pendulum_conveyor, FirstOrder);
SALTUS_EVALUATE_ALL(point_mass_throw, Impulsive);
SALTUS_EVALUATE_ALL(point_mass_throw, Continuous);
SALTUS_EVALUATE_ALL(biped_stop, Impulsive);
SALTUS_EVALUATE_ALL(ollie_simple, Impulsive);
SALTUS_EVALUATE_ALL(ollie, Impulsive);

}  // namespace
