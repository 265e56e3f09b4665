#include "scene/model_section.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "dynamics/builder.hpp"
#include "dynamics/urdf.hpp"

namespace saltus::scene {

namespace fs = std::filesystem;
using dynamics::BaseType;
using dynamics::Model;

namespace {

// R = Rz(yaw) Ry(pitch) Rx(roll), the URDF rpy convention.
Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

const std::string kModelKinds = "urdf, point_mass, point_masses, rigid_body, parts";
const std::string kPartKinds = "urdf, point_mass, rigid_body";

class ModelReader {
 public:
  explicit ModelReader(YamlReader& reader) : r_(reader) {}

  ModelSection read(const YAML::Node& node, BaseType base, const Eigen::Vector3d& gravity, const YAML::Node& base_node);

 private:
  std::vector<dynamics::Visual> readVisuals(const YAML::Node& node, const std::string& path, const std::string& link,
                                            int body);
  // One point mass on a chain of prismatic coordinates from the world link, added to `b`;
  // `names` holds the links and coordinates so far ("link x", "coordinate y").
  void addPointMass(dynamics::ModelBuilder& b, const YAML::Node& node, const std::string& path,
                    std::set<std::string>& names);
  // One point mass (a map) or several (a list), each on its own axes from the world.
  Model<double> readPointMasses(const YAML::Node& node, const std::string& path, BaseType base,
                                const Eigen::Vector3d& gravity, const YAML::Node& base_node);
  dynamics::LinkSpec readRigidBodyLink(const YAML::Node& node, const std::string& path, const std::string& default_link);
  Model<double> readRigidBody(const YAML::Node& node, const std::string& path, BaseType base,
                              const Eigen::Vector3d& gravity, const YAML::Node& base_node);
  // The URDF file `node` names, relative to the file's folder.
  std::string urdfPath(const YAML::Node& node, const std::string& path) const;
  ModelSection readParts(const YAML::Node& node, const std::string& path, const Eigen::Vector3d& gravity);
  // Part `node` (a URDF or a rigid body) with its base chain, added to `b`.
  void addPart(dynamics::ModelBuilder& b, const YAML::Node& node, const std::string& path, std::set<std::string>& names,
               std::vector<std::string>& urdf_files, const Eigen::Vector3d& gravity);

  YamlReader& r_;
};

std::vector<dynamics::Visual> ModelReader::readVisuals(const YAML::Node& node, const std::string& path,
                                                  const std::string& link, int body) {
  std::vector<dynamics::Visual> visuals;
  if (!node.IsDefined()) return visuals;
  r_.checkSequence(node, path);
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node v = node[i];
    const std::string p = indexPath(path, i);
    r_.checkMap(v, p, {"shape", "size", "xyz", "rpy", "rgba"});
    dynamics::Visual vis;
    vis.link = link;
    vis.body = body;
    const YAML::Node shape = r_.required(v, p, "shape"), size = r_.required(v, p, "size");
    const std::string s = r_.text(shape, keyPath(p, "shape"));
    if (s == "box") {
      vis.shape = dynamics::Visual::Shape::Box;
      vis.size = r_.vec3(size, keyPath(p, "size"));
    } else if (s == "cylinder") {
      vis.shape = dynamics::Visual::Shape::Cylinder;
      const Eigen::VectorXd rl = r_.vector(size, keyPath(p, "size"), 2);
      vis.size = Eigen::Vector3d(rl[0], rl[1], 0);
    } else if (s == "sphere") {
      vis.shape = dynamics::Visual::Shape::Sphere;
      vis.size = Eigen::Vector3d(size.IsSequence() ? r_.vector(size, keyPath(p, "size"), 1)[0]
                                                   : r_.number(size, keyPath(p, "size")),
                                 0, 0);
    } else {
      r_.fail(shape, keyPath(p, "shape"), "unknown shape '" + s + "'; expected one of: box, cylinder, sphere");
    }
    if ((vis.size.array() < 0).any() || vis.size.isZero() || vis.size.maxCoeff() > 1e6)
      r_.fail(size, keyPath(p, "size"), "sizes must be positive and at most 1e6 m, got " + fmt(vis.size));
    vis.p_BG = r_.vec3(v, p, "xyz", Eigen::Vector3d::Zero());
    vis.R_BG = rpyToMatrix(r_.vec3(v, p, "rpy", Eigen::Vector3d::Zero()));
    if (v["rgba"].IsDefined()) vis.rgba = r_.vector(v["rgba"], keyPath(p, "rgba"), 4);
    visuals.push_back(vis);
  }
  return visuals;
}

// A point mass on a chain of prismatic coordinates from the world, one per axis (world axes),
// through massless intermediate links named <link>_<coordinate>; added to `b`.
void ModelReader::addPointMass(dynamics::ModelBuilder& b, const YAML::Node& node, const std::string& path,
                          std::set<std::string>& names) {
  r_.checkMap(node, path, {"mass", "axes", "link", "visuals"});
  const double mass = r_.number(r_.required(node, path, "mass"), keyPath(path, "mass"));
  if (!(mass > 0)) r_.fail(node["mass"], keyPath(path, "mass"), "mass must be positive, got " + fmt(mass));
  const std::string link = node["link"].IsDefined() ? r_.text(node["link"], keyPath(path, "link")) : "mass";
  if (link == "world") r_.fail(node["link"], keyPath(path, "link"), "'world' is the name of the fixed frame");
  if (!names.insert("link " + link).second)
    r_.fail(node["link"].IsDefined() ? node["link"] : node, keyPath(path, "link"),
            "link '" + link + "' is used twice (give every link of the model a distinct name)");
  const YAML::Node axes = r_.required(node, path, "axes");
  const std::string apath = keyPath(path, "axes");
  r_.checkNameMap(axes, apath);
  if (axes.size() == 0 || axes.size() > 3) r_.fail(axes, apath, "expected 1 to 3 coordinates (name: axis)");
  Eigen::Matrix3d span = Eigen::Matrix3d::Zero();
  std::string parent = "world";
  int i = 0;
  for (auto it = axes.begin(); it != axes.end(); ++it, ++i) {
    const std::string name = it->first.Scalar();
    const std::string p = keyPath(apath, name);
    if (!names.insert("joint " + name).second)
      r_.fail(it->first, p, "coordinate '" + name + "' is used twice (give every coordinate of the model a distinct name)");
    const Eigen::Vector3d a = r_.vec3(it->second, p);
    if (!(a.norm() > 1e-12)) r_.fail(it->second, p, "an axis must be a non-zero vector");
    span.col(i) = a.normalized();
    Eigen::FullPivLU<Eigen::Matrix3d> lu(span.leftCols(i + 1) * span.leftCols(i + 1).transpose());
    if (lu.rank() < i + 1)
      r_.fail(it->second, p, "axis " + fmt(a) + " is a combination of the previous axes (the mass matrix would be singular)");
    const bool last = i + 1 == static_cast<int>(axes.size());
    const std::string child = last ? link : link + "_" + name;
    if (!last && !names.insert("link " + child).second)
      r_.fail(it->first, p, "the intermediate link '" + child + "' of this coordinate is already a link of the model");
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
}

Model<double> ModelReader::readPointMasses(const YAML::Node& node, const std::string& path, BaseType base,
                                      const Eigen::Vector3d& gravity, const YAML::Node& base_node) {
  if (base != BaseType::Fixed)
    r_.fail(base_node, "base", "point masses move along their own axes from the world: base must be fixed");
  dynamics::ModelBuilder b(node.IsSequence() ? "point_masses" : "point_mass");
  b.setSource(r_.file());
  b.addLink("world");
  std::set<std::string> names;  // links and coordinates so far
  if (node.IsSequence()) {
    if (node.size() == 0) r_.fail(node, path, "expected a list of at least one point mass");
    for (std::size_t i = 0; i < node.size(); ++i) addPointMass(b, node[i], indexPath(path, i), names);
  } else {
    addPointMass(b, node, path, names);
  }
  try {
    return b.build(BaseType::Fixed, gravity);
  } catch (const dynamics::ModelError& e) {  // e.g. a link name clashing with an intermediate link
    r_.fail(node, path, e.what());
  }
}

// The link of a `rigid_body` (named `link:`, else `default_link`) with its inertia and visuals.
dynamics::LinkSpec ModelReader::readRigidBodyLink(const YAML::Node& node, const std::string& path,
                                                  const std::string& default_link) {
  r_.checkMap(node, path, {"mass", "com", "inertia", "link", "visuals"});
  const double mass = r_.number(r_.required(node, path, "mass"), keyPath(path, "mass"));
  const Eigen::Vector3d com = r_.vec3(node, path, "com", Eigen::Vector3d::Zero());
  const std::string link = node["link"].IsDefined() ? r_.text(node["link"], keyPath(path, "link")) : default_link;
  if (link == "world")
    r_.fail(node["link"].IsDefined() ? node["link"] : node, keyPath(path, "link"), "'world' is the name of the fixed frame");
  const YAML::Node in = r_.required(node, path, "inertia");
  const std::string ipath = keyPath(path, "inertia");
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  if (in.IsSequence() && in.size() == 3 && in[0].IsScalar()) {
    I.diagonal() = r_.vec3(in, ipath);
  } else if (in.IsSequence() && in.size() == 3) {
    for (int r = 0; r < 3; ++r) I.row(r) = r_.vec3(in[r], indexPath(ipath, r)).transpose();
  } else {
    r_.fail(in, ipath, "expected the principal moments [Ixx, Iyy, Izz] or a 3x3 matrix [[...], [...], [...]], got " +
                        (in.IsSequence() ? "a sequence of " + std::to_string(in.size()) : describe(in)));
  }
  const std::string why = dynamics::checkInertia(mass, I, false);
  if (!why.empty()) r_.fail(in, ipath, why);
  dynamics::LinkSpec spec;
  spec.name = link;
  spec.has_inertial = true;
  spec.mass = mass;
  spec.com = com;
  spec.inertia_com = I;
  spec.visuals = readVisuals(node["visuals"], keyPath(path, "visuals"), link, -1);
  return spec;
}

Model<double> ModelReader::readRigidBody(const YAML::Node& node, const std::string& path, BaseType base,
                                         const Eigen::Vector3d& gravity, const YAML::Node& base_node) {
  if (base == BaseType::Fixed)
    r_.fail(base_node.IsDefined() ? base_node : node, "base",
            "a rigid_body model needs a moving base: base must be planar or free");
  dynamics::ModelBuilder b("rigid_body");
  b.setSource(r_.file());
  b.addLink(readRigidBodyLink(node, path, "body"));
  try {
    return b.build(base, gravity);
  } catch (const dynamics::ModelError& e) {
    r_.fail(node, path, e.what());
  }
}

std::string ModelReader::urdfPath(const YAML::Node& node, const std::string& path) const {
  fs::path urdf = r_.text(node, path);
  if (urdf.is_relative()) urdf = fs::path(r_.file()).parent_path() / urdf;
  return urdf.lexically_normal().string();
}

void ModelReader::addPart(dynamics::ModelBuilder& b, const YAML::Node& node, const std::string& path,
                          std::set<std::string>& names, std::vector<std::string>& urdf_files,
                          const Eigen::Vector3d& gravity) {
  const YAML::Node name_node = r_.required(node, path, "name");
  const std::string part = r_.text(name_node, keyPath(path, "name"));
  if (!isIdentifier(part))
    r_.fail(name_node, keyPath(path, "name"), "a part's name prefixes its base coordinates: expected letters, digits and '_', got '" + part + "'");
  BaseType base = BaseType::Fixed;
  const YAML::Node base_node = node["base"];
  if (base_node.IsDefined()) {
    try {
      base = dynamics::parseBaseType(r_.text(base_node, keyPath(path, "base")));
    } catch (const std::invalid_argument& e) {
      r_.fail(base_node, keyPath(path, "base"), e.what());
    }
  }
  if (base == BaseType::FreeQuaternion)
    r_.fail(base_node, keyPath(path, "base"),
            "a part's base is a chain of one-coordinate joints from the world, which a quaternion cannot be: "
            "expected fixed, planar or free (Euler angles)");

  // The part alone, as a model of its own: its errors name the part, and its links and joints
  // are then known to make a tree.
  dynamics::ModelBuilder alone("part");
  if (node["urdf"].IsDefined()) {
    const std::string file = urdfPath(node["urdf"], keyPath(path, "urdf"));
    try {
      alone = dynamics::readUrdfFile(file);
      alone.build(base, gravity);
    } catch (const dynamics::ModelError& e) {
      r_.fail(node["urdf"], keyPath(path, "urdf"), e.what());
    }
    urdf_files.push_back(file);
  } else {
    if (base == BaseType::Fixed)
      r_.fail(base_node.IsDefined() ? base_node : node, keyPath(path, "base"),
              "a rigid_body part needs a moving base: base must be planar or free");
    alone.addLink(readRigidBodyLink(node["rigid_body"], keyPath(path, "rigid_body"), part));
  }
  // The root link: the one that is no joint's child.
  std::set<std::string> children;
  for (const auto& j : alone.joints()) children.insert(j.child);
  std::string root;
  for (const auto& l : alone.links())
    if (!children.count(l.name)) root = l.name;

  const YAML::Node body_node = node["urdf"].IsDefined() ? node["urdf"] : node["rigid_body"];
  const std::string body_path = keyPath(path, node["urdf"].IsDefined() ? "urdf" : "rigid_body");
  if (root == "world" && base != BaseType::Fixed)
    r_.fail(base_node, keyPath(path, "base"), "the URDF's root link is 'world', fixed to the world: its part takes base fixed");
  auto claim = [&](const std::string& kind, const std::string& name) {
    if (name == "world" && kind == "link")
      r_.fail(body_node, body_path, "part '" + part + "' has a link named 'world', the name of the fixed frame");
    if (!names.insert(kind + " " + name).second)
      r_.fail(body_node, body_path, kind + " '" + name + "' of part '" + part +
                                        "' is already in the model (an earlier part, or this part's base "
                                        "coordinates <part>_x ...): links and joints need distinct names");
  };
  // The base: the world's axes, as dynamics::ModelBuilder's multi-coordinate base joints.
  struct Axis {
    const char* suffix;
    dynamics::LinkJointType type;
    Eigen::Vector3d axis;
  };
  std::vector<Axis> chain;
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(), Z = Eigen::Vector3d::UnitZ();
  using T = dynamics::LinkJointType;
  if (base == BaseType::Planar) chain = {{"x", T::Prismatic, X}, {"z", T::Prismatic, Z}, {"theta", T::Continuous, Y}};
  if (base == BaseType::Free)
    chain = {{"x", T::Prismatic, X}, {"y", T::Prismatic, Y},       {"z", T::Prismatic, Z},
             {"yaw", T::Continuous, Z}, {"pitch", T::Continuous, Y}, {"roll", T::Continuous, X}};
  std::string parent = "world";
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const std::string coordinate = part + "_" + chain[i].suffix;
    const bool last = i + 1 == chain.size();
    const std::string child = last ? root : coordinate;
    if (!last) {
      claim("link", child);
      b.addLink(child);
    }
    claim("joint", coordinate);
    dynamics::JointSpec j;
    j.name = coordinate;
    j.type = chain[i].type;
    j.parent = parent;
    j.child = child;
    j.axis = chain[i].axis;
    b.addJoint(j);
    parent = child;
  }
  // A fixed part's root is welded to the world, unless it is the URDF's own "world" link.
  const bool own_world = base == BaseType::Fixed && root == "world";
  if (base == BaseType::Fixed && !own_world) {
    dynamics::JointSpec weld;
    weld.name = part + "_fixed";
    weld.type = T::Fixed;
    weld.parent = "world";
    weld.child = root;
    claim("joint", weld.name);
    b.addJoint(weld);
  }
  const fs::path folder = node["urdf"].IsDefined() ? fs::path(urdfPath(node["urdf"], keyPath(path, "urdf"))).parent_path() : fs::path();
  for (dynamics::LinkSpec l : alone.links()) {
    if (own_world && l.name == "world") continue;
    claim("link", l.name);
    // A mesh path relative to the URDF's folder, made absolute: the model's source is the scene file.
    for (dynamics::Visual& v : l.visuals)
      if (!v.mesh_file.empty() && v.mesh_file.find("://") == std::string::npos && fs::path(v.mesh_file).is_relative())
        v.mesh_file = (folder / v.mesh_file).lexically_normal().string();
    b.addLink(l);
  }
  for (const auto& j : alone.joints()) {
    claim("joint", j.name);
    b.addJoint(j);
  }
}

ModelSection ModelReader::readParts(const YAML::Node& node, const std::string& path, const Eigen::Vector3d& gravity) {
  r_.checkSequence(node, path);
  if (node.size() == 0) r_.fail(node, path, "expected a list of at least one part");
  dynamics::ModelBuilder b("parts");
  b.setSource(r_.file());
  b.addLink("world");
  std::set<std::string> names;
  std::set<std::string> part_names;
  ModelSection section;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node part = node[i];
    const std::string p = indexPath(path, i);
    r_.checkMap(part, p, {"name", "base", "urdf", "point_mass", "rigid_body"});
    int kinds = 0;
    for (const char* k : {"urdf", "point_mass", "rigid_body"}) kinds += part[k].IsDefined();
    if (kinds != 1) r_.fail(part, p, "expected exactly one of: " + kPartKinds);
    if (part["name"].IsDefined() && !part_names.insert(r_.text(part["name"], keyPath(p, "name"))).second)
      r_.fail(part["name"], keyPath(p, "name"), "part '" + part["name"].Scalar() + "' is named twice");
    if (part["point_mass"].IsDefined()) {
      // A point mass moves on its own axes from the world: its coordinates are named in `axes`.
      if (part["base"].IsDefined())
        r_.fail(part["base"], keyPath(p, "base"), "a point mass moves along its own axes from the world: it takes no base");
      if (part["name"].IsDefined())
        r_.fail(part["name"], keyPath(p, "name"), "a point mass is named by its link and its coordinates by its axes: it takes no name");
      addPointMass(b, part["point_mass"], keyPath(p, "point_mass"), names);
    } else {
      addPart(b, part, p, names, section.urdf_files, gravity);
    }
  }
  try {
    section.model = b.build(BaseType::Fixed, gravity);
  } catch (const dynamics::ModelError& e) {
    r_.fail(node, path, e.what());
  }
  return section;
}

ModelSection ModelReader::read(const YAML::Node& node, BaseType base, const Eigen::Vector3d& gravity,
                               const YAML::Node& base_node) {
  r_.checkMap(node, "model", {"urdf", "point_mass", "point_masses", "rigid_body", "parts"});
  if (node.size() == 0) r_.fail(node, "model", "expected exactly one of: " + kModelKinds);
  if (node.size() > 1) {
    auto second = std::next(node.begin());
    r_.fail(second->first, keyPath("model", second->first.Scalar()),
            "expected exactly one of: " + kModelKinds + " ('" + node.begin()->first.Scalar() + "' is already given)");
  }
  ModelSection section;
  if (node["parts"].IsDefined()) {
    if (base_node.IsDefined())
      r_.fail(base_node, "base", "a model of parts gives each part its own base (model.parts[i].base), not one for the file");
    return readParts(node["parts"], "model.parts", gravity);
  }
  if (node["point_mass"].IsDefined()) {
    section.model = readPointMasses(node["point_mass"], "model.point_mass", base, gravity, base_node);
  } else if (node["point_masses"].IsDefined()) {
    r_.checkSequence(node["point_masses"], "model.point_masses");
    section.model = readPointMasses(node["point_masses"], "model.point_masses", base, gravity, base_node);
  } else if (node["rigid_body"].IsDefined()) {
    section.model = readRigidBody(node["rigid_body"], "model.rigid_body", base, gravity, base_node);
  } else {
    const std::string urdf = urdfPath(node["urdf"], "model.urdf");
    try {
      section.model = dynamics::readUrdfFile(urdf).build(base, gravity);
    } catch (const dynamics::ModelError& e) {
      r_.fail(node["urdf"], "model.urdf", e.what());
    }
    section.urdf_files.push_back(urdf);
  }
  return section;
}

}  // namespace

ModelSection readModelSection(YamlReader& reader, const YAML::Node& node, BaseType base, const Eigen::Vector3d& gravity,
                              const YAML::Node& base_node) {
  return ModelReader(reader).read(node, base, gravity, base_node);
}

}  // namespace saltus::scene
