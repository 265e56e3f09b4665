#include "timestepper/scenario.hpp"

#include <muParser.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <numbers>
#include <set>
#include <sstream>

#include "dynamics/builder.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"

namespace saltus::timestepper {

namespace fs = std::filesystem;
using dynamics::BaseType;
using dynamics::Model;

namespace {

std::string joinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none)" : s;
}

std::string keyPath(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
std::string indexPath(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar: return "the scalar '" + n.Scalar() + "'";
    case YAML::NodeType::Sequence: return "a sequence";
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Null: return "an empty value";
    default: return "nothing";
  }
}

std::string location(const std::string& file, const YAML::Mark& m) {
  if (m.is_null() || m.line < 0) return file;
  return file + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(10);
  s << x;
  return s.str();
}
std::string fmt(const Eigen::Vector3d& v) {
  return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]";
}

bool isIdentifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> d(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = d[0];
    d[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = d[j];
      d[j] = std::min({d[j] + 1, d[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return d[b.size()];
}

// " (did you mean 'x'?)" when one candidate is close to `word`.
std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const std::string& c : candidates) {
    const std::size_t d = editDistance(word, c);
    if (d < best_d) best_d = d, best = c;
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

double atan2Fn(double y, double x) { return std::atan2(y, x); }

// Rejects muparser's assignment operator (`x = 3` would change a parameter) and its
// comma-separated multiple expressions; returns "" when the text is acceptable.
std::string checkExpressionText(const std::string& s) {
  int depth = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (c == ',' && depth == 0)
      return "a number is one expression, found a ',' outside parentheses (a YAML list needs [ ] "
             "around it)";
    if (c == '=') {
      const char prev = i > 0 ? s[i - 1] : ' ', next = i + 1 < s.size() ? s[i + 1] : ' ';
      if (next != '=' && prev != '=' && prev != '<' && prev != '>' && prev != '!')
        return "assignment ('=') is not allowed in an expression";
    }
  }
  return "";
}

void setupParser(mu::Parser& p) {
  p.DefineConst("pi", std::numbers::pi);
  p.DefineFun("atan2", atan2Fn);
}

// A plain decimal number, without going through muparser.
bool plainNumber(const std::string& s, double& x) {
  if (s.empty()) return false;
  char* end = nullptr;
  x = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(x) &&
         s.find_first_of("xXpP") == std::string::npos;  // no hex floats, no inf/nan words
}

// R = Rz(yaw) Ry(pitch) Rx(roll), the URDF rpy convention.
Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

class Loader {
 public:
  Loader(std::string file, const std::map<std::string, double>& overrides)
      : file_(std::move(file)), overrides_(overrides) {
    setupParser(parser_);
  }

  Scene load(const YAML::Node& root);

 private:
  [[noreturn]] void fail(const YAML::Mark& m, const std::string& path, const std::string& what) const {
    throw ScenarioError(location(file_, m) + ": " + (path.empty() ? "" : path + ": ") + what);
  }
  [[noreturn]] void fail(const YAML::Node& at, const std::string& path, const std::string& what) const {
    fail(at.Mark(), path, what);
  }

  // A map (an empty value counts as an empty map when `allow_null`), whose keys are all in
  // `allowed` and each given once.
  void checkMap(const YAML::Node& n, const std::string& path, const std::vector<std::string>& allowed,
                bool allow_null = false) const {
    if (allow_null && n.IsNull()) return;
    if (!n.IsMap()) fail(n, path, "expected a map, got " + describe(n));
    std::set<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first, path, "map keys must be plain names, got " + describe(it->first));
      const std::string k = it->first.Scalar();
      if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), k) == allowed.end())
        fail(it->first, keyPath(path, k),
             "unknown key '" + k + "'" + suggestion(k, allowed) + "; expected one of: " + joinNames(allowed));
      if (!seen.insert(k).second) fail(it->first, keyPath(path, k), "key '" + k + "' is given twice");
    }
  }
  // Any keys (names of things), each once.
  void checkNameMap(const YAML::Node& n, const std::string& path) const { checkMap(n, path, {}, true); }

  void checkSequence(const YAML::Node& n, const std::string& path) const {
    if (!n.IsSequence() && !n.IsNull()) fail(n, path, "expected a sequence (a YAML list), got " + describe(n));
  }

  // Position of `key` itself in a map (the key, not its value).
  static YAML::Mark keyMark(const YAML::Node& map, const std::string& key) {
    for (auto it = map.begin(); it != map.end(); ++it)
      if (it->first.IsScalar() && it->first.Scalar() == key) return it->first.Mark();
    return map.Mark();
  }

  YAML::Node required(const YAML::Node& map, const std::string& path, const std::string& key) const {
    const YAML::Node n = map[key];
    if (!n.IsDefined()) fail(map, keyPath(path, key), "missing required key '" + key + "'");
    return n;
  }

  std::string text(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected a name (a scalar), got " + describe(n));
    return n.Scalar();
  }

  double evaluate(const std::string& expr, const YAML::Node& at, const std::string& path) {
    double x;
    if (plainNumber(expr, x)) return x;
    const std::string bad = checkExpressionText(expr);
    if (!bad.empty()) fail(at, path, "bad expression '" + expr + "': " + bad);
    try {
      parser_.SetExpr(expr);
      x = parser_.Eval();
    } catch (const mu::Parser::exception_type& e) {
      std::vector<std::string> names;
      for (const auto& [name, value] : params_) names.push_back(name);
      fail(at, path, "bad expression '" + expr + "': " + e.GetMsg() +
                         " (known names: parameters " + joinNames(names) + "; constant pi)");
    }
    if (!std::isfinite(x)) fail(at, path, "expression '" + expr + "' evaluates to " + fmt(x));
    return x;
  }

  double number(const YAML::Node& n, const std::string& path) {
    if (!n.IsScalar()) fail(n, path, "expected a number or an expression, got " + describe(n));
    return evaluate(n.Scalar(), n, path);
  }
  double number(const YAML::Node& map, const std::string& path, const std::string& key, double dflt) {
    const YAML::Node n = map[key];
    return n.IsDefined() ? number(n, keyPath(path, key)) : dflt;
  }
  int integer(const YAML::Node& n, const std::string& path) {
    const double x = number(n, path);
    if (x != std::round(x) || std::abs(x) > 1e9) fail(n, path, "expected an integer, got " + fmt(x));
    return static_cast<int>(x);
  }

  Eigen::VectorXd vector(const YAML::Node& n, const std::string& path, int size) {
    if (!n.IsSequence() || static_cast<int>(n.size()) != size)
      fail(n, path, "expected a sequence of " + std::to_string(size) + " numbers, got " +
                        (n.IsSequence() ? "a sequence of " + std::to_string(n.size()) : describe(n)));
    Eigen::VectorXd v(size);
    for (int i = 0; i < size; ++i) v[i] = number(n[i], indexPath(path, i));
    return v;
  }
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& path) { return vector(n, path, 3); }
  Eigen::Vector3d vec3(const YAML::Node& map, const std::string& path, const std::string& key,
                       const Eigen::Vector3d& dflt) {
    const YAML::Node n = map[key];
    return n.IsDefined() ? vec3(n, keyPath(path, key)) : dflt;
  }

  bool boolean(const YAML::Node& n, const std::string& path) const {
    if (n.IsScalar() && (n.Scalar() == "true" || n.Scalar() == "false")) return n.Scalar() == "true";
    fail(n, path, "expected true or false, got " + describe(n));
  }

  void readParameters(const YAML::Node& root);
  Model<double> readModel(const YAML::Node& node, BaseType base, const Eigen::Vector3d& gravity,
                          const YAML::Node& base_node);
  Model<double> readPointMass(const YAML::Node& node, const std::string& path, BaseType base,
                              const Eigen::Vector3d& gravity, const YAML::Node& base_node);
  Model<double> readRigidBody(const YAML::Node& node, const std::string& path, BaseType base,
                              const Eigen::Vector3d& gravity, const YAML::Node& base_node);
  std::vector<dynamics::Visual> readVisuals(const YAML::Node& node, const std::string& path,
                                            const std::string& link, int body);
  Eigen::VectorXd readCoordinateMap(const YAML::Node& node, const std::string& path,
                                    const Model<double>& model);
  int coordinate(const YAML::Node& name_node, const std::string& path, const Model<double>& model) const;
  std::vector<Surface> readSurfaces(const YAML::Node& node);
  std::vector<Contact> readContacts(const YAML::Node& node, const Scene& scene);
  std::vector<LimitStop> readLimits(const YAML::Node& root, const Model<double>& model);

  std::string file_;
  std::map<std::string, double> overrides_;
  std::map<std::string, double> params_;  // node-stable storage: muparser holds pointers into it
  mu::Parser parser_;
};

void Loader::readParameters(const YAML::Node& root) {
  const YAML::Node node = root["parameters"];
  std::vector<std::string> names;
  if (node.IsDefined()) {
    checkNameMap(node, "parameters");
    if (node.IsMap()) {
      for (auto it = node.begin(); it != node.end(); ++it) {
        const std::string name = it->first.Scalar();
        const std::string path = keyPath("parameters", name);
        if (!isIdentifier(name))
          fail(it->first, path, "a parameter name must be a letter or '_' followed by letters, digits or '_'");
        if (name == "pi") fail(it->first, path, "'pi' is a constant and cannot be a parameter");
        // The default is evaluated even when overridden, so that a broken file shows at once.
        double value = number(it->second, path);
        if (const auto o = overrides_.find(name); o != overrides_.end()) value = o->second;
        double& slot = params_[name];
        slot = value;
        try {
          parser_.DefineVar(name, &slot);
        } catch (const mu::Parser::exception_type& e) {
          fail(it->first, path, "cannot use '" + name + "' as a parameter name: " + e.GetMsg());
        }
        names.push_back(name);
      }
    }
  }
  for (const auto& [name, value] : overrides_)
    if (!params_.count(name))
      fail(keyMark(root, "parameters"), "parameters",
           "--set " + name + "=" + fmt(value) + ": the scene has no parameter '" + name + "'" +
               suggestion(name, names) + "; its parameters are: " + joinNames(names));
}

std::vector<dynamics::Visual> Loader::readVisuals(const YAML::Node& node, const std::string& path,
                                                  const std::string& link, int body) {
  std::vector<dynamics::Visual> visuals;
  if (!node.IsDefined()) return visuals;
  checkSequence(node, path);
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node v = node[i];
    const std::string p = indexPath(path, i);
    checkMap(v, p, {"shape", "size", "xyz", "rpy", "rgba"});
    dynamics::Visual vis;
    vis.link = link;
    vis.body = body;
    const YAML::Node shape = required(v, p, "shape"), size = required(v, p, "size");
    const std::string s = text(shape, keyPath(p, "shape"));
    if (s == "box") {
      vis.shape = dynamics::Visual::Shape::Box;
      vis.size = vec3(size, keyPath(p, "size"));
    } else if (s == "cylinder") {
      vis.shape = dynamics::Visual::Shape::Cylinder;
      const Eigen::VectorXd rl = vector(size, keyPath(p, "size"), 2);
      vis.size = Eigen::Vector3d(rl[0], rl[1], 0);
    } else if (s == "sphere") {
      vis.shape = dynamics::Visual::Shape::Sphere;
      vis.size = Eigen::Vector3d(size.IsSequence() ? vector(size, keyPath(p, "size"), 1)[0]
                                                   : number(size, keyPath(p, "size")),
                                 0, 0);
    } else {
      fail(shape, keyPath(p, "shape"), "unknown shape '" + s + "'; expected one of: box, cylinder, sphere");
    }
    if ((vis.size.array() < 0).any() || vis.size.isZero())
      fail(size, keyPath(p, "size"), "sizes must be positive, got " + fmt(vis.size));
    vis.p_BG = vec3(v, p, "xyz", Eigen::Vector3d::Zero());
    vis.R_BG = rpyToMatrix(vec3(v, p, "rpy", Eigen::Vector3d::Zero()));
    if (v["rgba"].IsDefined()) vis.rgba = vector(v["rgba"], keyPath(p, "rgba"), 4);
    visuals.push_back(vis);
  }
  return visuals;
}

// A point mass on a chain of prismatic coordinates, one per axis (world axes), through massless
// intermediate links named <link>_<coordinate>.
Model<double> Loader::readPointMass(const YAML::Node& node, const std::string& path, BaseType base,
                                    const Eigen::Vector3d& gravity, const YAML::Node& base_node) {
  checkMap(node, path, {"mass", "axes", "link", "visuals"});
  if (base != BaseType::Fixed)
    fail(base_node, "base", "a point_mass model moves along its own axes from the world: base must be fixed");
  const double mass = number(required(node, path, "mass"), keyPath(path, "mass"));
  if (!(mass > 0)) fail(node["mass"], keyPath(path, "mass"), "mass must be positive, got " + fmt(mass));
  const std::string link = node["link"].IsDefined() ? text(node["link"], keyPath(path, "link")) : "mass";
  if (link == "world") fail(node["link"], keyPath(path, "link"), "'world' is the name of the fixed frame");
  const YAML::Node axes = required(node, path, "axes");
  const std::string apath = keyPath(path, "axes");
  checkNameMap(axes, apath);
  if (axes.size() == 0 || axes.size() > 3) fail(axes, apath, "expected 1 to 3 coordinates (name: axis)");

  dynamics::ModelBuilder b("point_mass");
  b.setSource(file_);
  b.addLink("world");
  Eigen::Matrix3d span = Eigen::Matrix3d::Zero();
  std::string parent = "world";
  int i = 0;
  for (auto it = axes.begin(); it != axes.end(); ++it, ++i) {
    const std::string name = it->first.Scalar();
    const std::string p = keyPath(apath, name);
    const Eigen::Vector3d a = vec3(it->second, p);
    if (!(a.norm() > 1e-12)) fail(it->second, p, "an axis must be a non-zero vector");
    span.col(i) = a.normalized();
    Eigen::FullPivLU<Eigen::Matrix3d> lu(span.leftCols(i + 1) * span.leftCols(i + 1).transpose());
    if (lu.rank() < i + 1)
      fail(it->second, p, "axis " + fmt(a) + " is a combination of the previous axes (the mass matrix would be singular)");
    const bool last = i + 1 == static_cast<int>(axes.size());
    const std::string child = last ? link : link + "_" + name;
    if (last)
      b.addLink(link, mass, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
    else
      b.addLink(child);
    dynamics::JointSpec j;
    j.name = name;
    j.type = dynamics::LinkJointType::Prismatic;
    j.parent = parent;
    j.child = child;
    j.axis = span.col(i);
    b.addJoint(j);
    parent = child;
  }
  for (dynamics::Visual v : readVisuals(node["visuals"], keyPath(path, "visuals"), link, -1)) b.addVisual(link, v);
  try {
    return b.build(BaseType::Fixed, gravity);
  } catch (const dynamics::ModelError& e) {  // e.g. a link name clashing with an intermediate link
    fail(node, path, e.what());
  }
}

Model<double> Loader::readRigidBody(const YAML::Node& node, const std::string& path, BaseType base,
                                    const Eigen::Vector3d& gravity, const YAML::Node& base_node) {
  checkMap(node, path, {"mass", "com", "inertia", "link", "visuals"});
  if (base == BaseType::Fixed)
    fail(base_node.IsDefined() ? base_node : node, "base",
         "a rigid_body model needs a moving base: base must be planar or free");
  const double mass = number(required(node, path, "mass"), keyPath(path, "mass"));
  const Eigen::Vector3d com = vec3(node, path, "com", Eigen::Vector3d::Zero());
  const std::string link = node["link"].IsDefined() ? text(node["link"], keyPath(path, "link")) : "body";
  const YAML::Node in = required(node, path, "inertia");
  const std::string ipath = keyPath(path, "inertia");
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  if (in.IsSequence() && in.size() == 3 && in[0].IsScalar()) {
    I.diagonal() = vec3(in, ipath);
  } else if (in.IsSequence() && in.size() == 3) {
    for (int r = 0; r < 3; ++r) I.row(r) = vec3(in[r], indexPath(ipath, r)).transpose();
  } else {
    fail(in, ipath, "expected the principal moments [Ixx, Iyy, Izz] or a 3x3 matrix [[...], [...], [...]], got " +
                        (in.IsSequence() ? "a sequence of " + std::to_string(in.size()) : describe(in)));
  }
  const std::string why = dynamics::checkInertia(mass, I, false);
  if (!why.empty()) fail(in, ipath, why);
  dynamics::ModelBuilder b("rigid_body");
  b.setSource(file_);
  b.addLink(link, mass, com, I);
  for (dynamics::Visual v : readVisuals(node["visuals"], keyPath(path, "visuals"), link, -1))
    b.addVisual(link, v);
  try {
    return b.build(base, gravity);
  } catch (const dynamics::ModelError& e) {
    fail(node, path, e.what());
  }
}

Model<double> Loader::readModel(const YAML::Node& node, BaseType base, const Eigen::Vector3d& gravity,
                                const YAML::Node& base_node) {
  checkMap(node, "model", {"urdf", "point_mass", "rigid_body"});
  if (node.size() == 0) fail(node, "model", "expected exactly one of: urdf, point_mass, rigid_body");
  if (node.size() > 1) {
    auto second = std::next(node.begin());
    fail(second->first, keyPath("model", second->first.Scalar()),
         "expected exactly one of: urdf, point_mass, rigid_body ('" + node.begin()->first.Scalar() +
             "' is already given)");
  }
  if (node["point_mass"].IsDefined())
    return readPointMass(node["point_mass"], "model.point_mass", base, gravity, base_node);
  if (node["rigid_body"].IsDefined())
    return readRigidBody(node["rigid_body"], "model.rigid_body", base, gravity, base_node);
  const YAML::Node u = node["urdf"];
  fs::path urdf = text(u, "model.urdf");
  if (urdf.is_relative()) urdf = fs::path(file_).parent_path() / urdf;
  try {
    return dynamics::readUrdfFile(urdf.lexically_normal().string()).build(base, gravity);
  } catch (const dynamics::ModelError& e) {
    fail(u, "model.urdf", e.what());
  }
}

int Loader::coordinate(const YAML::Node& name_node, const std::string& path, const Model<double>& model) const {
  const std::string name = text(name_node, path);
  const int i = model.coordinateIndex(name);
  if (i < 0)
    fail(name_node, path, "unknown coordinate '" + name + "'" + suggestion(name, model.coordinate_name) +
                              "; the model's coordinates are: " + joinNames(model.coordinate_name));
  return i;
}

Eigen::VectorXd Loader::readCoordinateMap(const YAML::Node& node, const std::string& path,
                                          const Model<double>& model) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(model.nv());
  if (!node.IsDefined()) return x;
  checkNameMap(node, path);
  if (node.IsNull()) return x;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string p = keyPath(path, it->first.Scalar());
    x[coordinate(it->first, p, model)] = number(it->second, p);
  }
  return x;
}

std::vector<Surface> Loader::readSurfaces(const YAML::Node& node) {
  std::vector<Surface> surfaces;
  if (!node.IsDefined()) return surfaces;
  checkSequence(node, "surfaces");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node s = node[i];
    const std::string p = indexPath("surfaces", i);
    checkMap(s, p, {"name", "point", "normal", "velocity_schedule"});
    Surface surf;
    surf.name = text(required(s, p, "name"), keyPath(p, "name"));
    for (const Surface& other : surfaces)
      if (other.name == surf.name) fail(s["name"], keyPath(p, "name"), "surface '" + surf.name + "' is defined twice");
    surf.point = vec3(s, p, "point", Eigen::Vector3d::Zero());
    const Eigen::Vector3d n = vec3(s, p, "normal", Eigen::Vector3d::UnitZ());
    if (!(n.norm() > 1e-12)) fail(s["normal"], keyPath(p, "normal"), "the normal must be a non-zero vector, got " + fmt(n));
    surf.normal = n.normalized();
    const YAML::Node sched = s["velocity_schedule"];
    const std::string sp = keyPath(p, "velocity_schedule");
    if (sched.IsDefined()) {
      checkSequence(sched, sp);
      for (std::size_t j = 0; j < sched.size(); ++j) {
        const YAML::Node st = sched[j];
        const std::string stp = indexPath(sp, j);
        checkMap(st, stp, {"time", "velocity"});
        Surface::Step step;
        step.time = number(required(st, stp, "time"), keyPath(stp, "time"));
        step.velocity = vec3(required(st, stp, "velocity"), keyPath(stp, "velocity"));
        if (!surf.velocity_schedule.empty() && !(step.time > surf.velocity_schedule.back().time))
          fail(st["time"], keyPath(stp, "time"),
               "times must increase along the schedule: " + fmt(step.time) + " follows " +
                   fmt(surf.velocity_schedule.back().time));
        const double vn = surf.normal.dot(step.velocity);
        if (std::abs(vn) > 1e-9 * std::max(1.0, step.velocity.norm()))
          fail(st["velocity"], keyPath(stp, "velocity"),
               "the surface velocity " + fmt(step.velocity) + " must be tangent to the plane (normal " +
                   fmt(surf.normal) + "): its normal component is " + fmt(vn) + " m/s");
        surf.velocity_schedule.push_back(step);
      }
    }
    surfaces.push_back(surf);
  }
  return surfaces;
}

// Whether every point of the model moves in planes y = const: a planar base, or only revolute
// joints about world y and prismatic joints perpendicular to it (at q = 0, which rotations about
// y preserve).
bool isPlanar(const Model<double>& model) {
  if (model.base == BaseType::Planar) return true;
  if (model.base == BaseType::Free) return false;
  dynamics::Data<double> data(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nv());
  dynamics::forwardKinematics(model, data, q);
  for (int i = 0; i < model.nv(); ++i) {
    const Eigen::Vector3d a = dynamics::bodyRotation(data, i) * model.axis[i];
    const bool ok = model.joint_type[i] == dynamics::JointType::Revolute ? a.cross(Eigen::Vector3d::UnitY()).norm() < 1e-12
                                                                         : std::abs(a.y()) < 1e-12;
    if (!ok) return false;
  }
  return true;
}

std::vector<Contact> Loader::readContacts(const YAML::Node& node, const Scene& scene) {
  std::vector<Contact> contacts;
  if (!node.IsDefined()) return contacts;
  checkSequence(node, "contacts");
  const bool planar = isPlanar(scene.model);
  std::vector<std::string> surface_names, frame_names;
  for (const Surface& s : scene.surfaces) surface_names.push_back(s.name);
  for (const dynamics::Frame& f : scene.model.frames) frame_names.push_back(f.name);
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node c = node[i];
    const std::string p = indexPath("contacts", i);
    checkMap(c, p, {"name", "link", "point", "surface", "restitution", "friction", "directions"});
    Contact ct;
    const YAML::Node link = required(c, p, "link");
    ct.link = text(link, keyPath(p, "link"));
    ct.name = c["name"].IsDefined() ? text(c["name"], keyPath(p, "name")) : ct.link;
    for (const Contact& other : contacts)
      if (other.name == ct.name)
        fail(c["name"].IsDefined() ? c["name"] : c, keyPath(p, "name"),
             "contact name '" + ct.name + "' is used twice (give each contact a distinct name)");
    const int f = scene.model.frameIndex(ct.link);
    if (f < 0)
      fail(link, keyPath(p, "link"), "unknown link '" + ct.link + "'" + suggestion(ct.link, frame_names) +
                                          "; the model's links are: " + joinNames(frame_names));
    const dynamics::Frame& frame = scene.model.frames[f];
    if (frame.body < 0) fail(link, keyPath(p, "link"), "link '" + ct.link + "' is fixed to the world and cannot touch a surface");
    ct.body = frame.body;
    const Eigen::Vector3d point = vec3(c, p, "point", Eigen::Vector3d::Zero());
    ct.p_B = frame.R_BF * point + frame.p_BF;
    const YAML::Node surf = required(c, p, "surface");
    const std::string sname = text(surf, keyPath(p, "surface"));
    const auto s = std::find(surface_names.begin(), surface_names.end(), sname);
    if (s == surface_names.end())
      fail(surf, keyPath(p, "surface"), "unknown surface '" + sname + "'" + suggestion(sname, surface_names) +
                                            "; the scene's surfaces are: " + joinNames(surface_names));
    ct.surface = static_cast<int>(s - surface_names.begin());
    ct.restitution = number(c, p, "restitution", 0.0);
    if (!(ct.restitution >= 0 && ct.restitution <= 1))
      fail(c["restitution"], keyPath(p, "restitution"), "restitution must be in [0, 1], got " + fmt(ct.restitution));
    ct.friction = number(c, p, "friction", 0.0);
    if (!(ct.friction >= 0))
      fail(c["friction"], keyPath(p, "friction"), "friction must be non-negative, got " + fmt(ct.friction));
    if (c["directions"].IsDefined()) {
      ct.directions = integer(c["directions"], keyPath(p, "directions"));
      if (ct.friction > 0 && ct.directions < 2)
        fail(c["directions"], keyPath(p, "directions"),
             "a friction cone needs at least 2 directions (2 for planar motion, 4 or more in space), got " +
                 std::to_string(ct.directions));
      if (ct.directions < 0) fail(c["directions"], keyPath(p, "directions"), "directions must be non-negative");
    } else {
      ct.directions = planar ? 2 : 4;
    }
    if (ct.friction == 0) ct.directions = 0;
    contacts.push_back(ct);
  }
  return contacts;
}

std::vector<LimitStop> Loader::readLimits(const YAML::Node& root, const Model<double>& model) {
  std::vector<LimitStop> stops;
  const YAML::Node node = root["joint_limits"];
  const double e = number(root, "", "limit_restitution", 0.0);
  if (!(e >= 0 && e <= 1))
    fail(root["limit_restitution"], "limit_restitution", "restitution must be in [0, 1], got " + fmt(e));
  auto add = [&](int i) {
    const dynamics::JointLimits& l = model.limits[i];
    if (l.lower > -dynamics::kInf) stops.push_back({model.coordinate_name[i] + "_lower", i, false, l.lower, e});
    if (l.upper < dynamics::kInf) stops.push_back({model.coordinate_name[i] + "_upper", i, true, l.upper, e});
  };
  if (!node.IsDefined()) return stops;
  if (node.IsScalar()) {
    if (boolean(node, "joint_limits"))
      for (int i = 0; i < model.nv(); ++i) add(i);
    return stops;
  }
  if (!node.IsSequence())
    fail(node, "joint_limits", "expected true, false or a list of coordinate names, got " + describe(node));
  std::set<int> seen;
  for (std::size_t j = 0; j < node.size(); ++j) {
    const std::string p = indexPath("joint_limits", j);
    const int i = coordinate(node[j], p, model);
    if (!model.limits[i].hasPositionLimits())
      fail(node[j], p, "coordinate '" + model.coordinate_name[i] + "' has no finite position limit");
    if (!seen.insert(i).second) fail(node[j], p, "coordinate '" + model.coordinate_name[i] + "' is listed twice");
    add(i);
  }
  return stops;
}

Scene Loader::load(const YAML::Node& root) {
  if (!root.IsMap()) fail(root, "", "a scenario file must be a map of keys (name, model, surfaces, ...), got " + describe(root));
  checkMap(root, "",
           {"name", "description", "parameters", "model", "base", "gravity", "initial", "input", "surfaces",
            "contacts", "joint_limits", "limit_restitution", "duration"});
  Scene scene;
  scene.name = root["name"].IsDefined() ? text(root["name"], "name") : fs::path(file_).stem().string();
  scene.description = root["description"].IsDefined() ? text(root["description"], "description") : "";
  readParameters(root);
  scene.parameters = params_;

  BaseType base = BaseType::Fixed;
  const YAML::Node base_node = root["base"];
  if (base_node.IsDefined()) {
    try {
      base = dynamics::parseBaseType(text(base_node, "base"));
    } catch (const std::invalid_argument& e) {
      fail(base_node, "base", e.what());
    }
  }
  const Eigen::Vector3d gravity = vec3(root, "", "gravity", Eigen::Vector3d(0, 0, -9.81));
  scene.model = readModel(required(root, "", "model"), base, gravity, base_node);

  const YAML::Node initial = root["initial"];
  const bool has_initial = initial.IsDefined() && !initial.IsNull();
  if (initial.IsDefined()) checkMap(initial, "initial", {"q", "v"}, true);
  scene.q0 = readCoordinateMap(has_initial ? initial["q"] : YAML::Node(), "initial.q", scene.model);
  scene.v0 = readCoordinateMap(has_initial ? initial["v"] : YAML::Node(), "initial.v", scene.model);
  scene.tau = readCoordinateMap(root["input"], "input", scene.model);

  scene.surfaces = readSurfaces(root["surfaces"]);
  scene.contacts = readContacts(root["contacts"], scene);
  scene.limits = readLimits(root, scene.model);
  scene.duration = number(root, "", "duration", scene.duration);
  if (!(scene.duration > 0)) fail(root["duration"], "duration", "duration must be positive, got " + fmt(scene.duration));
  return scene;
}

bool looksLikePath(const std::string& s) {
  auto ends = [&](const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return s.find('/') != std::string::npos || ends(".yaml") || ends(".yml");
}

}  // namespace

std::string scenesDirectory() {
  if (const char* env = std::getenv("SALTUS_SCENES_DIR"); env && *env) return env;
  return std::string(SALTUS_SOURCE_DIR) + "/models/scenes";
}

std::vector<std::string> builtinSceneNames() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(scenesDirectory(), ec))
    if (entry.is_regular_file() && entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

Scene loadScene(const std::string& name_or_path, const std::map<std::string, double>& overrides) {
  std::string path = name_or_path, source = name_or_path;
  if (!looksLikePath(name_or_path)) {
    const std::vector<std::string> names = builtinSceneNames();
    if (std::find(names.begin(), names.end(), name_or_path) == names.end())
      throw ScenarioError("unknown built-in scene '" + name_or_path + "'" + suggestion(name_or_path, names) +
                          "; built-in scenes (" + scenesDirectory() + "): " + joinNames(names) +
                          "; or give the path of a scenario file (.yaml)");
    path = scenesDirectory() + "/" + name_or_path + ".yaml";
    source = "builtin:" + name_or_path;
  }
  YAML::Node root;
  try {
    if (!fs::is_regular_file(path)) throw ScenarioError(path + ": cannot open the scenario file: no such file");
    root = YAML::LoadFile(path);
  } catch (const YAML::ParserException& e) {
    throw ScenarioError(location(path, e.mark) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::BadFile&) {
    throw ScenarioError(path + ": cannot open the scenario file");
  }
  try {
    Scene scene = Loader(path, overrides).load(root);
    scene.source = source;
    return scene;
  } catch (const YAML::Exception& e) {  // not expected: every node is type-checked before use
    throw ScenarioError(location(path, e.mark) + ": " + e.msg);
  } catch (const dynamics::ModelError& e) {  // e.g. a builder model the checks above let through
    throw ScenarioError(path + ": model: " + e.what());
  }
}

std::map<std::string, double> parseOverrides(const std::vector<std::string>& assignments) {
  std::map<std::string, double> out;
  mu::Parser parser;
  setupParser(parser);
  auto trim = [](std::string s) {
    const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  for (const std::string& a : assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos)
      throw ScenarioError("--set '" + a + "': expected name=value, e.g. --set height=2");
    const std::string name = trim(a.substr(0, eq)), value = trim(a.substr(eq + 1));
    if (!isIdentifier(name))
      throw ScenarioError("--set '" + a + "': '" + name + "' is not a parameter name (letters, digits, '_')");
    double x;
    if (!plainNumber(value, x)) {
      const std::string bad = checkExpressionText(value);
      if (!bad.empty()) throw ScenarioError("--set '" + a + "': bad value '" + value + "': " + bad);
      try {
        parser.SetExpr(value);
        x = parser.Eval();
      } catch (const mu::Parser::exception_type& e) {
        throw ScenarioError("--set '" + a + "': bad value '" + value + "': " + e.GetMsg() +
                            " (a number or a constant expression such as pi/4)");
      }
      if (!std::isfinite(x)) throw ScenarioError("--set '" + a + "': value evaluates to " + fmt(x));
    }
    out[name] = x;
  }
  return out;
}

}  // namespace saltus::timestepper
