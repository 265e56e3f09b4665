#include "sweep/spec.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <limits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "collocation/problem_file.hpp"
#include "collocation/transcription.hpp"
#include "scene/yaml_reader.hpp"
#include "verify/replay.hpp"

namespace saltus::sweep {

namespace fs = std::filesystem;
using scene::YamlReader;

std::string formatValue(double x) {
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(x);
}

namespace {

// A grid `{name: [values] | value}`: every parameter name an identifier, every value finite.
std::map<std::string, std::vector<double>> readGrid(YamlReader& r, const YAML::Node& n, const std::string& path) {
  std::map<std::string, std::vector<double>> grid;
  r.checkNameMap(n, path);
  if (n.IsNull()) return grid;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::string name = it->first.Scalar();
    const std::string at = scene::keyPath(path, name);
    if (!scene::isIdentifier(name)) r.fail(it->first, at, "expected a parameter name (letters, digits, _)");
    std::vector<double> values;
    if (it->second.IsSequence()) {
      if (it->second.size() == 0) r.fail(it->second, at, "expected at least one value");
      for (std::size_t i = 0; i < it->second.size(); ++i)
        values.push_back(r.number(it->second[i], scene::indexPath(at, i)));
    } else {
      values.push_back(r.number(it->second, at));
    }
    std::set<double> seen;
    for (double v : values)
      if (!seen.insert(v).second) r.fail(it->second, at, "the value " + formatValue(v) + " is listed twice");
    grid[name] = values;
  }
  return grid;
}

int positiveInteger(YamlReader& r, const YAML::Node& n, const std::string& path, int minimum) {
  const int k = r.integer(n, path);
  if (k < minimum) r.fail(n, path, "expected an integer ≥ " + std::to_string(minimum) + ", got " + std::to_string(k));
  return k;
}

// A path given in the spec, relative to the spec's folder.
std::string resolvePath(const std::string& path, const std::string& spec_file) {
  if (fs::path(path).is_absolute() || spec_file.empty()) return path;
  return (fs::path(spec_file).parent_path() / path).lexically_normal().string();
}

// The options at `where` ("options", or "variants.NAME": what a variant changes) into o: each key
// given replaces o's, and ipopt and task_ipopt entries are added to o's.
void readOptions(YamlReader& r, const YAML::Node& n, SolveSettings& o, const std::string& where) {
  const std::string prefix = where + ".";
  r.checkMap(n, where, {"N", "P", "restarts", "resimulations", "resimulation_tracking", "seed", "seed_from", "seed_scale", "hints", "continuation", "tighten_within", "tighten_factor", "feasibility_repeats", "task_max_iter", "penalty_iterations", "task_penalty", "hessian", "feasibility_hessian", "ipopt", "task_ipopt"},
             true);
  if (n.IsNull()) return;
  if (n["N"]) o.N = positiveInteger(r, n["N"], prefix + "N", 1);
  if (n["P"]) {
    o.P = positiveInteger(r, n["P"], prefix + "P", 1);
    if (*o.P > 9) r.fail(n["P"], prefix + "P", "expected an order from 1 to 9, got " + std::to_string(*o.P));
  }
  if (n["restarts"]) o.restarts = positiveInteger(r, n["restarts"], prefix + "restarts", 0);
  if (n["feasibility_repeats"])
    o.feasibility_repeats = positiveInteger(r, n["feasibility_repeats"], prefix + "feasibility_repeats", 0);
  if (n["resimulations"]) o.resimulations = positiveInteger(r, n["resimulations"], prefix + "resimulations", 0);
  if (n["resimulation_tracking"]) {
    o.resimulation_tracking = r.number(n["resimulation_tracking"], prefix + "resimulation_tracking");
    if (!(*o.resimulation_tracking >= 0))
      r.fail(n["resimulation_tracking"], prefix + "resimulation_tracking",
             "expected a natural frequency >= 0 rad/s (0: open loop)");
  }
  if (n["hints"]) o.hints = r.boolean(n["hints"], prefix + "hints");
  if (n["continuation"]) o.continuation = r.boolean(n["continuation"], prefix + "continuation");
  if (n["seed_scale"]) {
    o.seed_scale = r.number(n["seed_scale"], prefix + "seed_scale");
    if (*o.seed_scale < 0) r.fail(n["seed_scale"], prefix + "seed_scale", "expected a non-negative number");
  }
  if (n["tighten_within"]) {
    o.tighten_within = r.number(n["tighten_within"], prefix + "tighten_within");
    if (!(*o.tighten_within >= 0))
      r.fail(n["tighten_within"], prefix + "tighten_within", "expected a non-negative ratio (0: never tighten)");
  }
  if (n["tighten_factor"]) {
    o.tighten_factor = r.number(n["tighten_factor"], prefix + "tighten_factor");
    if (!(*o.tighten_factor >= 0) || !std::isfinite(*o.tighten_factor))
      r.fail(n["tighten_factor"], prefix + "tighten_factor", "expected a finite non-negative factor (at most 1: one step)");
  }
  if (n["task_max_iter"]) o.task_max_iter = positiveInteger(r, n["task_max_iter"], prefix + "task_max_iter", 0);
  if (n["task_penalty"]) o.task_penalty = r.boolean(n["task_penalty"], prefix + "task_penalty");
  if (n["penalty_iterations"])
    o.penalty_iterations = positiveInteger(r, n["penalty_iterations"], prefix + "penalty_iterations", 0);
  if (n["seed"]) {
    // A bare `null` is YAML's empty value: the null seed, as in a problem file's solve.seed.
    o.seed_kind = n["seed"].IsNull() ? "null" : r.text(n["seed"], prefix + "seed");
    try {
      if (collocation::parseSeedKind(o.seed_kind) == collocation::SeedKind::Solution)
        r.fail(n["seed"], prefix + "seed", "a solution seed is not for a sweep; expected null, perturbed, simulation or perturbed-simulation");
    } catch (const std::invalid_argument& e) {
      r.fail(n["seed"], prefix + "seed", e.what());
    }
  }
  if (n["seed_from"]) {
    const std::string given = r.text(n["seed_from"], prefix + "seed_from");
    o.seed_from = resolvePath(given, r.file());
    if (!fs::exists(o.seed_from))
      r.fail(n["seed_from"], prefix + "seed_from",
             "no earlier solution at '" + o.seed_from + "' (expected the folder saltus optimize --out wrote, relative to the spec)");
    if (n["seed"])
      r.fail(n["seed_from"], prefix + "seed_from", "not with " + prefix + "seed: the seed is the earlier solution, perturbed by seed_scale");
  }
  for (const auto& [key, value] : {std::pair{"hessian", &o.hessian}, {"feasibility_hessian", &o.feasibility_hessian}}) {
    if (!n[key]) continue;
    const std::string at = prefix + key;
    *value = r.text(n[key], at);
    if (*value != "exact" && *value != "limited-memory")
      r.fail(n[key], at, "expected exact or limited-memory, got '" + *value + "'");
  }
  for (const auto& [key, options] : {std::pair{"ipopt", &o.ipopt}, {"task_ipopt", &o.task_ipopt}}) {
    if (!n[key]) continue;
    const std::string at = prefix + key;
    r.checkNameMap(n[key], at);
    for (auto it = n[key].begin(); it != n[key].end(); ++it) {
      const std::string name_at = scene::keyPath(at, it->first.Scalar());
      if (!it->second.IsScalar()) r.fail(it->second, name_at, "expected a number or a name, got " + scene::describe(it->second));
      (*options)[it->first.Scalar()] = it->second.Scalar();
    }
  }
}

void readReplay(YamlReader& r, const YAML::Node& n, ReplayCheck& c) {
  if (n.IsScalar() && (n.Scalar() == "false" || n.Scalar() == "true")) {
    c.enabled = r.boolean(n, "replay");
    return;
  }
  r.checkMap(n, "replay", {"dt", "tolerance", "restart"});
  if (n["dt"]) {
    c.dt = r.number(n["dt"], "replay.dt");
    if (!(c.dt > 0)) r.fail(n["dt"], "replay.dt", "expected a positive step [s]");
  }
  if (n["tolerance"]) {
    c.tolerance = r.number(n["tolerance"], "replay.tolerance");
    if (!(c.tolerance >= 0)) r.fail(n["tolerance"], "replay.tolerance", "expected a non-negative deviation [m or rad]");
  }
  if (n["restart"]) {
    const std::string restart = r.text(n["restart"], "replay.restart");
    try {
      c.restart = verify::parseRestart(restart);
    } catch (const std::invalid_argument& e) {
      r.fail(n["restart"], "replay.restart", e.what());
    }
  }
}

// A problem is a built-in name or a path (a '/' in it, or a YAML file's extension).
std::string resolveProblem(const std::string& name, const std::string& spec_file) {
  const bool is_path = name.find('/') != std::string::npos || name.ends_with(".yaml") || name.ends_with(".yml");
  return is_path ? resolvePath(name, spec_file) : name;
}

// Characters safe in a directory name; others become '_'.
std::string sanitise(const std::string& s) {
  std::string out;
  for (char ch : s) out += std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.' || ch == '=' ? ch : '_';
  return out;
}

}  // namespace

SweepSpec parseSweepSpec(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1)
      throw scene::ScenarioError(scene::location(file, documents[1].Mark()) +
                                 ": a sweep spec is one YAML document; found a second one");
    if (!documents.empty()) root = documents.front();
  } catch (const YAML::ParserException& e) {
    throw scene::ScenarioError(scene::location(file, e.mark) + ": YAML syntax error: " + e.msg);
  }
  YamlReader r(file, {});
  if (!root.IsMap()) r.fail(root, "", "a sweep spec must be a map of keys (problems, methods, set, seeds, options), got " +
                                          scene::describe(root));
  r.checkMap(root, "", {"problems", "methods", "set", "seeds", "options", "variants", "replay", "success"});
  SweepSpec spec;
  spec.file = file;

  const YAML::Node problems = r.required(root, "", "problems");
  r.checkSequence(problems, "problems");
  if (problems.size() == 0) r.fail(problems, "problems", "expected at least one problem");
  for (std::size_t i = 0; i < problems.size(); ++i) {
    const std::string at = scene::indexPath("problems", i);
    const YAML::Node p = problems[i];
    ProblemEntry entry;
    if (p.IsMap()) {
      r.checkMap(p, at, {"problem", "set"});
      entry.problem = resolveProblem(r.text(r.required(p, at, "problem"), at + ".problem"), file);
      if (p["set"]) entry.set = readGrid(r, p["set"], at + ".set");
    } else {
      entry.problem = resolveProblem(r.text(p, at), file);
    }
    spec.problems.push_back(entry);
  }

  const YAML::Node methods = r.required(root, "", "methods");
  r.checkSequence(methods, "methods");
  if (methods.size() == 0) r.fail(methods, "methods", "expected at least one method");
  for (std::size_t i = 0; i < methods.size(); ++i) {
    const std::string at = scene::indexPath("methods", i), m = r.text(methods[i], at);
    try {
      splitMethod(m);
    } catch (const std::invalid_argument& e) {
      r.fail(methods[i], at, e.what());
    }
    if (std::find(spec.methods.begin(), spec.methods.end(), m) != spec.methods.end())
      r.fail(methods[i], at, "the method " + m + " is listed twice");
    spec.methods.push_back(m);
  }

  if (root["set"]) spec.set = readGrid(r, root["set"], "set");

  const YAML::Node seeds = r.required(root, "", "seeds");
  if (seeds.IsSequence()) {
    if (seeds.size() == 0) r.fail(seeds, "seeds", "expected at least one seed");
    for (std::size_t i = 0; i < seeds.size(); ++i)
      spec.seeds.push_back(static_cast<unsigned>(positiveInteger(r, seeds[i], scene::indexPath("seeds", i), 0)));
  } else if (seeds.IsMap()) {
    r.checkMap(seeds, "seeds", {"from", "count"});
    const int from = positiveInteger(r, r.required(seeds, "seeds", "from"), "seeds.from", 0);
    const int count = positiveInteger(r, r.required(seeds, "seeds", "count"), "seeds.count", 1);
    if (count > 100000 || from > std::numeric_limits<int>::max() - count)
      r.fail(seeds, "seeds", "expected at most 100000 seeds below " + std::to_string(std::numeric_limits<int>::max()));
    for (int k = 0; k < count; ++k) spec.seeds.push_back(static_cast<unsigned>(from + k));
  } else {
    r.fail(seeds, "seeds", "expected a list of seeds or {from: S, count: K}, got " + scene::describe(seeds));
  }
  std::set<unsigned> unique(spec.seeds.begin(), spec.seeds.end());
  if (unique.size() != spec.seeds.size()) r.fail(seeds, "seeds", "a seed is listed twice");

  if (root["options"]) readOptions(r, root["options"], spec.options, "options");
  if (root["variants"]) {
    const YAML::Node variants = root["variants"];
    r.checkNameMap(variants, "variants");
    if (!variants.IsMap() || variants.size() == 0)
      r.fail(variants, "variants",
             "expected a map of variant names to the options each changes, e.g. {baseline: {}, monotone: {ipopt: "
             "{mu_strategy: monotone}}}");
    for (auto it = variants.begin(); it != variants.end(); ++it) {
      const std::string name = it->first.Scalar(), at = scene::keyPath("variants", name);
      if (name.empty() || !std::all_of(name.begin(), name.end(), [](char ch) {
            return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
          }))
        r.fail(it->first, at, "expected a variant name (letters, digits, _ and -), got '" + name + "'");
      SolveSettings o = spec.options;
      readOptions(r, it->second, o, at);
      if (!o.seed_from.empty() && !o.seed_kind.empty())
        r.fail(it->second, at,
               "seed_from and seed are both in force (one from options): the seed is the earlier solution, perturbed "
               "by seed_scale");
      spec.variants.push_back({name, o});
    }
  }
  for (const auto& [variant, o] : spec.settings()) {
    if (o.seed_from.empty()) continue;
    for (std::size_t i = 0; i < spec.methods.size(); ++i)
      if (!splitMethod(spec.methods[i]).seed_method.empty())
        r.fail(methods[i], scene::indexPath("methods", i),
               "a two-step method is seeded by its first method's solution, not by " +
                   (variant.empty() ? std::string("options") : "variants." + variant) + ".seed_from");
  }
  if (root["replay"]) readReplay(r, root["replay"], spec.replay);
  if (root["success"]) {
    const std::string rule = r.text(root["success"], "success");
    if (rule != "physical" && rule != "feasible")
      r.fail(root["success"], "success", "expected physical (feasible and its replay within tolerance) or feasible, got '" + rule + "'");
    if (rule == "physical" && !spec.replay.enabled)
      r.fail(root["success"], "success", "physical needs the replay check, which replay: false turns off");
    spec.physical_success = rule == "physical";
  }
  return spec;
}

SweepSpec readSweepSpec(const std::string& path) {
  if (!fs::is_regular_file(path)) throw scene::ScenarioError(path + ": cannot open the sweep spec: no such file");
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw scene::ScenarioError(path + ": cannot read the sweep spec");
  return parseSweepSpec(text.str(), path);
}

MethodLabel splitMethod(const std::string& label) {
  auto known = [](const std::string& name) {
    try {
      collocation::parseMethod(name);
      return true;
    } catch (const std::invalid_argument&) {
      return false;
    }
  };
  MethodLabel m;
  const std::size_t from = label.find(" from ");
  m.method = label.substr(0, from);
  if (from != std::string::npos) m.seed_method = label.substr(from + 6);
  if (!known(m.method) || (from != std::string::npos && !known(m.seed_method)))
    throw std::invalid_argument("expected impulsive, continuous or first-order, or 'M from S' (M solved from S's "
                                "solution), got '" + label + "'");
  if (m.seed_method == m.method) throw std::invalid_argument("'" + label + "': a method cannot seed itself");
  return m;
}

std::vector<std::pair<std::string, SolveSettings>> SweepSpec::settings() const {
  if (variants.empty()) return {{"", options}};
  return variants;
}

std::string SweepCase::cell() const {
  std::string s = problem_name + " " + method;
  for (const auto& [name, value] : set) s += " " + name + "=" + formatValue(value);
  if (!variant.empty()) s += " [" + variant + "]";
  return s;
}

std::vector<std::string> SweepCase::optimizeArguments(const std::string& out) const {
  const SolveSettings& o = options;
  const MethodLabel m = splitMethod(method);
  std::vector<std::string> a = {"optimize", problem, "--method", m.method, "--seed", std::to_string(seed)};
  if (!m.seed_method.empty()) a.insert(a.end(), {"--seed-method", m.seed_method});
  for (const auto& [name, value] : set) a.insert(a.end(), {"--set", name + "=" + formatValue(value)});
  if (o.N) a.insert(a.end(), {"--N", std::to_string(*o.N)});
  if (o.P) a.insert(a.end(), {"--P", std::to_string(*o.P)});
  if (o.restarts) a.insert(a.end(), {"--restarts", std::to_string(*o.restarts)});
  if (o.resimulations) a.insert(a.end(), {"--resimulations", std::to_string(*o.resimulations)});
  if (o.resimulation_tracking)
    a.insert(a.end(), {"--resimulation-tracking", formatValue(*o.resimulation_tracking)});
  if (!o.seed_kind.empty()) a.insert(a.end(), {"--seed-kind", o.seed_kind});
  if (!o.seed_from.empty()) a.insert(a.end(), {"--seed-from", o.seed_from});
  if (!o.hints) a.push_back("--no-hints");
  if (!o.continuation) a.push_back("--no-continuation");
  if (o.seed_scale) a.insert(a.end(), {"--seed-scale", formatValue(*o.seed_scale)});
  if (o.tighten_within) a.insert(a.end(), {"--tighten-within", formatValue(*o.tighten_within)});
  if (o.tighten_factor) a.insert(a.end(), {"--tighten-factor", formatValue(*o.tighten_factor)});
  if (o.feasibility_repeats) a.insert(a.end(), {"--feasibility-repeats", std::to_string(*o.feasibility_repeats)});
  if (o.task_max_iter) a.insert(a.end(), {"--task-max-iter", std::to_string(*o.task_max_iter)});
  if (o.task_penalty) a.insert(a.end(), {"--task-penalty", *o.task_penalty ? "on" : "off"});
  if (o.penalty_iterations) a.insert(a.end(), {"--penalty-iterations", std::to_string(*o.penalty_iterations)});
  if (!o.hessian.empty()) a.insert(a.end(), {"--hessian", o.hessian});
  if (!o.feasibility_hessian.empty()) a.insert(a.end(), {"--feasibility-hessian", o.feasibility_hessian});
  for (const auto& [name, value] : o.ipopt) a.insert(a.end(), {"--ipopt", name + "=" + value});
  for (const auto& [name, value] : o.task_ipopt) a.insert(a.end(), {"--task-ipopt", name + "=" + value});
  a.insert(a.end(), {"--out", out});
  return a;
}

std::vector<SweepCase> expandSweep(const SweepSpec& spec, std::vector<SkippedCell>* skipped) {
  std::vector<SweepCase> cases;
  std::string first_reason;
  std::set<std::string> ids;
  for (std::size_t pi = 0; pi < spec.problems.size(); ++pi) {
    const ProblemEntry& entry = spec.problems[pi];
    const std::string where = spec.file + ": problems[" + std::to_string(pi) + "] (" + entry.problem + ")";
    // The problem's grid: the top-level one, then its own (its own wins on a shared name).
    std::map<std::string, std::vector<double>> grid = spec.set;
    for (const auto& [name, values] : entry.set) grid[name] = values;
    std::vector<std::map<std::string, double>> combinations(1);
    for (const auto& [name, values] : grid) {
      std::vector<std::map<std::string, double>> next;
      for (const auto& c : combinations)
        for (double v : values) {
          auto d = c;
          d[name] = v;
          next.push_back(d);
        }
      combinations = next;
    }
    const auto variants = spec.settings();
    for (const auto& values : combinations) {
      // The problem as each variant meshes it (options N and P).
      std::vector<collocation::Problem> meshed;
      collocation::Problem problem;
      std::string set;
      for (const auto& [name, value] : values) set += (set.empty() ? "" : ", ") + name + "=" + formatValue(value);
      for (const auto& [variant, o] : variants) {
        try {
          if (meshed.empty()) problem = collocation::loadProblem(entry.problem, values);
          meshed.push_back(problem);
          if (o.N || o.P) collocation::remesh(meshed.back(), o.N.value_or(problem.N), o.P.value_or(problem.P));
        } catch (const std::exception& e) {
          throw scene::ScenarioError(where + (set.empty() ? "" : " with " + set) +
                                     (variant.empty() || meshed.empty() ? "" : ", variant " + variant) + ": " + e.what());
        }
      }
      for (const std::string& method : spec.methods) {
        const MethodLabel label = splitMethod(method);
        std::string why = collocation::methodCannotTake(problem, collocation::parseMethod(label.method));
        if (why.empty() && !label.seed_method.empty())
          why = collocation::methodCannotTake(problem, collocation::parseMethod(label.seed_method));
        if (!why.empty()) {
          if (first_reason.empty()) first_reason = where + ", method " + method + ": " + why;
          if (skipped) skipped->push_back({problem.name, method, values, why});
          continue;
        }
        std::set<std::pair<int, int>> transcribed;  // meshes (N, P) this method was checked on
        for (std::size_t v = 0; v < variants.size(); ++v) {
          const std::string& variant = variants[v].first;
          if (transcribed.insert({meshed[v].N, meshed[v].P}).second) {
            try {
              const collocation::Transcription check(meshed[v], collocation::parseMethod(label.method));
            } catch (const std::invalid_argument& e) {
              throw scene::ScenarioError(where + ", method " + method + (variant.empty() ? "" : ", variant " + variant) +
                                         ": " + e.what());
            }
          }
          for (unsigned seed : spec.seeds) {
            SweepCase c;
            c.problem = entry.problem;
            c.problem_name = problem.name;
            c.method = method;
            c.set = values;
            c.variant = variant;
            c.options = variants[v].second;
            c.seed = seed;
            c.physical_required = spec.physical_success;
            c.id = sanitise(problem.name) + "__" + sanitise(method);
            for (const auto& [name, value] : values) c.id += "__" + sanitise(name + "=" + formatValue(value));
            if (!variant.empty()) c.id += "__variant=" + variant;
            c.id += "__seed=" + std::to_string(seed);
            if (!ids.insert(c.id).second)
              throw scene::ScenarioError(where + ": the solve " + c.id +
                                         " is in the grid twice (two entries of problem '" + problem.name +
                                         "' with the same parameter values)");
            cases.push_back(c);
          }
        }
      }
    }
  }
  if (cases.empty() && !first_reason.empty())
    throw scene::ScenarioError(first_reason + " (and no other solve is left in the grid)");
  return cases;
}

}  // namespace saltus::sweep
