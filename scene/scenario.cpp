#include "scene/scenario.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <numbers>
#include <set>
#include <sstream>

#include "dynamics/configuration.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/urdf.hpp"
#include "scene/model_section.hpp"
#include "saltus/build_paths.hpp"

namespace saltus::scene {

namespace fs = std::filesystem;
using dynamics::BaseType;
using dynamics::Model;

namespace {

// Reads the scene keys of a scenario (or problem) file through a YamlReader, which holds the
// file's parameters.
class Loader {
 public:
  explicit Loader(YamlReader& reader) : r_(reader) {}

  Scene load(const YAML::Node& root, const std::vector<std::string>& extra_keys);

 private:
  Eigen::VectorXd readInitialConfiguration(const YAML::Node& node, const Model<double>& model);
  Eigen::VectorXd readCoordinateMap(const YAML::Node& node, const std::string& path,
                                    const Model<double>& model);
  int coordinate(const YAML::Node& name_node, const std::string& path, const Model<double>& model) const;
  std::vector<Surface> readSurfaces(const YAML::Node& node);
  std::vector<Contact> readContacts(const YAML::Node& node, const Scene& scene);
  BodyPlane readBodyPlane(const YAML::Node& node, const std::string& path, const Scene& scene,
                          const std::vector<std::string>& frame_names);
  std::vector<LimitStop> readLimits(const YAML::Node& root, const Model<double>& model);

  YamlReader& r_;
};


int Loader::coordinate(const YAML::Node& name_node, const std::string& path, const Model<double>& model) const {
  const std::string name = r_.text(name_node, path);
  const int i = model.coordinateIndex(name);
  if (i < 0)
    r_.fail(name_node, path, "unknown coordinate '" + name + "'" + suggestion(name, model.coordinate_name) +
                              "; the model's coordinates are: " + joinNames(model.coordinate_name));
  return i;
}

Eigen::VectorXd Loader::readCoordinateMap(const YAML::Node& node, const std::string& path,
                                          const Model<double>& model) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(model.nv());
  if (!node.IsDefined()) return x;
  r_.checkNameMap(node, path);
  if (node.IsNull()) return x;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string p = keyPath(path, it->first.Scalar());
    const int k = coordinate(it->first, p, model);
    x[k] = r_.number(it->second, p);
    const double limit = path == "initial.q" ? kMaxPosition : kMaxRate;
    if (std::abs(x[k]) > limit)
      r_.fail(it->second, p, "expected at most " + fmt(limit) + " in magnitude (" +
                                 (path == "initial.q" ? std::string(model.isTranslation(k) ? "m" : "rad")
                                  : path == "initial.v" ? std::string(model.isTranslation(k) ? "m/s" : "rad/s")
                                                        : std::string(model.isTranslation(k) ? "N" : "N m")) +
                                 "), got " + fmt(x[k]));
  }
  return x;
}

// initial.q of a quaternion base: its position coordinates by name (base_x, ..., base_qw, base_qx,
// base_qy, base_qz, joints), or the orientation as base_yaw, base_pitch, base_roll (R = Rz(ψ)
// Ry(θ) Rx(φ), as the Euler base), not both. A quaternion given in part has its other
// components 0 and must be of unit length within 1e-3 (rounded values such as 0.7071 are
// normalised); none given is the identity. Other bases: readCoordinateMap.
Eigen::VectorXd Loader::readInitialConfiguration(const YAML::Node& node, const Model<double>& model) {
  if (model.base != BaseType::FreeQuaternion) return readCoordinateMap(node, "initial.q", model);
  Eigen::VectorXd q = dynamics::neutralConfiguration(model);
  if (!node.IsDefined()) return q;
  r_.checkNameMap(node, "initial.q");
  if (node.IsNull()) return q;
  const std::vector<std::string> euler{"base_yaw", "base_pitch", "base_roll"};
  std::vector<std::string> accepted = model.position_name;
  accepted.insert(accepted.end(), euler.begin(), euler.end());
  Eigen::Vector3d angles = Eigen::Vector3d::Zero();
  Eigen::Vector4d quaternion = Eigen::Vector4d::Zero();
  YAML::Node quaternion_node, euler_node;
  bool has_quaternion = false, has_euler = false;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string name = r_.text(it->first, "initial.q");
    const std::string p = keyPath("initial.q", name);
    const double x = r_.number(it->second, p);
    if (std::abs(x) > kMaxPosition)
      r_.fail(it->second, p, "expected at most " + fmt(kMaxPosition) + " in magnitude, got " + fmt(x));
    const auto e = std::find(euler.begin(), euler.end(), name);
    const int k = model.positionIndex(name);
    if (e != euler.end()) {
      angles[e - euler.begin()] = x;
      euler_node = it->first;
      has_euler = true;
    } else if (k >= 3 && k < 7) {
      quaternion[k - 3] = x;
      quaternion_node = it->first;
      has_quaternion = true;
    } else if (k >= 0) {
      q[k] = x;
    } else {
      r_.fail(it->first, p, "unknown coordinate '" + name + "'" + suggestion(name, accepted) +
                                "; the model's position coordinates are: " + joinNames(accepted));
    }
  }
  if (has_euler && has_quaternion)
    r_.fail(euler_node, "initial.q", "give the base orientation either as a quaternion (base_qw, base_qx, base_qy, "
                                     "base_qz) or as base_yaw, base_pitch, base_roll, not both");
  if (has_quaternion) {
    const double norm = quaternion.norm();
    if (!(std::abs(norm - 1.0) <= 1e-3))
      r_.fail(quaternion_node, "initial.q", "the base quaternion (base_qw, base_qx, base_qy, base_qz) = " +
                                                ("(" + fmt(quaternion[0]) + ", " + fmt(quaternion[1]) + ", " + fmt(quaternion[2]) + ", " + fmt(quaternion[3]) + ")") + " must have unit length (within 1e-3), got " + fmt(norm));
    q.segment<4>(3) = quaternion / norm;
  } else if (has_euler) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(angles[0], Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(angles[1], Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(angles[2], Eigen::Vector3d::UnitX())).toRotationMatrix();
    q.segment<4>(3) = dynamics::rotationToQuaternion(R);
  }
  return q;
}

std::vector<Surface> Loader::readSurfaces(const YAML::Node& node) {
  std::vector<Surface> surfaces;
  if (!node.IsDefined()) return surfaces;
  r_.checkSequence(node, "surfaces");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node s = node[i];
    const std::string p = indexPath("surfaces", i);
    r_.checkMap(s, p, {"name", "point", "normal", "velocity_schedule"});
    Surface surf;
    surf.name = r_.text(r_.required(s, p, "name"), keyPath(p, "name"));
    for (const Surface& other : surfaces)
      if (other.name == surf.name) r_.fail(s["name"], keyPath(p, "name"), "surface '" + surf.name + "' is defined twice");
    surf.point = r_.vec3(s, p, "point", Eigen::Vector3d::Zero());
    const Eigen::Vector3d n = r_.vec3(s, p, "normal", Eigen::Vector3d::UnitZ());
    if (!(n.norm() > 1e-12)) r_.fail(s["normal"], keyPath(p, "normal"), "the normal must be a non-zero vector, got " + fmt(n));
    surf.normal = n.normalized();
    const YAML::Node sched = s["velocity_schedule"];
    const std::string sp = keyPath(p, "velocity_schedule");
    if (sched.IsDefined()) {
      r_.checkSequence(sched, sp);
      for (std::size_t j = 0; j < sched.size(); ++j) {
        const YAML::Node st = sched[j];
        const std::string stp = indexPath(sp, j);
        r_.checkMap(st, stp, {"time", "velocity"});
        Surface::Step step;
        step.time = r_.number(r_.required(st, stp, "time"), keyPath(stp, "time"));
        step.velocity = r_.vec3(r_.required(st, stp, "velocity"), keyPath(stp, "velocity"));
        if (!surf.velocity_schedule.empty() && !(step.time > surf.velocity_schedule.back().time))
          r_.fail(st["time"], keyPath(stp, "time"),
               "times must increase along the schedule: " + fmt(step.time) + " follows " +
                   fmt(surf.velocity_schedule.back().time));
        const double vn = surf.normal.dot(step.velocity);
        if (std::abs(vn) > 1e-9 * std::max(1.0, step.velocity.norm()))
          r_.fail(st["velocity"], keyPath(stp, "velocity"),
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
  if (model.base == BaseType::Free || model.base == BaseType::FreeQuaternion) return false;
  dynamics::Data<double> data(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nv());
  dynamics::forwardKinematics(model, data, q);
  for (int i = 0; i < model.nbodies(); ++i) {  // a fixed base: one-coordinate joints only
    const Eigen::Vector3d a = dynamics::bodyRotation(data, i) * model.axis[i];
    const bool ok = model.joint_type[i] == dynamics::JointType::Revolute ? a.cross(Eigen::Vector3d::UnitY()).norm() < 1e-12
                                                                         : std::abs(a.y()) < 1e-12;
    if (!ok) return false;
  }
  return true;
}

BodyPlane Loader::readBodyPlane(const YAML::Node& node, const std::string& path, const Scene& scene,
                                const std::vector<std::string>& frame_names) {
  r_.checkMap(node, path, {"link", "point", "normal", "extent"});
  BodyPlane plane;
  const YAML::Node link = r_.required(node, path, "link");
  plane.link = r_.text(link, keyPath(path, "link"));
  const int f = scene.model.frameIndex(plane.link);
  if (f < 0)
    r_.fail(link, keyPath(path, "link"), "unknown link '" + plane.link + "'" + suggestion(plane.link, frame_names) +
                                             "; the model's links are: " + joinNames(frame_names));
  const dynamics::Frame& frame = scene.model.frames[f];
  if (frame.body < 0)
    r_.fail(link, keyPath(path, "link"), "link '" + plane.link + "' is fixed to the world: give the plane as a surface");
  plane.body = frame.body;
  const Eigen::Vector3d n = r_.vec3(node, path, "normal", Eigen::Vector3d::UnitZ());
  if (!(n.norm() > 1e-12))
    r_.fail(node["normal"], keyPath(path, "normal"), "the normal must be a non-zero vector, got " + fmt(n));
  plane.normal = frame.R_BF * n.normalized();
  plane.tangents = frame.R_BF * planeTangents(n.normalized());
  plane.point = frame.R_BF * r_.vec3(node, path, "point", Eigen::Vector3d::Zero()) + frame.p_BF;
  const YAML::Node extent = r_.required(node, path, "extent");
  plane.extent = r_.vector(extent, keyPath(path, "extent"), 2);
  if (!(plane.extent.minCoeff() > 0))
    r_.fail(extent, keyPath(path, "extent"),
            "the half-lengths along the plane's two tangents must be positive, got [" + fmt(plane.extent[0]) + ", " +
                fmt(plane.extent[1]) + "] m");
  return plane;
}

std::vector<Contact> Loader::readContacts(const YAML::Node& node, const Scene& scene) {
  std::vector<Contact> contacts;
  if (!node.IsDefined()) return contacts;
  r_.checkSequence(node, "contacts");
  const bool planar = isPlanar(scene.model);
  std::vector<std::string> surface_names, frame_names;
  for (const Surface& s : scene.surfaces) surface_names.push_back(s.name);
  for (const dynamics::Frame& f : scene.model.frames) frame_names.push_back(f.name);
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node c = node[i];
    const std::string p = indexPath("contacts", i);
    r_.checkMap(c, p, {"name", "link", "point", "surface", "plane", "free_point", "restitution", "friction", "directions"});
    Contact ct;
    const YAML::Node link = r_.required(c, p, "link");
    ct.link = r_.text(link, keyPath(p, "link"));
    ct.name = c["name"].IsDefined() ? r_.text(c["name"], keyPath(p, "name")) : ct.link;
    for (const Contact& other : contacts)
      if (other.name == ct.name)
        r_.fail(c["name"].IsDefined() ? c["name"] : c, keyPath(p, "name"),
             "contact name '" + ct.name + "' is used twice (give each contact a distinct name)");
    const int f = scene.model.frameIndex(ct.link);
    if (f < 0)
      r_.fail(link, keyPath(p, "link"), "unknown link '" + ct.link + "'" + suggestion(ct.link, frame_names) +
                                          "; the model's links are: " + joinNames(frame_names));
    const dynamics::Frame& frame = scene.model.frames[f];
    if (frame.body < 0) r_.fail(link, keyPath(p, "link"), "link '" + ct.link + "' is fixed to the world and cannot touch a surface");
    ct.body = frame.body;
    const Eigen::Vector3d point = r_.vec3(c, p, "point", Eigen::Vector3d::Zero());
    ct.p_B = frame.R_BF * point + frame.p_BF;
    // Exactly one of: a world surface, or a plane on another body.
    if (!c["surface"].IsDefined() && !c["plane"].IsDefined())
      r_.fail(c, keyPath(p, "surface"),
              "missing required key 'surface' (a world surface by name), or 'plane' (a plane on another body)");
    if (c["surface"].IsDefined() && c["plane"].IsDefined())
      r_.fail(c["plane"], keyPath(p, "plane"), "a contact touches either a world surface or a plane on a body: give "
                                               "'surface' or 'plane', not both");
    if (c["surface"].IsDefined()) {
      const YAML::Node surf = c["surface"];
      const std::string sname = r_.text(surf, keyPath(p, "surface"));
      const auto s = std::find(surface_names.begin(), surface_names.end(), sname);
      if (s == surface_names.end())
        r_.fail(surf, keyPath(p, "surface"), "unknown surface '" + sname + "'" + suggestion(sname, surface_names) +
                                              "; the scene's surfaces are: " + joinNames(surface_names));
      ct.surface = static_cast<int>(s - surface_names.begin());
    } else {
      ct.surface = -1;
      ct.plane = readBodyPlane(c["plane"], keyPath(p, "plane"), scene, frame_names);
      if (ct.plane.body == ct.body)
        r_.fail(c["plane"], keyPath(p, "plane"), "the plane is on the same body as the point (link '" +
                                                    ct.plane.link + "'): a body cannot touch itself");
    }
    if (c["free_point"].IsDefined() && r_.boolean(c["free_point"], keyPath(p, "free_point"))) {
      if (ct.surface >= 0)
        r_.fail(c["free_point"], keyPath(p, "free_point"),
                "a contact point free along its plane needs a plane on a body ('plane'): on a world surface, "
                "which is unbounded, the contact point is wherever the point is");
      for (int axis = 0; axis < 2; ++axis)  // t2 is the normal to the plane of motion: no motion along it
        if (!(planar && std::abs(ct.plane.tangents(1, axis)) > 1 - 1e-9)) ct.free_axes.push_back(axis);
    }
    ct.restitution = r_.number(c, p, "restitution", 0.0);
    if (!(ct.restitution >= 0 && ct.restitution <= 1))
      r_.fail(c["restitution"], keyPath(p, "restitution"), "restitution must be in [0, 1], got " + fmt(ct.restitution));
    ct.friction = r_.number(c, p, "friction", 0.0);
    if (!(ct.friction >= 0))
      r_.fail(c["friction"], keyPath(p, "friction"), "friction must be non-negative, got " + fmt(ct.friction));
    if (c["directions"].IsDefined()) {
      ct.directions = r_.integer(c["directions"], keyPath(p, "directions"));
      if (ct.friction > 0 && ct.directions < 2)
        r_.fail(c["directions"], keyPath(p, "directions"),
             "a friction cone needs at least 2 directions (2 for planar motion, 4 or more in space), got " +
                 std::to_string(ct.directions));
      if (ct.directions < 0) r_.fail(c["directions"], keyPath(p, "directions"), "directions must be non-negative");
      if (ct.directions > kMaxDirections)
        r_.fail(c["directions"], keyPath(p, "directions"),
                "expected at most " + std::to_string(kMaxDirections) + " directions (a cone of 64 is within 0.12 % of "
                "the circular one), got " + std::to_string(ct.directions));
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
  const double e = r_.number(root, "", "limit_restitution", 0.0);
  if (!(e >= 0 && e <= 1))
    r_.fail(root["limit_restitution"], "limit_restitution", "restitution must be in [0, 1], got " + fmt(e));
  auto add = [&](int i) {
    const dynamics::JointLimits& l = model.limits[i];
    if (l.lower > -dynamics::kInf) stops.push_back({model.coordinate_name[i] + "_lower", i, false, l.lower, e});
    if (l.upper < dynamics::kInf) stops.push_back({model.coordinate_name[i] + "_upper", i, true, l.upper, e});
  };
  if (!node.IsDefined()) return stops;
  if (node.IsScalar()) {
    if (r_.boolean(node, "joint_limits"))
      for (int i = 0; i < model.nv(); ++i) add(i);
    return stops;
  }
  if (!node.IsSequence())
    r_.fail(node, "joint_limits", "expected true, false or a list of coordinate names, got " + describe(node));
  std::set<int> seen;
  for (std::size_t j = 0; j < node.size(); ++j) {
    const std::string p = indexPath("joint_limits", j);
    const int i = coordinate(node[j], p, model);
    if (!model.limits[i].hasPositionLimits())
      r_.fail(node[j], p, "coordinate '" + model.coordinate_name[i] + "' has no finite position limit");
    if (!seen.insert(i).second) r_.fail(node[j], p, "coordinate '" + model.coordinate_name[i] + "' is listed twice");
    add(i);
  }
  return stops;
}

Scene Loader::load(const YAML::Node& root, const std::vector<std::string>& extra_keys) {
  if (!root.IsMap()) r_.fail(root, "", "a scenario file must be a map of keys (name, model, surfaces, ...), got " + describe(root));
  std::vector<std::string> keys = {"name", "description", "parameters", "model", "base", "gravity", "initial",
                                   "input", "surfaces", "contacts", "joint_limits", "limit_restitution", "duration"};
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  r_.checkMap(root, "", keys);
  Scene scene;
  scene.name = root["name"].IsDefined() ? r_.text(root["name"], "name") : fs::path(r_.file()).stem().string();
  scene.description = root["description"].IsDefined() ? r_.text(root["description"], "description") : "";
  scene.parameters = r_.parameters();

  BaseType base = BaseType::Fixed;
  const YAML::Node base_node = root["base"];
  if (base_node.IsDefined()) {
    try {
      base = dynamics::parseBaseType(r_.text(base_node, "base"));
    } catch (const std::invalid_argument& e) {
      r_.fail(base_node, "base", e.what());
    }
  }
  const Eigen::Vector3d gravity = r_.vec3(root, "", "gravity", Eigen::Vector3d(0, 0, -9.81));
  // Plausibility limits (README, "Scenario files"): far beyond any robot, short of where products
  // of the values overflow or swamp the solvers' tolerances.
  if (gravity.stableNorm() > kMaxGravity)
    r_.fail(root["gravity"], "gravity", "expected an acceleration of at most " + fmt(kMaxGravity) +
                                            " m/s^2 in magnitude (about 100 g), got " + fmt(gravity) + " (magnitude " +
                                            fmt(gravity.stableNorm()) + ")");
  ModelSection section = readModelSection(r_, r_.required(root, "", "model"), base, gravity, base_node);
  scene.model = std::move(section.model);
  scene.model_files = std::move(section.urdf_files);

  const YAML::Node initial = root["initial"];
  const bool has_initial = initial.IsDefined() && !initial.IsNull();
  if (initial.IsDefined()) r_.checkMap(initial, "initial", {"q", "v"}, true);
  scene.q0 = readInitialConfiguration(has_initial ? initial["q"] : YAML::Node(), scene.model);
  scene.v0 = readCoordinateMap(has_initial ? initial["v"] : YAML::Node(), "initial.v", scene.model);
  scene.initial_location = has_initial ? location(r_.file(), initial.Mark()) + ": initial"
                                       : r_.file() + ": initial state (every coordinate 0)";
  scene.tau = readCoordinateMap(root["input"], "input", scene.model);

  scene.surfaces = readSurfaces(root["surfaces"]);
  scene.contacts = readContacts(root["contacts"], scene);
  scene.limits = readLimits(root, scene.model);
  scene.duration = r_.number(root, "", "duration", scene.duration);
  if (!(scene.duration > 0)) r_.fail(root["duration"], "duration", "duration must be positive, got " + fmt(scene.duration));
  return scene;
}

}  // namespace

std::string dataDirectory() {
  std::error_code ec;
  if (fs::is_directory(std::string(SALTUS_SOURCE_DIR) + "/models", ec)) return SALTUS_SOURCE_DIR;
  return SALTUS_INSTALL_DATA_DIR;
}

std::string scenesDirectory() {
  if (const char* env = std::getenv("SALTUS_SCENES_DIR"); env && *env) return env;
  return dataDirectory() + "/models/scenes";
}

std::vector<std::string> builtinSceneNames() {
  return yamlFileNames(scenesDirectory());
}

Scene loadScene(const std::string& name_or_path, const std::map<std::string, double>& overrides) {
  const auto [path, source] = resolveYamlFile(name_or_path, scenesDirectory(), "scene", "scenario file");
  const YAML::Node root = loadYamlFile(path);
  YamlReader reader(path, overrides);
  if (root.IsMap()) reader.readParameters(root);
  Scene scene = readScene(reader, root);
  scene.source = source;
  return scene;
}

Scene readScene(YamlReader& reader, const YAML::Node& root, const std::vector<std::string>& extra_keys) {
  try {
    return Loader(reader).load(root, extra_keys);
  } catch (const YAML::Exception& e) {  // not expected: every node is type-checked before use
    throw ScenarioError(location(reader.file(), e.mark) + ": " + e.msg);
  } catch (const dynamics::ModelError& e) {  // e.g. a builder model the checks above let through
    throw ScenarioError(reader.file() + ": model: " + e.what());
  }
}

}  // namespace saltus::scene
