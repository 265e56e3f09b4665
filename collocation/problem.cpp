#include "collocation/problem.hpp"

#include <stdexcept>

#include "scene/yaml_reader.hpp"

namespace saltus::collocation {

const char* toString(Method m) {
  switch (m) {
    case Method::Impulsive: return "impulsive";
    case Method::Continuous: return "continuous";
    case Method::FirstOrder: return "first-order";
  }
  return "unknown";
}

Method parseMethod(const std::string& name) {
  const std::vector<std::string> names = {"impulsive", "continuous", "first-order"};
  for (Method m : {Method::Impulsive, Method::Continuous, Method::FirstOrder})
    if (name == toString(m)) return m;
  throw std::invalid_argument("unknown method '" + name + "'" + scene::suggestion(name, names) +
                              "; expected one of: " + scene::joinNames(names));
}

scene::Scene sceneAtMeshTimes(const Problem& problem, const std::vector<double>& element_start) {
  scene::Scene scene = problem.scene;
  for (const auto& [surface, steps] : problem.surface_steps) {
    std::vector<scene::Surface::Step>& schedule = scene.surfaces.at(surface).velocity_schedule;
    schedule.clear();
    for (const SurfaceStep& s : steps) schedule.push_back({element_start.at(static_cast<std::size_t>(s.element)), s.velocity});
  }
  return scene;
}

const char* toString(SeedKind k) {
  switch (k) {
    case SeedKind::Null: return "null";
    case SeedKind::Perturbed: return "perturbed";
    case SeedKind::Solution: return "solution";
    case SeedKind::Simulation: return "simulation";
    case SeedKind::PerturbedSimulation: return "perturbed-simulation";
  }
  return "unknown";
}

SeedKind parseSeedKind(const std::string& name) {
  const std::vector<SeedKind> kinds = {SeedKind::Null, SeedKind::Perturbed, SeedKind::Solution, SeedKind::Simulation,
                                       SeedKind::PerturbedSimulation};
  std::vector<std::string> names;
  for (SeedKind k : kinds) {
    if (name == toString(k)) return k;
    names.emplace_back(toString(k));
  }
  throw std::invalid_argument("unknown seed '" + name + "'" + scene::suggestion(name, names) +
                              "; expected one of: " + scene::joinNames(names));
}

void remesh(Problem& p, int N, int P) {
  if (N < 1) throw std::invalid_argument("N: expected at least 1 element, got " + std::to_string(N));
  if (P < 1) throw std::invalid_argument("P: expected at least 1 collocation point, got " + std::to_string(P));
  auto fix = [&](std::vector<PointBound>& list) {
    for (PointBound& b : list) {
      if (b.element == p.N - 1 && b.point == p.P + 1) {
        b.element = N - 1;
        b.point = P + 1;
      } else if (b.element >= N || b.point > P + 1) {
        throw std::invalid_argument("the condition given at " + b.origin + " lies outside the new mesh (N = " +
                                    std::to_string(N) + ", P = " + std::to_string(P) + ")");
      }
    }
  };
  fix(p.bounds);
  fix(p.hints);
  for (const auto& [surface, steps] : p.surface_steps)
    for (const SurfaceStep& step : steps)
      if (step.element >= N)
        throw std::invalid_argument("surface '" + p.scene.surfaces.at(surface).name + "' steps its velocity at element " +
                                    std::to_string(step.element + 1) + ", outside the new mesh (N = " + std::to_string(N) + ")");
  p.N = N;
  p.P = P;
}

}  // namespace saltus::collocation
