// The constant description of a kinematic tree (RBDA 4.1: λ(i), joint types, X_T, I_i).
//
// Every body i has exactly one joint connecting it to its parent λ(i) < i (−1 is the fixed
// world). Joints of URDF links have one coordinate; a floating base is one multi-coordinate
// joint (JointType::Planar, 3 coordinates, or JointType::Free, 6) on the root body. Body i's
// coordinates are first_coordinate[i] .. first_coordinate[i] + num_coordinates[i] − 1, so a body
// index is a coordinate index only while every joint has one coordinate (fixed-base models).
// Bodies are numbered depth first (the builder's order), so the subtree of body i is the range
// [i, subtree_end[i]). Coordinates follow the bodies' order. Fixed URDF joints are merged into their
// parent body. Generalised velocities are always the time derivatives of the coordinates:
// v = q̇, nq = nv.
#pragma once

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynamics/spatial.hpp"

namespace saltus::dynamics {

// Revolute, Prismatic: one coordinate along / about `axis`.
// Planar: the three coordinates of BaseType::Planar; Free: the six of BaseType::Free (below).
enum class JointType { Revolute, Prismatic, Planar, Free };

// How the tree's root link is attached to the world.
//  Fixed:  the root link is the world.
//  Planar: coordinates (base_x, base_z, base_theta): translation along world x and z, then a
//          rotation θ about the y axis; motion in the vertical x–z plane.
//  Free:   coordinates (base_x, base_y, base_z, base_yaw, base_pitch, base_roll): translation in
//          world axes, then intrinsic Z–Y′–X″ Euler angles (yaw ψ, pitch θ, roll φ), so the base
//          orientation is R = Rz(ψ) Ry(θ) Rx(φ). Singular at θ = ±π/2 (gimbal lock), where the
//          mass matrix loses rank; keep pitch away from ±π/2 or re-parametrise.
// Planar and Free bases are one joint (JointType::Planar / Free) between the world and the root
// link's body, body 0, whose frame is the root link frame.
enum class BaseType { Fixed, Planar, Free };

const char* toString(BaseType base);
const char* toString(JointType type);

constexpr double kInf = std::numeric_limits<double>::infinity();

struct JointLimits {
  double lower = -kInf;    // position [m or rad]; −∞ when unlimited (continuous joints)
  double upper = kInf;
  double velocity = kInf;  // |q̇| bound
  double effort = kInf;    // |τ| bound (input bound for optimisation)
  bool hasPositionLimits() const { return lower > -kInf || upper < kInf; }
};

// Visual geometry for rendering, attached to a body.
struct Visual {
  enum class Shape { Box, Cylinder, Sphere, Mesh };
  std::string link;        // URDF link it came from
  int body = -1;           // body it moves with (−1: world)
  Eigen::Matrix3d R_BG = Eigen::Matrix3d::Identity();  // orientation of the geometry in the body frame
  Eigen::Vector3d p_BG = Eigen::Vector3d::Zero();      // position of the geometry in the body frame
  Shape shape = Shape::Box;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();      // box: extents; cylinder: (radius, length, 0); sphere: (radius, 0, 0)
  std::string mesh_file;
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();
  Eigen::Vector4d rgba{0.7, 0.7, 0.7, 1.0};
};

// A named frame rigidly attached to a body: every URDF link is one (a link merged through a
// fixed joint keeps its own frame on the body it was merged into).
struct Frame {
  std::string name;
  int body = -1;                                       // −1: the world
  Eigen::Matrix3d R_BF = Eigen::Matrix3d::Identity();  // orientation of the frame in the body frame
  Eigen::Vector3d p_BF = Eigen::Vector3d::Zero();      // origin of the frame in the body frame
};

template <class S>
struct Model {
  std::string name;    // robot name
  std::string source;  // file it was read from, or "builder"
  BaseType base = BaseType::Fixed;
  int n_base = 0;      // number of leading base coordinates (0, 3 or 6): those of body 0's joint

  // Per body i, in topological order: parent[i] < i.
  std::vector<int> parent;                 // λ(i), −1 for the world
  std::vector<JointType> joint_type;
  std::vector<Vec3<S>> axis;               // unit joint axis in the body (joint) frame (zero for Planar, Free)
  std::vector<int> axis_kind;              // 0, 1, 2: axis is +x, +y, +z (fast paths); −1: general
  // How the kernels' loops evaluate body i's joint (prepareKernels; joint.hpp, withJoint):
  // kAxisJoint + K: revolute about σ e_K with no rotation in X_T, so ^iX_λ = rot(R_K(σq)ᵀ) xlt(r_T)
  // acts on a vector as a cross product and a plane rotation; kRotatedAxisJoint + K: revolute
  // about σ e_K after a general X_T rotation; kGenericJoint: any other one-coordinate joint;
  // kMultiJoint: a multi-coordinate (base) joint.
  std::vector<int> joint_kernel;
  std::vector<S> axis_sign;                // σ = ±1 for the axis joints, else 1
  std::vector<int> subtree_end;            // one past the last body of body i's subtree
  std::vector<Transform<S>> X_tree;        // X_T(i): λ(i) frame -> joint frame at q = 0
  std::vector<RigidInertia<S>> inertia;    // I_i in the body frame
  std::vector<bool> massless;              // I_i = 0 (intermediate links of multi-axis mechanisms)
  std::vector<std::string> body_name;
  std::vector<int> first_coordinate;       // index of body i's first coordinate
  std::vector<int> num_coordinates;        // 1, or 3 (Planar), 6 (Free): only body 0 (parent −1) may have more than 1

  // Per coordinate k.
  std::vector<std::string> coordinate_name;  // URDF joint name (or base_x ...)
  std::vector<JointLimits> limits;
  std::vector<int> coordinate_body;          // the body whose joint coordinate k belongs to
  // The coordinate before k on the path to the root: k − 1 inside a multi-coordinate joint, else
  // the last coordinate of the parent body (−1 at the root). The coordinates form a tree in which
  // M(q)_kl can be non-zero only for l on k's path (or k on l's).
  std::vector<int> parent_coordinate;

  Vec3<S> gravity = Vec3<S>(S(0), S(0), S(-9.81));

  std::vector<Frame> frames;
  std::vector<Visual> visuals;

  int nv() const { return static_cast<int>(coordinate_body.size()); }
  int nq() const { return nv(); }
  int nbodies() const { return static_cast<int>(parent.size()); }
  // Whether coordinate k is a length (prismatic joint, base translation) rather than an angle.
  bool isTranslation(int k) const {
    const int b = coordinate_body[k];
    const JointType t = joint_type[b];
    if (t == JointType::Prismatic) return true;
    if (t == JointType::Revolute) return false;
    return k - first_coordinate[b] < num_coordinates[b] - (t == JointType::Free ? 3 : 1);
  }
  S totalMass() const {
    S m(0);
    for (const auto& I : inertia) m += I.m;
    return m;
  }
  // −1 when absent.
  int bodyIndex(const std::string& body) const;
  int coordinateIndex(const std::string& coordinate) const;
  int frameIndex(const std::string& frame) const;
  // true when body a is b or an ancestor of b.
  bool isAncestor(int a, int b) const {
    while (b > a) b = parent[b];
    return a == b;
  }
  // Fills first_coordinate, coordinate_body and parent_coordinate from parent and
  // num_coordinates (the builder calls it).
  void numberCoordinates() {
    first_coordinate.assign(parent.size(), 0);
    coordinate_body.clear();
    parent_coordinate.clear();
    for (int i = 0; i < nbodies(); ++i) {
      first_coordinate[i] = static_cast<int>(coordinate_body.size());
      for (int c = 0; c < num_coordinates[i]; ++c) {
        const int p = parent[i];
        parent_coordinate.push_back(c > 0 ? first_coordinate[i] + c - 1
                                          : p < 0 ? -1 : first_coordinate[p] + num_coordinates[p] - 1);
        coordinate_body.push_back(i);
      }
    }
  }

  template <class T>
  Model<T> cast() const {
    Model<T> m;
    m.name = name;
    m.source = source;
    m.base = base;
    m.n_base = n_base;
    m.parent = parent;
    m.joint_type = joint_type;
    m.axis_kind = axis_kind;
    m.joint_kernel = joint_kernel;
    m.subtree_end = subtree_end;
    m.axis_sign.clear();
    for (const S& x : axis_sign) m.axis_sign.push_back(T(x));
    m.axis.reserve(axis.size());
    for (const auto& a : axis) m.axis.push_back(a.template cast<T>());
    m.X_tree.reserve(X_tree.size());
    for (const auto& X : X_tree) m.X_tree.push_back(X.template cast<T>());
    m.inertia.reserve(inertia.size());
    for (const auto& I : inertia) m.inertia.push_back(I.template cast<T>());
    m.massless = massless;
    m.body_name = body_name;
    m.first_coordinate = first_coordinate;
    m.num_coordinates = num_coordinates;
    m.coordinate_name = coordinate_name;
    m.limits = limits;
    m.coordinate_body = coordinate_body;
    m.parent_coordinate = parent_coordinate;
    m.gravity = gravity.template cast<T>();
    m.frames = frames;
    m.visuals = visuals;
    return m;
  }
};

// 0, 1, 2 when a is the unit vector +x, +y, +z; −1 otherwise.
inline int axisKind(const Eigen::Vector3d& a) {
  for (int k = 0; k < 3; ++k)
    if (a == Eigen::Vector3d::Unit(k)) return k;
  return -1;
}

// Values of Model::joint_kernel.
constexpr int kAxisJoint = 0;         // + K (0, 1, 2)
constexpr int kRotatedAxisJoint = 3;  // + K
constexpr int kGenericJoint = 6;
constexpr int kMultiJoint = 7;

// Fills model.joint_kernel and model.axis_sign from the joint types, axes and X_T, and
// model.subtree_end (the builder calls it once the bodies are in place, depth first).
inline void prepareKernels(Model<double>& model) {
  const int nb = model.nbodies();
  // Depth first: the body before i is i's parent or in its parent's subtree.
  for (int i = 1; i < nb; ++i)
    if (model.parent[i] >= 0 && !model.isAncestor(model.parent[i], i - 1))
      throw std::logic_error("prepareKernels: bodies are not in depth-first order");
  model.subtree_end.resize(nb);
  for (int i = 0; i < nb; ++i) model.subtree_end[i] = i + 1;
  for (int i = nb - 1; i >= 0; --i)
    if (model.parent[i] >= 0) model.subtree_end[model.parent[i]] = std::max(model.subtree_end[model.parent[i]], model.subtree_end[i]);
  model.joint_kernel.assign(nb, kGenericJoint);
  model.axis_sign.assign(nb, 1.0);
  for (int i = 0; i < nb; ++i) {
    if (model.num_coordinates[i] > 1) {
      model.joint_kernel[i] = kMultiJoint;
      continue;
    }
    if (model.joint_type[i] != JointType::Revolute) continue;
    for (int k = 0; k < 3; ++k) {
      const double sigma = model.axis[i][k];
      if ((sigma == 1.0 || sigma == -1.0) && model.axis[i][(k + 1) % 3] == 0.0 && model.axis[i][(k + 2) % 3] == 0.0) {
        model.axis_sign[i] = sigma;
        model.joint_kernel[i] = (model.X_tree[i].E == Mat3<double>::Identity() ? kAxisJoint : kRotatedAxisJoint) + k;
      }
    }
  }
}

template <class S>
int Model<S>::bodyIndex(const std::string& body) const {
  for (int i = 0; i < nbodies(); ++i)
    if (body_name[i] == body) return i;
  return -1;
}
template <class S>
int Model<S>::coordinateIndex(const std::string& coordinate) const {
  for (int i = 0; i < nv(); ++i)
    if (coordinate_name[i] == coordinate) return i;
  return -1;
}
template <class S>
int Model<S>::frameIndex(const std::string& frame) const {
  for (int i = 0; i < static_cast<int>(frames.size()); ++i)
    if (frames[i].name == frame) return i;
  return -1;
}

}  // namespace saltus::dynamics
