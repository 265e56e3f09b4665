// What is drawn for a scene's model: triangle meshes (primitives, capsules, meshes loaded from
// URDF visuals), each attached to a body with a pose and a scale, posed in the world by forward
// kinematics (dynamics/kinematics.hpp).
//  - URDF / builder visuals: box, cylinder (along its z axis, as in URDF), sphere, mesh files
//    (through assimp; `package://` and unreadable files are drawn as a capsule, reported once
//    on the warning stream).
//  - a body without visuals: capsules from its joint origin to each child's joint origin, or to
//    its centre of mass when it has no children; a point mass (com at the joint origin, no
//    children) is a sphere.
//  - the pivot of a revolute joint on the world: a small dark sphere.
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "contact/kinematics.hpp"
#include "dynamics/data.hpp"
#include "render/camera.hpp"
#include "scene/scene.hpp"

namespace saltus::render {

// An indexed triangle mesh with per-vertex normals (float: what OpenGL takes).
struct Mesh {
  std::vector<Eigen::Vector3f> vertices, normals;
  std::vector<std::uint32_t> triangles;  // three indices per triangle
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();  // bounding box
  void computeBounds();
};

// Unit primitives.
Mesh sphereMesh(int slices = 32, int stacks = 16);       // radius 1 at the origin
Mesh cylinderMesh(int slices = 32);                      // radius 1, z in [−½, ½], capped
Mesh boxMesh();                                          // [−½, ½]³
Mesh coneMesh(int slices = 24);                          // base radius 1 at z = 0, apex at z = 1, capped
Mesh capsuleMesh(double radius, double length, int slices = 24, int stacks = 8);  // axis z from 0 to length
Mesh diskMesh(int slices = 48);                          // radius 1 in the z = 0 plane, normal +z

// A mesh attached to a body: world pose X_WB · X_BG · diag(scale).
struct Shape {
  int body = -1;  // −1: the world
  Eigen::Isometry3d X_BG = Eigen::Isometry3d::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  int mesh = 0;   // index into SceneGeometry::meshes()
  Eigen::Vector4f rgba{0.7f, 0.7f, 0.7f, 1.0f};
};

class SceneGeometry {
 public:
  // Mesh file problems are written once each to `warnings`.
  SceneGeometry(const scene::Scene& scene, std::ostream& warnings);

  const scene::Scene& scene() const { return *scene_; }
  const std::vector<Mesh>& meshes() const { return meshes_; }
  const std::vector<Shape>& shapes() const { return shapes_; }

  // World poses of the shapes (without scale), and per scene contact its point and its plane's
  // frame at q (the contact layer's: a plane on a body moves with it).
  struct Pose {
    std::vector<Eigen::Isometry3d> X_WG;
    std::vector<Eigen::Vector3d> p_contact;
    std::vector<contact::PlaneFrame<double>> contact_frame;
    // The contact point projected onto its plane, and its world vector of a load in that frame.
    Eigen::Vector3d onPlane(std::size_t c) const {
      const contact::PlaneFrame<double>& f = contact_frame[c];
      return p_contact[c] - f.normal.dot(p_contact[c] - f.point) * f.normal;
    }
  };
  Pose pose(const Eigen::VectorXd& q) const;
  // Bounding box of the posed shapes (and contact points).
  Bounds bounds(const Pose& pose) const;
  // Typical size of the model [m]: capsule lengths, visual sizes; at least 0.05.
  double characteristicLength() const { return length_; }

 private:
  int addMesh(Mesh mesh);
  const scene::Scene* scene_;
  std::vector<Mesh> meshes_;
  std::vector<Shape> shapes_;
  double length_ = 0.05;
  std::unique_ptr<dynamics::Data<double>> data_;
  std::vector<contact::ContactPair> pairs_;  // the scene's contacts (its stops are not drawn)
};

// The direction a surface's material moves along: its first non-zero scheduled velocity,
// projected onto the plane and normalised; zero when it never moves (then it is not a belt).
Eigen::Vector3d beltDirection(const scene::Surface& surface);
// How far the material has travelled along `direction` by time t [m]: direction ·
// Surface::displacement(t).
double surfaceTravel(const scene::Surface& surface, const Eigen::Vector3d& direction, double t);

// Reads a mesh file through assimp (triangulated, vertices in the file's root frame). Returns
// false and sets *why when it cannot.
bool loadMeshFile(const std::string& path, Mesh& mesh, std::string* why);

}  // namespace saltus::render
