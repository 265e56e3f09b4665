#include "render/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <set>

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "dynamics/kinematics.hpp"

namespace saltus::render {

namespace {

constexpr double kPi = std::numbers::pi;

std::uint32_t addVertex(Mesh& m, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  m.vertices.push_back(p.cast<float>());
  m.normals.push_back(n.normalized().cast<float>());
  return static_cast<std::uint32_t>(m.vertices.size() - 1);
}

void addTriangle(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  m.triangles.insert(m.triangles.end(), {a, b, c});
}

// A flat disk cap at height z facing ±z.
void addCap(Mesh& m, int slices, double radius, double z, double facing) {
  const std::uint32_t centre = addVertex(m, {0, 0, z}, {0, 0, facing});
  const std::uint32_t first = static_cast<std::uint32_t>(m.vertices.size());
  for (int i = 0; i <= slices; ++i) {
    const double a = 2 * kPi * i / slices;
    addVertex(m, {radius * std::cos(a), radius * std::sin(a), z}, {0, 0, facing});
  }
  for (int i = 0; i < slices; ++i) {
    if (facing > 0) addTriangle(m, centre, first + i, first + i + 1);
    else addTriangle(m, centre, first + i + 1, first + i);
  }
}

// A surface of revolution about z: rings of (radius, z, normal radial part, normal z part).
struct Ring {
  double r, z, nr, nz;
};
void addRevolution(Mesh& m, int slices, const std::vector<Ring>& rings) {
  const std::uint32_t first = static_cast<std::uint32_t>(m.vertices.size());
  for (const Ring& ring : rings)
    for (int i = 0; i <= slices; ++i) {
      const double a = 2 * kPi * i / slices, c = std::cos(a), s = std::sin(a);
      addVertex(m, {ring.r * c, ring.r * s, ring.z}, {ring.nr * c, ring.nr * s, ring.nz});
    }
  const std::uint32_t row = slices + 1;
  for (std::uint32_t k = 0; k + 1 < rings.size(); ++k)
    for (int i = 0; i < slices; ++i) {
      const std::uint32_t a = first + k * row + i, b = a + 1, c = a + row, d = c + 1;
      addTriangle(m, a, b, d);
      addTriangle(m, a, d, c);
    }
}

}  // namespace

void Mesh::computeBounds() {
  lo = Eigen::Vector3d::Constant(vertices.empty() ? 0 : std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const auto& v : vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
}

Mesh sphereMesh(int slices, int stacks) {
  Mesh m;
  std::vector<Ring> rings;
  for (int j = 0; j <= stacks; ++j) {
    const double phi = -kPi / 2 + kPi * j / stacks;
    rings.push_back({std::cos(phi), std::sin(phi), std::cos(phi), std::sin(phi)});
  }
  addRevolution(m, slices, rings);
  m.computeBounds();
  return m;
}

Mesh cylinderMesh(int slices) {
  Mesh m;
  addRevolution(m, slices, {{1, -0.5, 1, 0}, {1, 0.5, 1, 0}});
  addCap(m, slices, 1, 0.5, 1);
  addCap(m, slices, 1, -0.5, -1);
  m.computeBounds();
  return m;
}

Mesh boxMesh() {
  Mesh m;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      const Eigen::Vector3d n = sign * Eigen::Vector3d::Unit(axis);
      const Eigen::Vector3d u = Eigen::Vector3d::Unit((axis + 1) % 3), w = n.cross(u);
      const std::uint32_t a = addVertex(m, 0.5 * (n - u - w), n), b = addVertex(m, 0.5 * (n + u - w), n),
                          c = addVertex(m, 0.5 * (n + u + w), n), d = addVertex(m, 0.5 * (n - u + w), n);
      addTriangle(m, a, b, c);
      addTriangle(m, a, c, d);
    }
  m.computeBounds();
  return m;
}

Mesh coneMesh(int slices) {
  Mesh m;
  const double k = 1 / std::sqrt(2.0);  // slope 1: normal (1, 1)/√2
  addRevolution(m, slices, {{1, 0, k, k}, {0, 1, k, k}});
  addCap(m, slices, 1, 0, -1);
  m.computeBounds();
  return m;
}

Mesh capsuleMesh(double radius, double length, int slices, int stacks) {
  Mesh m;
  std::vector<Ring> rings;
  for (int j = 0; j <= stacks; ++j) {  // bottom hemisphere, centre z = 0
    const double phi = -kPi / 2 + kPi / 2 * j / stacks;
    rings.push_back({radius * std::cos(phi), radius * std::sin(phi), std::cos(phi), std::sin(phi)});
  }
  for (int j = 0; j <= stacks; ++j) {  // top hemisphere, centre z = length
    const double phi = kPi / 2 * j / stacks;
    rings.push_back({radius * std::cos(phi), length + radius * std::sin(phi), std::cos(phi), std::sin(phi)});
  }
  addRevolution(m, slices, rings);
  m.computeBounds();
  return m;
}

Mesh diskMesh(int slices) {
  Mesh m;
  addCap(m, slices, 1, 0, 1);
  m.computeBounds();
  return m;
}

Eigen::Vector3d beltDirection(const scene::Surface& surface) {
  for (const auto& step : surface.velocity_schedule) {
    const Eigen::Vector3d v = step.velocity - step.velocity.dot(surface.normal) * surface.normal;
    if (v.norm() > 1e-12) return v.normalized();
  }
  return Eigen::Vector3d::Zero();
}

double surfaceTravel(const scene::Surface& surface, const Eigen::Vector3d& direction, double t) {
  return direction.dot(surface.displacement(t));
}

bool loadMeshFile(const std::string& path, Mesh& mesh, std::string* why) {
  const aiScene* scene = aiImportFile(path.c_str(), aiProcess_Triangulate | aiProcess_GenSmoothNormals |
                                                        aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices);
  if (!scene) {
    *why = aiGetErrorString();
    return false;
  }
  mesh = Mesh{};
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* in = scene->mMeshes[i];
    const std::uint32_t base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < in->mNumVertices; ++v) {
      const aiVector3D& p = in->mVertices[v];
      mesh.vertices.emplace_back(p.x, p.y, p.z);
      if (in->mNormals) mesh.normals.emplace_back(in->mNormals[v].x, in->mNormals[v].y, in->mNormals[v].z);
      else mesh.normals.emplace_back(0, 0, 1);
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      addTriangle(mesh, base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]);
    }
  }
  aiReleaseImport(scene);
  if (mesh.triangles.empty()) {
    *why = "no triangles in the file";
    return false;
  }
  mesh.computeBounds();
  return true;
}

int SceneGeometry::addMesh(Mesh mesh) {
  meshes_.push_back(std::move(mesh));
  return static_cast<int>(meshes_.size() - 1);
}

SceneGeometry::SceneGeometry(const scene::Scene& scene, std::ostream& warnings)
    : scene_(&scene), data_(std::make_unique<dynamics::Data<double>>(scene.model)) {
  pairs_ = contact::contactPairs(scene);
  pairs_.resize(scene.contacts.size());  // the stops come after the contacts
  const dynamics::Model<double>& model = scene.model;
  const int sphere = addMesh(sphereMesh()), cylinder = addMesh(cylinderMesh()), box = addMesh(boxMesh());
  const int nb = model.nbodies();

  // Segments of the bodies without visuals (joint origin -> child joint origins, or -> com).
  std::vector<bool> has_visual(nb, false);
  for (const dynamics::Visual& v : model.visuals)
    if (v.body >= 0) has_visual[v.body] = true;
  struct Segment {
    int body;
    Eigen::Vector3d a, b;
  };
  std::vector<Segment> segments;
  std::vector<int> point_masses;
  for (int b = 0; b < nb; ++b) {
    if (has_visual[b]) continue;
    bool has_child = false;
    for (int c = b + 1; c < nb; ++c)
      if (model.parent[c] == b) {
        has_child = true;
        if (model.X_tree[c].r.norm() > 1e-9) segments.push_back({b, Eigen::Vector3d::Zero(), model.X_tree[c].r});
      }
    if (has_child || model.inertia[b].m <= 0) continue;
    const Eigen::Vector3d com = model.inertia[b].h / model.inertia[b].m;
    if (com.norm() > 1e-9) segments.push_back({b, Eigen::Vector3d::Zero(), com});
    else point_masses.push_back(b);
  }
  double longest = 0;
  for (const Segment& s : segments) longest = std::max(longest, (s.b - s.a).norm());
  for (const dynamics::Visual& v : model.visuals) longest = std::max(longest, v.size.maxCoeff());
  length_ = std::max(0.05, longest);
  const double capsule_radius = longest > 0 ? std::max(0.004, 0.04 * longest) : 0.02;
  const Eigen::Vector4f capsule_rgba(0.55f, 0.6f, 0.68f, 1.0f);

  auto addSegment = [&](int body, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                        const Eigen::Vector4f& rgba) {
    Shape s;
    s.body = body;
    s.mesh = addMesh(capsuleMesh(radius, (b - a).norm()));
    s.X_BG.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), b - a).toRotationMatrix();
    s.X_BG.translation() = a;
    s.rgba = rgba;
    shapes_.push_back(s);
  };
  for (const Segment& s : segments) addSegment(s.body, s.a, s.b, capsule_radius, capsule_rgba);
  for (int b : point_masses) {
    Shape s;
    s.body = b;
    s.mesh = sphere;
    s.scale = Eigen::Vector3d::Constant(longest > 0 ? 3 * capsule_radius : 0.05);
    s.rgba = capsule_rgba;
    shapes_.push_back(s);
  }

  // The pivot of a revolute joint on the world: a small dark sphere fixed there.
  for (int b = 0; b < nb; ++b)
    if (model.parent[b] < 0 && model.joint_type[b] == dynamics::JointType::Revolute) {
      Shape s;
      s.body = -1;
      s.X_BG.translation() = model.X_tree[b].r;
      s.mesh = sphere;
      s.scale = Eigen::Vector3d::Constant(longest > 0 ? 2 * capsule_radius : 0.03);
      s.rgba = Eigen::Vector4f(0.2f, 0.2f, 0.22f, 1.0f);
      shapes_.push_back(s);
    }

  // URDF / builder visuals.
  std::set<std::string> reported;
  for (const dynamics::Visual& v : model.visuals) {
    Shape s;
    s.body = v.body;
    s.X_BG.linear() = v.R_BG;
    s.X_BG.translation() = v.p_BG;
    s.rgba = v.rgba.cast<float>();
    switch (v.shape) {
      case dynamics::Visual::Shape::Box:
        s.mesh = box;
        s.scale = v.size;
        break;
      case dynamics::Visual::Shape::Cylinder:
        s.mesh = cylinder;
        s.scale = {v.size[0], v.size[0], v.size[1]};
        break;
      case dynamics::Visual::Shape::Sphere:
        s.mesh = sphere;
        s.scale = Eigen::Vector3d::Constant(v.size[0]);
        break;
      case dynamics::Visual::Shape::Mesh: {
        std::string file = v.mesh_file, why;
        if (file.rfind("file://", 0) == 0) file = file.substr(7);
        Mesh mesh;
        bool loaded = false;
        if (file.rfind("package://", 0) == 0) {
          why = "package:// paths are not resolved (no ROS package path)";
        } else {
          std::filesystem::path p(file);
          if (p.is_relative() && !model.source.empty()) p = std::filesystem::path(model.source).parent_path() / p;
          file = p.string();
          loaded = loadMeshFile(file, mesh, &why);
        }
        if (loaded) {
          s.mesh = addMesh(std::move(mesh));
          s.scale = v.mesh_scale;
          break;
        }
        if (reported.insert(v.mesh_file).second)
          warnings << "saltus render: cannot load mesh '" << v.mesh_file << "' of link '" << v.link << "' (" << why
                   << "); drawing a capsule instead\n";
        // a capsule from the body's joint origin to the visual's origin (or a sphere there)
        const Eigen::Vector3d b = v.p_BG;
        if (b.norm() > 1e-9) {
          addSegment(v.body, Eigen::Vector3d::Zero(), b, capsule_radius, s.rgba);
          continue;
        }
        s.mesh = sphere;
        s.scale = Eigen::Vector3d::Constant(3 * capsule_radius);
        break;
      }
    }
    shapes_.push_back(s);
  }
}

SceneGeometry::Pose SceneGeometry::pose(const Eigen::VectorXd& q) const {
  const dynamics::Model<double>& model = scene_->model;
  dynamics::forwardKinematics(model, *data_, q);
  Pose out;
  out.X_WG.reserve(shapes_.size());
  for (const Shape& s : shapes_) {
    Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
    X_WB.linear() = dynamics::bodyRotation(*data_, s.body);
    X_WB.translation() = dynamics::bodyPosition(*data_, s.body);
    out.X_WG.push_back(X_WB * s.X_BG);
  }
  for (const contact::ContactPair& pair : pairs_) {
    out.p_contact.push_back(contact::contactPoint(pair, *data_));
    out.contact_frame.push_back(contact::planeFrame(pair, *data_));
  }
  return out;
}

Bounds SceneGeometry::bounds(const Pose& pose) const {
  Bounds box;
  for (std::size_t i = 0; i < shapes_.size(); ++i) {
    const Mesh& m = meshes_[shapes_[i].mesh];
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c((corner & 1) ? m.hi.x() : m.lo.x(), (corner & 2) ? m.hi.y() : m.lo.y(),
                              (corner & 4) ? m.hi.z() : m.lo.z());
      box.add(pose.X_WG[i] * c.cwiseProduct(shapes_[i].scale));
    }
  }
  for (const Eigen::Vector3d& p : pose.p_contact) box.add(p);
  return box;
}

}  // namespace saltus::render
