// Problems and points shared by the transcription's and the NLP's tests: the legged benchmarks
// cut down to a few elements, and random points near a transcription's seed.
#pragma once

#include <Eigen/Core>

#include <random>
#include <string>
#include <vector>

#include "collocation/problem_file.hpp"
#include "collocation/transcription.hpp"

namespace saltus::testing {

// A random point near the seed: every variable moved by up to ±0.3 (h kept inside its bounds).
inline Eigen::VectorXd randomPoint(const collocation::Transcription& t, unsigned seed) {
  Eigen::VectorXd x = t.perturb(t.nullSeed(), 0.1, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  for (int i = 0; i < x.size(); ++i) x[i] += U(rng) * (t.variableNames()[i][0] == 'h' ? 0.01 : 1.0);
  return x;
}

// The legged benchmarks on N elements of two points: the planar biped (9 coordinates, two feet
// with friction, 12 joint-limit stops on a floating base, six bounded inputs, minimise_max) and the
// spatial monopod (a free Euler base, one foot with a k = 4 cone, stops on a floating base, effort).
inline collocation::Problem smallLegged(const std::string& name, int N = 2) {
  collocation::Problem p = collocation::loadProblem(name);
  // The monopod's first leg (y ≤ 0 through [13, 0], x = 2.5 there) does not fit a two-element
  // mesh whose end is the final condition x = y = 2.5: only the conditions at the end are kept.
  std::erase_if(p.bounds, [&](const collocation::PointBound& b) { return b.element >= 0 && b.element < p.N - 1; });
  collocation::remesh(p, N, 2);
  return p;
}

}  // namespace saltus::testing
