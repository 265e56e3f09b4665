#include "collocation/seeding.hpp"

#include <memory>
#include <optional>
#include <stdexcept>

#include "collocation/input_schedule.hpp"
#include "collocation/saved_solution.hpp"

namespace saltus::collocation {

Seeding makeSeeding(const Transcription& t) {
  const Problem& p = t.problem();
  Seeding s;
  auto base = std::make_shared<Eigen::VectorXd>();
  SeedKind kind = p.seed_kind;
  const bool simulation = kind == SeedKind::Simulation || kind == SeedKind::PerturbedSimulation;
  // The schedule is read before the simulation: a bad file is an error, not a fallback.
  std::optional<InputSchedule> schedule;
  if (!p.seed_inputs.empty()) {
    const std::string where = p.seed_inputs_origin.empty() ? "" : p.seed_inputs_origin + ": ";
    if (!simulation)
      throw std::invalid_argument(where + "an input schedule drives a simulation seed (simulation or "
                                  "perturbed-simulation); the seed is '" + std::string(toString(kind)) + "'");
    try {
      schedule = readInputSchedule(p.seed_inputs, p);
    } catch (const InputScheduleError& e) {
      throw InputScheduleError(where + e.what());
    }
  }
  switch (p.seed_kind) {
    case SeedKind::Simulation:
    case SeedKind::PerturbedSimulation:
      try {
        *base = seedFromSimulation(t, &s.simulation, schedule ? &*schedule : nullptr);
      } catch (const std::runtime_error& e) {
        s.fallback = std::string(e.what()) + "; started from the null seed";
        *base = t.nullSeed();
        kind = p.seed_kind == SeedKind::Simulation ? SeedKind::Null : SeedKind::Perturbed;
      }
      break;
    case SeedKind::Solution: {
      SavedSolution earlier;
      try {
        earlier = loadSolution(p.seed_solution);
      } catch (const SolutionError& e) {
        if (p.seed_solution_origin.empty()) throw;
        throw SolutionError(p.seed_solution_origin + ": " + e.what());
      }
      *base = seedFromSolution(t, earlier);
      break;
    }
    case SeedKind::Null:
    case SeedKind::Perturbed: *base = t.nullSeed(); break;
  }
  const double scale = p.seed_scale;
  const unsigned random_seed = p.random_seed;
  s.seed = [&t, base, kind, scale, random_seed](int k) -> Seed {
    const bool exact_first = kind == SeedKind::Null || kind == SeedKind::Simulation;
    if ((exact_first && k == 0) || scale <= 0)
      return {*base, kind == SeedKind::Simulation || kind == SeedKind::Solution};
    return {t.perturb(*base, scale, random_seed + static_cast<unsigned>(k)), kind == SeedKind::Solution};
  };
  s.restarts = scale > 0 ? p.restarts : 0;  // without a perturbation every attempt is the same
  return s;
}

}  // namespace saltus::collocation
