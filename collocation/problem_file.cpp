// Problem files (problem_file.hpp): the scene, the mesh, the inputs, the conditions and hints, the
// surface velocities and the cost. How the problem is solved (`solve`, `ipopt`, `task_ipopt`) is
// read in problem_file_solve.cpp; the reader both use is problem_reader.hpp.
#include "collocation/problem_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>

#include "collocation/problem_fingerprint.hpp"
#include "collocation/problem_reader.hpp"
#include "scene/scenario.hpp"
#include "scene/yaml_reader.hpp"

namespace saltus::collocation {

namespace fs = std::filesystem;
using scene::describe;
using scene::fmt;
using scene::indexPath;
using scene::joinNames;
using scene::keyPath;
using scene::suggestion;
using scene::YamlReader;

namespace {

// The scene keys a problem file shares with scenario files (`input` and `duration` are refused:
// see refuseSceneOnlyKeys), and the keys of the problem itself.
const std::vector<std::string> kSceneKeys = {"name",    "description", "parameters",   "model",
                                             "base",    "gravity",     "initial",      "surfaces",
                                             "contacts", "joint_limits", "limit_restitution"};
const std::vector<std::string> kProblemKeys = {"mesh",   "inputs", "initial_free",     "final",
                                               "bounds", "constraints", "hints", "surface_velocity",
                                               "cost",   "solve",  "ipopt",  "task_ipopt"};
const std::vector<std::string> kConditionKeys = {"q", "v", "u", "gap"};

bool isInfinity(const std::string& s, bool& negative) {
  static const std::set<std::string> pos = {".inf", ".Inf", ".INF", "+.inf", "+.Inf", "+.INF"};
  static const std::set<std::string> neg = {"-.inf", "-.Inf", "-.INF"};
  negative = neg.count(s) > 0;
  return negative || pos.count(s) > 0;
}

// `input` and `duration` are scenario keys with no meaning in a problem.
void refuseSceneOnlyKeys(const YamlReader& r, const YAML::Node& root) {
  if (root["input"].IsDefined())
    r.fail(YamlReader::keyMark(root, "input"), "input",
           "a problem has no constant input: list the actuated coordinates under `inputs` (the optimiser "
           "chooses their forces), with bounds there or under `bounds.u`");
  if (root["duration"].IsDefined())
    r.fail(YamlReader::keyMark(root, "duration"), "duration",
           "a problem has no fixed duration: the element lengths are variables; give the horizon with "
           "mesh.N, mesh.h_max and mesh.total_time ({at_least: T} or {equal: T})");
}

}  // namespace

namespace detail {

int ProblemReader::coordinate(const YAML::Node& name_node, const std::string& path) const {
  const std::string name = r_.text(name_node, path);
  const dynamics::Model<double>& model = p_.scene.model;
  const int i = model.coordinateIndex(name);
  if (i < 0)
    r_.fail(name_node, path, "unknown coordinate '" + name + "'" + suggestion(name, model.coordinate_name) +
                                 "; the model's coordinates are: " + joinNames(model.coordinate_name));
  return i;
}

int ProblemReader::input(const YAML::Node& name_node, const std::string& path) const {
  const std::string name = r_.text(name_node, path);
  std::vector<std::string> names;
  for (int i : p_.inputs) names.push_back(p_.scene.model.coordinate_name[i]);
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    const bool is_coordinate = p_.scene.model.coordinateIndex(name) >= 0;
    r_.fail(name_node, path,
            (is_coordinate ? "coordinate '" + name + "' is not actuated (list it under `inputs`)"
                           : "unknown input '" + name + "'" + suggestion(name, names)) +
                "; the inputs are: " + joinNames(names));
  }
  return static_cast<int>(it - names.begin());
}

int ProblemReader::gapIndex(const YAML::Node& name_node, const std::string& path) const {
  const std::string name = r_.text(name_node, path);
  std::vector<std::string> names;
  for (const scene::Contact& c : p_.scene.contacts) names.push_back(c.name);
  for (const scene::LimitStop& s : p_.scene.limits) names.push_back(s.name);
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    r_.fail(name_node, path, "unknown contact '" + name + "'" + suggestion(name, names) +
                                 "; the scene's contacts and joint-limit stops are: " + joinNames(names));
  return static_cast<int>(it - names.begin());
}

double ProblemReader::bound(const YAML::Node& n, const std::string& path, double unbounded) {
  if (n.IsNull()) return unbounded;
  bool negative = false;
  if (n.IsScalar() && isInfinity(n.Scalar(), negative)) return negative ? -kInf : kInf;
  return r_.number(n, path);
}

void ProblemReader::readRange(const YAML::Node& n, const std::string& path, double& lower, double& upper) {
  if (n.IsScalar()) {
    lower = upper = r_.number(n, path);
    return;
  }
  if (!n.IsSequence() || n.size() != 2)
    r_.fail(n, path, "expected a number (fixes the value) or [lower, upper] (null or .inf for no bound), got " +
                         (n.IsSequence() ? "a sequence of " + std::to_string(n.size()) : describe(n)));
  lower = bound(n[0], indexPath(path, 0), -kInf);
  upper = bound(n[1], indexPath(path, 1), kInf);
  if (lower == kInf) r_.fail(n[0], indexPath(path, 0), "a lower bound of +infinity admits no value");
  if (upper == -kInf) r_.fail(n[1], indexPath(path, 1), "an upper bound of -infinity admits no value");
  if (lower > upper)
    r_.fail(n, path, "the lower bound " + fmt(lower) + " exceeds the upper bound " + fmt(upper));
}

void ProblemReader::readMesh(const YAML::Node& node) {
  r_.checkMap(node, "mesh", {"N", "P", "h_max", "h_min_ratio", "total_time", "first_order_steps_per_element"});
  const YAML::Node n = r_.required(node, "mesh", "N");
  p_.N = r_.integer(n, "mesh.N");
  if (p_.N < 1 || p_.N > kMaxElements)
    r_.fail(n, "mesh.N", "the number of finite elements must be from 1 to " + std::to_string(kMaxElements) + ", got " +
                             std::to_string(p_.N));
  if (node["P"].IsDefined()) {
    p_.P = r_.integer(node["P"], "mesh.P");
    if (p_.P < 1 || p_.P > 9)
      r_.fail(node["P"], "mesh.P", "the number of collocation points per element must be an integer in [1, 9], got " +
                                       std::to_string(p_.P));
  }
  const YAML::Node h = r_.required(node, "mesh", "h_max");
  p_.h_max = r_.number(h, "mesh.h_max");
  if (!(p_.h_max > 0)) r_.fail(h, "mesh.h_max", "the largest element length must be positive, got " + fmt(p_.h_max));
  p_.h_min_ratio = r_.number(node, "mesh", "h_min_ratio", p_.h_min_ratio);
  if (!(p_.h_min_ratio > 0 && p_.h_min_ratio <= 1))
    r_.fail(node["h_min_ratio"], "mesh.h_min_ratio",
            "the shortest element length as a fraction of h_max must be in (0, 1], got " + fmt(p_.h_min_ratio));
  if (node["first_order_steps_per_element"].IsDefined()) {
    const YAML::Node s = node["first_order_steps_per_element"];
    p_.first_order_steps_per_element = r_.integer(s, "mesh.first_order_steps_per_element");
    if (p_.first_order_steps_per_element < 1 || p_.first_order_steps_per_element > kMaxStepsPerElement)
      r_.fail(s, "mesh.first_order_steps_per_element",
              "expected an integer from 1 to " + std::to_string(kMaxStepsPerElement) + ", got " +
                  std::to_string(p_.first_order_steps_per_element));
  }

  const YAML::Node t = node["total_time"];
  p_.total_time_kind = TotalTime::Free;
  p_.total_time = 0;
  if (!t.IsDefined() || t.IsNull()) return;
  r_.checkMap(t, "mesh.total_time", {"at_least", "equal"});
  if (t.size() != 1)
    r_.fail(t, "mesh.total_time", "expected exactly one of: at_least, equal (or no total_time: free)");
  const double longest = p_.N * p_.h_max, shortest = p_.N * p_.h_min_ratio * p_.h_max;
  if (t["at_least"].IsDefined()) {
    p_.total_time_kind = TotalTime::AtLeast;
    p_.total_time = r_.number(t["at_least"], "mesh.total_time.at_least");
    if (!(p_.total_time >= 0))
      r_.fail(t["at_least"], "mesh.total_time.at_least", "the total time must be non-negative, got " + fmt(p_.total_time));
    if (p_.total_time > longest)
      r_.fail(t["at_least"], "mesh.total_time.at_least",
              "a total time of at least " + fmt(p_.total_time) + " s cannot be reached: N h_max = " + fmt(longest) + " s");
  } else {
    p_.total_time_kind = TotalTime::Equal;
    p_.total_time = r_.number(t["equal"], "mesh.total_time.equal");
    if (!(p_.total_time >= shortest && p_.total_time <= longest))
      r_.fail(t["equal"], "mesh.total_time.equal",
              "a total time of " + fmt(p_.total_time) + " s is outside what the mesh allows: [N h_min_ratio h_max, N h_max] = [" +
                  fmt(shortest) + ", " + fmt(longest) + "] s");
  }
}

void ProblemReader::readInputs(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) {
    p_.input_lower.resize(0);
    p_.input_upper.resize(0);
    return;
  }
  std::vector<double> lower, upper;
  auto add = [&](const YAML::Node& name_node, const std::string& path) {
    const int i = coordinate(name_node, path);
    if (std::find(p_.inputs.begin(), p_.inputs.end(), i) != p_.inputs.end())
      r_.fail(name_node, path, "coordinate '" + p_.scene.model.coordinate_name[i] + "' is listed twice");
    p_.inputs.push_back(i);
    const double effort = p_.scene.model.limits[i].effort;
    lower.push_back(std::isfinite(effort) ? -effort : -kInf);
    upper.push_back(std::isfinite(effort) ? effort : kInf);
  };
  if (node.IsSequence()) {
    for (std::size_t j = 0; j < node.size(); ++j) add(node[j], indexPath("inputs", j));
  } else {
    if (!node.IsMap())
      r_.fail(node, "inputs", "expected a list of coordinate names or a map name: {lower, upper}, got " + describe(node));
    r_.checkNameMap(node, "inputs");
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string path = keyPath("inputs", it->first.Scalar());
      add(it->first, path);
      const YAML::Node b = it->second;
      r_.checkMap(b, path, {"lower", "upper"}, true);
      if (b.IsNull()) continue;
      if (b["lower"].IsDefined()) lower.back() = bound(b["lower"], keyPath(path, "lower"), -kInf);
      if (b["upper"].IsDefined()) upper.back() = bound(b["upper"], keyPath(path, "upper"), kInf);
      if (lower.back() > upper.back())
        r_.fail(b, path, "the lower bound " + fmt(lower.back()) + " exceeds the upper bound " + fmt(upper.back()));
    }
  }
  p_.input_lower = Eigen::Map<Eigen::VectorXd>(lower.data(), static_cast<Eigen::Index>(lower.size()));
  p_.input_upper = Eigen::Map<Eigen::VectorXd>(upper.data(), static_cast<Eigen::Index>(upper.size()));
}

std::vector<int> ProblemReader::readCoordinateList(const YAML::Node& node, const std::string& path) {
  std::vector<int> out;
  if (!node.IsDefined() || node.IsNull()) return out;
  r_.checkSequence(node, path);
  for (std::size_t j = 0; j < node.size(); ++j) {
    const std::string p = indexPath(path, j);
    const int i = coordinate(node[j], p);
    if (std::find(out.begin(), out.end(), i) != out.end())
      r_.fail(node[j], p, "coordinate '" + p_.scene.model.coordinate_name[i] + "' is listed twice");
    out.push_back(i);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void ProblemReader::readInitialFree(const YAML::Node& node) {
  if (!node.IsDefined()) return;
  r_.checkMap(node, "initial_free", {"q", "v"}, true);
  if (node.IsNull()) return;
  p_.initial_free_q = readCoordinateList(node["q"], "initial_free.q");
  p_.initial_free_v = readCoordinateList(node["v"], "initial_free.v");
}

// The q, v, u and gap keys of `map` (already checked for unknown keys), as PointBounds at
// [element, point].
void ProblemReader::readConditions(const YAML::Node& map, const std::string& path, int element, int point,
                                   std::vector<PointBound>& out) {
  for (const std::string& key : kConditionKeys) {
    const YAML::Node n = map[key];
    if (!n.IsDefined()) continue;
    const std::string kpath = keyPath(path, key);
    r_.checkNameMap(n, kpath);
    if (n.IsNull()) continue;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string p = keyPath(kpath, it->first.Scalar());
      PointBound b;
      b.element = element;
      b.point = point;
      if (key == "q") b.quantity = {Quantity::Kind::Position, coordinate(it->first, p)};
      if (key == "v") b.quantity = {Quantity::Kind::Velocity, coordinate(it->first, p)};
      if (key == "u") b.quantity = {Quantity::Kind::Input, input(it->first, p)};
      if (key == "gap") b.quantity = {Quantity::Kind::Gap, gapIndex(it->first, p)};
      readRange(it->second, p, b.lower, b.upper);
      b.origin = origin(it->second);
      out.push_back(b);
    }
  }
}

// `at: [n, p]` of a list entry: 1-based element n ∈ [1, N], point p ∈ [0, P + 1]; returns the
// 0-based element and the point.
std::pair<int, int> ProblemReader::readAt(const YAML::Node& entry, const std::string& path, const std::string& key) {
  const YAML::Node at = r_.required(entry, path, key);
  const std::string apath = keyPath(path, key);
  if (!at.IsSequence() || at.size() != 2)
    r_.fail(at, apath, "expected [element, point], e.g. [6, 0] (elements numbered from 1 as in the paper), got " +
                           (at.IsSequence() ? "a sequence of " + std::to_string(at.size()) : describe(at)));
  const int n = r_.integer(at[0], indexPath(apath, 0)), pt = r_.integer(at[1], indexPath(apath, 1));
  if (n < 1 || n > p_.N)
    r_.fail(at[0], apath, "element " + std::to_string(n) + " is not in [1, " + std::to_string(p_.N) +
                              "] (elements are numbered from 1 as in the paper, up to mesh.N = " + std::to_string(p_.N) + ")");
  if (pt < 0 || pt > p_.P + 1)
    r_.fail(at[1], apath, "point " + std::to_string(pt) + " is not in [0, " + std::to_string(p_.P + 1) +
                              "] (0: the element's first mesh point, 1 to P = " + std::to_string(p_.P) +
                              ": its collocation points, P + 1 = " + std::to_string(p_.P + 1) + ": its last mesh point)");
  return {n - 1, pt};
}

void ProblemReader::readPointConditions(const YAML::Node& node, const std::string& path, std::vector<PointBound>& out) {
  if (!node.IsDefined()) return;
  r_.checkSequence(node, path);
  std::vector<std::string> keys = {"at", "from", "to"};
  keys.insert(keys.end(), kConditionKeys.begin(), kConditionKeys.end());
  for (std::size_t j = 0; j < node.size(); ++j) {
    const YAML::Node e = node[j];
    const std::string p = indexPath(path, j);
    r_.checkMap(e, p, keys);
    // One point (`at`), or every point from `from` through `to` (both included).
    const bool range = e["from"].IsDefined() || e["to"].IsDefined();
    if (range && e["at"].IsDefined())
      r_.fail(e["at"], keyPath(p, "at"), "give either at: [n, p] or from: [n, p] and to: [n, p], not both");
    const std::size_t placement = range ? 2 : 1;
    if (e.size() <= placement)
      r_.fail(e, p, std::string("nothing to impose at ") + (range ? "these points" : "this point") +
                        ": give one or more of q, v, u, gap");
    if (!range) {
      const auto [element, point] = readAt(e, p);
      readConditions(e, p, element, point, out);
      continue;
    }
    const auto [n1, p1] = readAt(e, p, "from");
    const auto [n2, p2] = readAt(e, p, "to");
    if (n2 < n1 || (n2 == n1 && p2 < p1))
      r_.fail(e["to"], keyPath(p, "to"), "[" + std::to_string(n2 + 1) + ", " + std::to_string(p2) + "] comes before from: [" +
                                             std::to_string(n1 + 1) + ", " + std::to_string(p1) + "]");
    for (int n = n1; n <= n2; ++n) {
      const int first = n == n1 ? p1 : 0, last = n == n2 ? p2 : p_.P + 1;
      if (first == 0 && last == p_.P + 1) {
        readConditions(e, p, n, -1, out);  // the whole element
      } else {
        for (int pt = first; pt <= last; ++pt) readConditions(e, p, n, pt, out);
      }
    }
  }
}

void ProblemReader::readSurfaceVelocity(const YAML::Node& node, const YAML::Node& root) {
  std::vector<std::string> names;
  for (const scene::Surface& s : p_.scene.surfaces) names.push_back(s.name);
  std::set<int> given;
  if (node.IsDefined()) {
    r_.checkNameMap(node, "surface_velocity");
    if (node.IsMap()) {
      for (auto it = node.begin(); it != node.end(); ++it) {
        const std::string name = it->first.Scalar(), path = keyPath("surface_velocity", name);
        const auto found = std::find(names.begin(), names.end(), name);
        if (found == names.end())
          r_.fail(it->first, path, "unknown surface '" + name + "'" + suggestion(name, names) +
                                       "; the scene's surfaces are: " + joinNames(names));
        const int s = static_cast<int>(found - names.begin());
        scene::Surface& surface = p_.scene.surfaces[s];
        const YAML::Node list = it->second;
        if (!list.IsSequence() || list.size() == 0)
          r_.fail(list, path, "expected a list of steps {at: [n, 0], velocity: [x, y, z]}, got " +
                                  (list.IsSequence() ? "an empty list" : describe(list)));
        std::vector<SurfaceStep> steps;
        for (std::size_t j = 0; j < list.size(); ++j) {
          const YAML::Node e = list[j];
          const std::string p = indexPath(path, j);
          r_.checkMap(e, p, {"at", "velocity"});
          const auto [element, point] = readAt(e, p);
          if (point != 0)
            r_.fail(e["at"][1], keyPath(p, "at"),
                    "a surface's velocity steps at a mesh point [n, 0] (the start of element n), got point " +
                        std::to_string(point) + ": the velocity is constant through each element");
          if (!steps.empty() && element <= steps.back().element)
            r_.fail(e["at"][0], keyPath(p, "at"),
                    "elements must increase along the steps: element " + std::to_string(element + 1) + " follows " +
                        std::to_string(steps.back().element + 1));
          SurfaceStep step;
          step.element = element;
          const YAML::Node v = r_.required(e, p, "velocity");
          step.velocity = r_.vec3(v, keyPath(p, "velocity"));
          const double vn = surface.normal.dot(step.velocity);
          if (std::abs(vn) > 1e-9 * std::max(1.0, step.velocity.norm()))
            r_.fail(v, keyPath(p, "velocity"),
                    "the surface velocity " + fmt(step.velocity) + " must be tangent to the plane (normal " +
                        fmt(surface.normal) + "): its normal component is " + fmt(vn) + " m/s");
          steps.push_back(step);
        }
        p_.surface_steps[s] = steps;
        surface.velocity_schedule.clear();  // replaced by the steps on the mesh
        given.insert(s);
      }
    }
  }
  // A surface left to its time schedule must not change velocity after t = 0; a constant
  // non-zero velocity becomes one step at the first element.
  for (int s = 0; s < static_cast<int>(p_.scene.surfaces.size()); ++s) {
    if (given.count(s)) continue;
    const scene::Surface& surface = p_.scene.surfaces[s];
    Eigen::Vector3d before = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < surface.velocity_schedule.size(); ++j) {
      const scene::Surface::Step& step = surface.velocity_schedule[j];
      if (step.time > 0 && step.velocity != before) {
        const std::string path = keyPath(indexPath(keyPath(indexPath("surfaces", s), "velocity_schedule"), j), "time");
        r_.fail(root["surfaces"][s]["velocity_schedule"][j]["time"], path,
                "surface '" + surface.name + "' changes velocity to " + fmt(step.velocity) + " at t = " +
                    fmt(step.time) + " s, but in a problem the element lengths are variables, so the time of a step is "
                    "not known in advance: give the steps at mesh points under surface_velocity." + surface.name +
                    " (e.g. - {at: [6, 0], velocity: " + fmt(step.velocity) + "})");
      }
      before = step.velocity;
    }
    const Eigen::Vector3d v0 = surface.velocity(0);
    if (!v0.isZero()) p_.surface_steps[s] = {SurfaceStep{0, v0}};
  }
}

void ProblemReader::readCost(const YAML::Node& node) {
  if (!node.IsDefined()) return;
  r_.checkMap(node, "cost", {"penalty_weight", "effort", "minimise_max"}, true);
  if (node.IsNull()) return;
  CostTerms& c = p_.cost;
  c.penalty_weight = r_.number(node, "cost", "penalty_weight", c.penalty_weight);
  if (!(c.penalty_weight >= 0))
    r_.fail(node["penalty_weight"], "cost.penalty_weight", "a weight must be non-negative, got " + fmt(c.penalty_weight));
  c.effort_weight = r_.number(node, "cost", "effort", c.effort_weight);
  if (!(c.effort_weight >= 0))
    r_.fail(node["effort"], "cost.effort", "a weight must be non-negative, got " + fmt(c.effort_weight));
  if (c.effort_weight > 0 && p_.inputs.empty())
    r_.fail(node["effort"], "cost.effort", "an effort cost needs inputs: list the actuated coordinates under `inputs`");
  const YAML::Node m = node["minimise_max"];
  if (m.IsDefined()) {
    r_.checkMap(m, "cost.minimise_max", {"coordinate", "weight"});
    c.max_coordinate = coordinate(r_.required(m, "cost.minimise_max", "coordinate"), "cost.minimise_max.coordinate");
    c.max_weight = r_.number(m, "cost.minimise_max", "weight", 1.0);
    if (!(c.max_weight >= 0))
      r_.fail(m["weight"], "cost.minimise_max.weight", "a weight must be non-negative, got " + fmt(c.max_weight));
  }
}

void ProblemReader::read(const YAML::Node& root) {
  readMesh(r_.required(root, "", "mesh"));
  readInputs(root["inputs"]);
  readInitialFree(root["initial_free"]);
  if (const YAML::Node f = root["final"]; f.IsDefined()) {
    r_.checkMap(f, "final", kConditionKeys, true);
    if (!f.IsNull()) readConditions(f, "final", p_.N - 1, p_.P + 1, p_.bounds);
  }
  if (const YAML::Node b = root["bounds"]; b.IsDefined()) {
    r_.checkMap(b, "bounds", kConditionKeys, true);
    if (!b.IsNull()) readConditions(b, "bounds", -1, -1, p_.bounds);
  }
  readPointConditions(root["constraints"], "constraints", p_.bounds);
  readPointConditions(root["hints"], "hints", p_.hints);
  readSurfaceVelocity(root["surface_velocity"], root);
  readCost(root["cost"]);
  readSolve(root["solve"]);
  readIpopt(root["ipopt"], "ipopt", p_.ipopt_options);
  readIpopt(root["task_ipopt"], "task_ipopt", p_.task_ipopt_options);
}

}  // namespace detail

std::string problemsDirectory() {
  if (const char* env = std::getenv("SALTUS_PROBLEMS_DIR"); env && *env) return env;
  return scene::dataDirectory() + "/models/problems";
}

std::vector<std::string> builtinProblemNames() {
  return scene::yamlFileNames(problemsDirectory());
}

namespace {

// A problem file's `scene: <name or path>`: the scene read from that scenario file (a built-in
// scene's name, or a path relative to the problem file), with the overrides that name its
// parameters. The problem file then holds no scene keys of its own but its name, description and
// parameters, and its expressions may use the scene's parameters.
struct SceneReference {
  scene::Scene scene;
  std::string path;  // the scenario file
  std::map<std::string, double> parameters;  // its parameters in use
};

SceneReference readSceneReference(const YamlReader& reader, const YAML::Node& root,
                                  const std::map<std::string, double>& overrides) {
  const YAML::Node node = root["scene"];
  const std::string name = reader.text(node, "scene");
  for (const std::string& key : kSceneKeys)
    if (key != "name" && key != "description" && key != "parameters" && root[key].IsDefined())
      reader.fail(YamlReader::keyMark(root, key), key,
                  "the scene comes from '" + name + "' (key 'scene'): a problem file that names its scene gives "
                  "none of its keys; change them in the scenario file, or its parameters with --set");
  // A path is relative to the problem file's folder; a name is a built-in scene.
  std::string wanted = name;
  const bool path_like = name.find('/') != std::string::npos || name.ends_with(".yaml") || name.ends_with(".yml");
  if (path_like && !std::filesystem::path(name).is_absolute())
    wanted = (std::filesystem::path(reader.file()).parent_path() / name).string();
  SceneReference ref;
  std::string source;
  try {
    const scene::YamlSource found = scene::resolveYamlFile(wanted, scene::scenesDirectory(), "scene", "scenario file");
    ref.path = found.path;
    source = found.source;
  } catch (const scene::ScenarioError& e) {
    reader.fail(node, "scene", e.what());
  }
  const YAML::Node scene_root = scene::loadYamlFile(ref.path);
  // The overrides of the scene's parameters go to it; the problem's own stay with the problem.
  std::map<std::string, double> scene_overrides;
  std::set<std::string> own;
  if (const YAML::Node p = root["parameters"]; p.IsMap())
    for (auto it = p.begin(); it != p.end(); ++it) own.insert(it->first.Scalar());
  for (const auto& [key, value] : overrides)
    if (!own.count(key) && scene_root.IsMap() && scene_root["parameters"].IsMap() &&
        scene_root["parameters"][key].IsDefined())
      scene_overrides[key] = value;
  YamlReader scene_reader(ref.path, scene_overrides);
  if (scene_root.IsMap()) scene_reader.readParameters(scene_root);
  ref.scene = scene::readScene(scene_reader, scene_root);
  ref.scene.source = source;
  ref.parameters = scene_reader.parameters();
  return ref;
}

}  // namespace

namespace {

// with_steps: also the problems of a continuation's steps (solve.continuation), each the file
// read again with the step's values over the overrides; without: none (a step's own problem).
Problem load(const std::string& name_or_path, const std::map<std::string, double>& overrides, bool with_steps) {
  const auto [path, source] = scene::resolveYamlFile(name_or_path, problemsDirectory(), "problem", "problem file");
  const YAML::Node root = scene::loadYamlFile(path, "problem file");
  Problem problem;
  std::map<std::string, double> own_overrides = overrides;
  std::optional<SceneReference> ref;
  if (root.IsMap() && root["scene"].IsDefined()) {
    const YamlReader first(path, {});  // for the messages about the key
    ref = readSceneReference(first, root, overrides);
    for (const auto& [name, value] : ref->parameters) own_overrides.erase(name);
  }
  YamlReader reader(path, own_overrides);
  if (ref) reader.defineParameters(ref->parameters, ref->path);
  if (root.IsMap()) reader.readParameters(root);
  if (!root.IsMap())
    reader.fail(root, "", "a problem file must be a map of keys (name, model, mesh, ...), got " + describe(root));
  refuseSceneOnlyKeys(reader, root);
  std::vector<std::string> keys = kSceneKeys;
  keys.insert(keys.end(), kProblemKeys.begin(), kProblemKeys.end());
  keys.push_back("scene");
  reader.checkMap(root, "", keys);

  if (ref) {
    problem.scene = std::move(ref->scene);
    problem.scene_file = ref->path;
    if (root["name"].IsDefined()) problem.scene.name = reader.text(root["name"], "name");
    if (root["description"].IsDefined()) problem.scene.description = reader.text(root["description"], "description");
  } else {
    problem.scene = scene::readScene(reader, root, kProblemKeys);
    problem.scene.source = source;
  }
  if (problem.scene.model.base == dynamics::BaseType::FreeQuaternion)  // derivatives are taken along coordinates
    reader.fail(root[ref ? "scene" : "base"], ref ? "scene" : "base",
                std::string("the optimiser takes derivatives along coordinates, which a quaternion base's orientation "
                            "has not: use base: free (Euler angles; keep pitch away from ±π/2) ") +
                    (ref ? "in the scenario file" : "in a problem file"));
  problem.name = problem.scene.name;
  problem.description = problem.scene.description;
  problem.source = source;
  problem.parameters = reader.parameters();
  try {
    detail::ProblemReader(reader, problem).read(root);
  } catch (const YAML::Exception& e) {  // not expected: every node is type-checked before use
    throw scene::ScenarioError(scene::location(reader.file(), e.mark) + ": " + e.msg);
  }
  problem.fingerprint = problemFingerprint(root, problem);
  if (!with_steps) problem.continuation.clear();
  for (ContinuationStep& step : problem.continuation) {
    std::map<std::string, double> values = overrides;
    for (const auto& [name, value] : step.parameters) values[name] = value;
    step.problem = std::make_shared<const Problem>(load(name_or_path, values, false));
  }
  return problem;
}

}  // namespace

Problem loadProblem(const std::string& name_or_path, const std::map<std::string, double>& overrides) {
  return load(name_or_path, overrides, true);
}

}  // namespace saltus::collocation
