// The `solve`, `ipopt` and `task_ipopt` sections of a problem file: how the problem is solved
// (stages, seeds, Hessians, the penalty form, each method's own penalty keys, Ipopt's options).
// The format is models/problems/README.md's; the rest of the reader is problem_file.cpp.
#include <filesystem>
#include <string>
#include <tuple>

#include "collocation/problem_reader.hpp"
#include "collocation/solver.hpp"
#include "scene/scenario.hpp"

namespace saltus::collocation::detail {

namespace fs = std::filesystem;
using scene::describe;
using scene::fmt;
using scene::joinNames;
using scene::keyPath;
using scene::suggestion;

void ProblemReader::readSolve(const YAML::Node& node) {
  if (!node.IsDefined()) return;
  r_.checkMap(node, "solve",
              {"complementarity_tolerance", "task_stage", "seed", "seed_scale", "random_seed", "seed_solution",
               "seed_inputs", "restarts", "resimulations", "resimulation_tracking", "hessian", "feasibility_hessian", "derivative_check", "penalty_iterations", "task_penalty",
               "continuation", "impulsive", "continuous", "first-order"},
              true);
  if (node.IsNull()) return;
  p_.complementarity_tolerance = r_.number(node, "solve", "complementarity_tolerance", p_.complementarity_tolerance);
  if (!(p_.complementarity_tolerance > 0))
    r_.fail(node["complementarity_tolerance"], "solve.complementarity_tolerance",
            "the tolerance must be positive, got " + fmt(p_.complementarity_tolerance));
  if (node["task_stage"].IsDefined()) p_.task_stage = r_.boolean(node["task_stage"], "solve.task_stage");
  if (const YAML::Node s = node["seed"]; s.IsDefined()) {
    try {
      p_.seed_kind = parseSeedKind(s.IsNull() ? "null" : r_.text(s, "solve.seed"));
    } catch (const std::invalid_argument& e) {
      r_.fail(s, "solve.seed", e.what());
    }
  }
  p_.seed_scale = r_.number(node, "solve", "seed_scale", p_.seed_scale);
  if (!(p_.seed_scale >= 0))
    r_.fail(node["seed_scale"], "solve.seed_scale", "the seed scale must be non-negative, got " + fmt(p_.seed_scale));
  if (const YAML::Node s = node["random_seed"]; s.IsDefined()) {
    const int seed = r_.integer(s, "solve.random_seed");
    if (seed < 0) r_.fail(s, "solve.random_seed", "expected a non-negative integer, got " + std::to_string(seed));
    p_.random_seed = static_cast<unsigned>(seed);
  }
  if (const YAML::Node s = node["restarts"]; s.IsDefined()) {
    p_.restarts = r_.integer(s, "solve.restarts");
    if (p_.restarts < 0) r_.fail(s, "solve.restarts", "expected a non-negative integer, got " + std::to_string(p_.restarts));
  }
  if (const YAML::Node s = node["resimulations"]; s.IsDefined()) {
    p_.resimulations = r_.integer(s, "solve.resimulations");
    if (p_.resimulations < 0)
      r_.fail(s, "solve.resimulations", "expected a non-negative integer, got " + std::to_string(p_.resimulations));
  }
  p_.resimulation_tracking = r_.number(node, "solve", "resimulation_tracking", p_.resimulation_tracking);
  if (!(p_.resimulation_tracking >= 0))
    r_.fail(node["resimulation_tracking"], "solve.resimulation_tracking",
            "expected a natural frequency >= 0 rad/s (0: open loop), got " + fmt(p_.resimulation_tracking));
  // A file named relative to the problem file, and where it was given.
  for (auto [key, path, where] : {std::tuple{"seed_solution", &p_.seed_solution, &p_.seed_solution_origin},
                                  std::tuple{"seed_inputs", &p_.seed_inputs, &p_.seed_inputs_origin}}) {
    const YAML::Node s = node[key];
    if (!s.IsDefined()) continue;
    const std::string name = std::string("solve.") + key;
    fs::path file = r_.text(s, name);
    if (file.is_relative()) file = fs::path(r_.file()).parent_path() / file;
    *path = file.lexically_normal().string();
    *where = origin(s) + ": " + name;
  }
  if (p_.seed_kind == SeedKind::Solution && p_.seed_solution.empty())
    r_.fail(node, "solve.seed_solution",
            "seed: solution needs seed_solution: the directory (or trajectory.csv) of an earlier solution, relative "
            "to the problem file");
  // continuation: a list of steps, each a map of parameter values (loadProblem reads each step's
  // problem); a value may be an expression of the parameters in use.
  if (const YAML::Node c = node["continuation"]; c.IsDefined()) {
    r_.checkSequence(c, "solve.continuation");
    for (std::size_t i = 0; i < c.size(); ++i) {
      const std::string at = "solve.continuation[" + std::to_string(i) + "]";
      const YAML::Node step = c[i];
      r_.checkNameMap(step, at);
      if (step.IsNull() || step.size() == 0)
        r_.fail(step, at, "a step changes at least one parameter, e.g. {g: 4.905}");
      ContinuationStep s;
      for (auto it = step.begin(); it != step.end(); ++it) {
        const std::string name = it->first.Scalar();
        if (!p_.parameters.count(name)) {
          std::vector<std::string> known;
          for (const auto& [k, v] : p_.parameters) known.push_back(k);
          r_.fail(it->first, at + "." + name,
                  "no parameter '" + name + "'" + suggestion(name, known) + "; the parameters are: " + joinNames(known));
        }
        s.parameters[name] = r_.number(it->second, at + "." + name);
      }
      p_.continuation.push_back(std::move(s));
    }
  }
  // hessian: every stage's; feasibility_hessian: the feasibility and tightening stages'.
  for (const char* key : {"hessian", "feasibility_hessian"}) {
    const YAML::Node h = node[key];
    if (!h.IsDefined()) continue;
    const std::string where = std::string("solve.") + key;
    const std::string kind = r_.text(h, where);
    if (kind != "exact" && kind != "limited-memory")
      r_.fail(h, where, "unknown hessian '" + kind + "'" + suggestion(kind, {"exact", "limited-memory"}) +
                            "; expected one of: exact, limited-memory");
    if (std::string(key) == "hessian") p_.exact_hessian = kind == "exact";
    p_.feasibility_exact_hessian = kind == "exact";
  }
  if (node["derivative_check"].IsDefined())
    p_.derivative_check = r_.boolean(node["derivative_check"], "solve.derivative_check");
  // The penalty keys for every method, then a method's own (solve.<method>).
  Problem::MethodSolve every;
  readPenaltyKeys(node, "solve", every);
  if (every.penalty_iterations) p_.penalty_iterations = *every.penalty_iterations;
  if (every.task_penalty) p_.task_penalty = *every.task_penalty;
  for (const Method m : {Method::Impulsive, Method::Continuous, Method::FirstOrder}) {
    const YAML::Node s = node[toString(m)];
    if (!s.IsDefined()) continue;
    const std::string at = std::string("solve.") + toString(m);
    r_.checkMap(s, at, {"penalty_iterations", "task_penalty", "penalty_weight"}, true);
    if (s.IsNull()) continue;
    Problem::MethodSolve& own = p_.method_solve[m];
    readPenaltyKeys(s, at, own);
    if (const YAML::Node w = s["penalty_weight"]; w.IsDefined()) {  // cost.penalty_weight's, for this method
      own.penalty_weight = r_.number(w, at + ".penalty_weight");
      if (!(*own.penalty_weight >= 0))
        r_.fail(w, at + ".penalty_weight", "a weight must be non-negative, got " + fmt(*own.penalty_weight));
    }
  }
}

void ProblemReader::readPenaltyKeys(const YAML::Node& node, const std::string& at, Problem::MethodSolve& into) {
  if (const YAML::Node s = node["task_penalty"]; s.IsDefined()) into.task_penalty = r_.boolean(s, at + ".task_penalty");
  if (const YAML::Node s = node["penalty_iterations"]; s.IsDefined()) {
    const int n = r_.integer(s, at + ".penalty_iterations");
    if (n < 0)
      r_.fail(s, at + ".penalty_iterations",
              "expected a non-negative iteration count (0: no penalty stage), got " + std::to_string(n));
    into.penalty_iterations = n;
  }
}

void ProblemReader::readIpopt(const YAML::Node& node, const std::string& key,
                              std::map<std::string, std::string>& options) {
  if (!node.IsDefined()) return;
  r_.checkNameMap(node, key);
  if (node.IsNull()) return;
  const std::map<std::string, std::string> owned = {{"hessian_approximation", "solve.hessian"},
                                                    {"derivative_test", "solve.derivative_check"}};
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string name = it->first.Scalar(), path = keyPath(key, name);
    if (const auto o = owned.find(name); o != owned.end())
      r_.fail(it->first, path, "set this through " + o->second + " instead");
    if (!it->second.IsScalar())
      r_.fail(it->second, path, "expected the option's value (a number or a word), got " + describe(it->second));
    try {
      checkIpoptOption(name, it->second.Scalar());
    } catch (const IpoptOptionError& e) {
      r_.fail(it->first, path, e.what());
    }
    options[name] = it->second.Scalar();
  }
}

}  // namespace saltus::collocation::detail
