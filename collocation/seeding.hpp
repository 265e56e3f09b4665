// The starting points of a solve with restarts, by the problem's seed kind (Problem::seed_kind):
//   simulation  the time-stepper's motion on a mesh placed on its events (simulation_seed.hpp),
//               the default
//   null        zero except where bounds impose (the initial state at [1, 0]); h mid-bounds
//   perturbed   the null point plus uniform random values in [0, seed_scale] on the positions and
//               normal reactions (paper §V.C)
//   perturbed-simulation  the simulation seed plus the same random values: robustness near it,
//               one point per random seed
//   solution    an earlier solution (saved_solution.hpp), perturbed by seed_scale
// Attempt 0 starts from that point (perturbed for `perturbed`, `perturbed-simulation` and `solution`, with
// random_seed);
// attempt k ≥ 1, after an infeasible end, from it perturbed with random_seed + k. A simulation
// seed (in attempt 0) and an earlier solution (perturbed or not, in every attempt) are near a
// solution (Seed::warm): Ipopt starts with a small barrier parameter. From a perturbed Ollie
// solution (scale 0.01 and 0.1) the cold start (μ₀ = 0.1) walked away from the contact sequence
// and failed; the warm one came back to it (README, "The Ollie").
#pragma once

#include <string>

#include "collocation/simulation_seed.hpp"
#include "collocation/solver.hpp"

namespace saltus::collocation {

struct Seeding {
  SeedFunction seed;
  int restarts = 0;  // further attempts: the problem's, or 0 when no perturbation would change the point
  SimulationSeedReport simulation;  // a simulation seed's events and mesh
  // Set when the simulation failed (a time-stepper error) and the null seed was used instead.
  std::string fallback;
};

// Builds the base point now (a simulation seed runs the time-stepper; a solution seed reads its
// files, so SolutionError and scene::ScenarioError pass through); the returned function refers
// to `t`.
Seeding makeSeeding(const Transcription& t);

}  // namespace saltus::collocation
