// The constant description of a kinematic tree (RBDA 4.1: λ(i), joint types, X_T, I_i).
//
// Every body i has exactly one joint connecting it to its parent λ(i) < i (−1 is the fixed
// world). Joints of URDF links have one coordinate; a floating base is one multi-coordinate
// joint (JointType::Planar, 3 coordinates, JointType::Free or FreeQuaternion, 6) on the root body.
// Body i's velocity coordinates are first_coordinate[i] .. first_coordinate[i] + num_coordinates[i]
// − 1, so a body index is a coordinate index only while every joint has one coordinate (fixed-base
// models).
// Bodies are numbered depth first (the builder's order), so the subtree of body i is the range
// [i, subtree_end[i]). Coordinates follow the bodies' order. Fixed URDF joints are merged into their
// parent body. The generalised velocities are the time derivatives of the coordinates (v = q̇,
// nq = nv) except for a FreeQuaternion base, whose orientation is a unit quaternion (four
// position coordinates for three velocity ones: nq = nv + 1, configuration.hpp); body i's first
// position coordinate is first_position[i].
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynamics/spatial.hpp"

namespace saltus::dynamics {

// Revolute, Prismatic: one coordinate along / about `axis`.
// Planar, Free, FreeQuaternion: the coordinates of the BaseType of that name (below).
enum class JointType { Revolute, Prismatic, Planar, Free, FreeQuaternion };

// How the tree's root link is attached to the world.
//  Fixed:  the root link is the world.
//  Planar: coordinates (base_x, base_z, base_theta): translation along world x and z, then a
//          rotation θ about the y axis; motion in the vertical x–z plane.
//  Free:   coordinates (base_x, base_y, base_z, base_yaw, base_pitch, base_roll): translation in
//          world axes, then intrinsic Z–Y′–X″ Euler angles (yaw ψ, pitch θ, roll φ), so the base
//          orientation is R = Rz(ψ) Ry(θ) Rx(φ). Singular at θ = ±π/2 (gimbal lock), where the
//          mass matrix loses rank; keep pitch away from ±π/2 or use FreeQuaternion.
//  FreeQuaternion: position coordinates (base_x, base_y, base_z, base_qw, base_qx, base_qy,
//          base_qz): the origin in world axes and the unit quaternion of R (scalar first, as
//          MuJoCo and Drake); velocity coordinates (base_x, base_y, base_z, base_wx, base_wy,
//          base_wz): the world velocity of the origin ṗ and the angular velocity ω_B in body
//          axes (MuJoCo's free joint). No singular orientation: a body can tumble. Positions
//          move on the manifold (configuration.hpp, integrate), not by q += v dt.
// Floating bases are one joint (JointType::Planar / Free / FreeQuaternion) between the world and
// the root link's body, body 0, whose frame is the root link frame.
enum class BaseType { Fixed, Planar, Free, FreeQuaternion };

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

// Values of Model::joint_kernel.
constexpr int kAxisJoint = 0;         // + K (0, 1, 2)
constexpr int kRotatedAxisJoint = 3;  // + K
constexpr int kGenericJoint = 6;
constexpr int kMultiJoint = 7;

// Body i seen from a frame B'_i turned from its body frame B_i by a constant signed permutation
// Q_i (coordinates x' = Q_i x), for an algorithm whose result does not depend on the coordinates
// each body's quantities are expressed in, such as M(q) in the CRBA (crba.hpp). Down the tree, a
// revolute joint about σ e_K whose X_T rotation E_T is a signed permutation gets Q_i = Q_λ E_Tᵀ:
// from B'_λ the joint is then rot(Q_i E_J(q) E_T Q_λᵀ) xlt(Q_λ r_T) with Q_i E_J(q) E_T Q_λᵀ =
// Q_i E_J(q) Q_iᵀ, the rotation by the same angle about Q_i e_K = τ e_K' (RBDA 4.32, Table 2.2): an
// axis joint about σ' e_K', σ' = τ σ, with no X_T rotation (E_T = 1 included: Q_i = Q_λ). Every
// other joint keeps Q_i = 1 and is reached from B'_λ by ^iX_λ rot(Q_λᵀ). prepareTurnedFrames fills
// Model::turned_frame.
template <class S>
struct TurnedFrame {
  int kernel = kGenericJoint;   // joint kernel from B'_λ: kAxisJoint + K' when turned, else joint_kernel[i]
  bool turned = false;          // an axis joint from B'_λ (E_T a signed permutation, 1 included): kernel = kAxisJoint + K'
  bool parent_turned = false;   // Q_λ ≠ 1
  S sign = S(1);                // σ' of a turned joint
  // cos q = cos_sign E(cos_row, cos_col) and σ' sin q = sin_sign E(cos_row, sin_col), read off the
  // rotation E = E_J(q) E_T of ^iX_λ (joint.hpp, storeRotatedAxisTransform).
  int cos_row = 0, cos_col = 0, sin_col = 0;
  S cos_sign = S(1), sin_sign = S(1);
  Vec3<S> r_T = Vec3<S>::Zero();              // joint origin in B'_λ coordinates: Q_λ r_T
  Mat3<S> Q = Mat3<S>::Identity();            // Q_i
  RigidInertia<S> inertia = RigidInertia<S>::Zero();  // I_i in B'_i coordinates

  template <class T>
  TurnedFrame<T> cast() const {
    return {kernel, turned, parent_turned, T(sign), cos_row, cos_col, sin_col, T(cos_sign), T(sin_sign),
            r_T.template cast<T>(), Q.template cast<T>(), inertia.template cast<T>()};
  }
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
  std::vector<TurnedFrame<S>> turned_frame;  // body i in its turned frame B'_i (prepareTurnedFrames)
  std::vector<Transform<S>> X_tree;        // X_T(i): λ(i) frame -> joint frame at q = 0
  std::vector<RigidInertia<S>> inertia;    // I_i in the body frame
  std::vector<bool> massless;              // I_i = 0 (intermediate links of multi-axis mechanisms)
  std::vector<std::string> body_name;
  std::vector<int> first_coordinate;       // index of body i's first coordinate
  std::vector<int> num_coordinates;        // 1, or 3 (Planar), 6 (Free, FreeQuaternion): only body 0 (parent −1) may have more than 1
  std::vector<int> first_position;         // index of body i's first position coordinate in q

  // Per coordinate k.
  std::vector<std::string> coordinate_name;  // per velocity coordinate: URDF joint name (or base_x ...)
  std::vector<std::string> position_name;    // per position coordinate (nq): coordinate_name but for a quaternion base
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
  int nq() const { return nv() + (base == BaseType::FreeQuaternion ? 1 : 0); }
  // The position coordinate of velocity coordinate k outside a quaternion base's rotation.
  int positionOf(int k) const { return k < n_base ? k : k + nq() - nv(); }
  int nbodies() const { return static_cast<int>(parent.size()); }
  // Whether coordinate k is a length (prismatic joint, base translation) rather than an angle.
  bool isTranslation(int k) const {
    const int b = coordinate_body[k];
    const JointType t = joint_type[b];
    if (t == JointType::Prismatic) return true;
    if (t == JointType::Revolute) return false;
    return k - first_coordinate[b] < num_coordinates[b] - (t == JointType::Planar ? 1 : 3);
  }
  S totalMass() const {
    S m(0);
    for (const auto& I : inertia) m += I.m;
    return m;
  }
  // −1 when absent.
  int bodyIndex(const std::string& body) const;
  int coordinateIndex(const std::string& coordinate) const;
  int positionIndex(const std::string& position) const;
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
    first_position.assign(parent.size(), 0);
    coordinate_body.clear();
    parent_coordinate.clear();
    for (int i = 0, position = 0; i < nbodies(); ++i) {
      first_coordinate[i] = static_cast<int>(coordinate_body.size());
      first_position[i] = position;
      position += num_coordinates[i] + (joint_type[i] == JointType::FreeQuaternion ? 1 : 0);
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
    m.turned_frame.clear();
    for (const auto& t : turned_frame) m.turned_frame.push_back(t.template cast<T>());
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
    m.first_position = first_position;
    m.coordinate_name = coordinate_name;
    m.position_name = position_name;
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

// Whether E is a signed permutation (one entry ±1 in every row and column, the others 0) with
// determinant +1: a rotation by multiples of π/2 about the coordinate axes.
inline bool isSignedPermutationRotation(const Mat3<double>& E) {
  int count = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double x = E(r, c);
      if (x != 0.0 && x != 1.0 && x != -1.0) return false;
      count += x != 0.0;
    }
  return count == 3 && (E.transpose() * E).isIdentity(0) && E.determinant() == 1.0;
}

// URDF exporters write π/2 to 10–12 significant digits (the benchmark models' 1.57079632679 is
// 4.9e-12 short), so their rpy of multiples of π/2 give rotations a few 1e-12 off a signed
// permutation. The builder takes a joint-origin rotation within kSignedPermutationTolerance of one,
// entry by entry, to be that permutation: a change of the model by a rotation below ~1e-10 rad (a
// tenth of a nanometre at one metre), far under any physical tolerance, that lets the joint after
// it be an axis joint in the turned frames (TurnedFrame) and makes such models' kinematics exact in
// those entries.
constexpr double kSignedPermutationTolerance = 1e-10;
// E with entries within kSignedPermutationTolerance of 0 and ±1 set to them, when the result is a
// signed-permutation rotation; E unchanged otherwise.
inline Mat3<double> snapToSignedPermutation(const Mat3<double>& E) {
  Mat3<double> P;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double x = E(r, c), rounded = x > 0.5 ? 1.0 : x < -0.5 ? -1.0 : 0.0;
      if (!(std::abs(x - rounded) <= kSignedPermutationTolerance)) return E;
      P(r, c) = rounded;
    }
  return isSignedPermutationRotation(P) ? P : E;
}

// Fills model.turned_frame (TurnedFrame above) from the parents, joint kernels, axis signs, X_T
// and inertias; prepareKernels calls it.
inline void prepareTurnedFrames(Model<double>& model) {
  const int nb = model.nbodies();
  model.turned_frame.assign(nb, TurnedFrame<double>{});
  for (int i = 0; i < nb; ++i) {
    TurnedFrame<double>& t = model.turned_frame[i];
    const int p = model.parent[i];
    const Mat3<double> Q_parent = p < 0 ? Mat3<double>::Identity() : model.turned_frame[p].Q;
    const Transform<double>& XT = model.X_tree[i];
    const int kernel = model.joint_kernel[i];
    t.kernel = kernel;
    t.parent_turned = !Q_parent.isIdentity(0);
    if (kernel < kGenericJoint && isSignedPermutationRotation(XT.E)) {
      const int K = kernel % 3, i1 = (K + 1) % 3, i2 = (K + 2) % 3;
      t.Q = Q_parent * XT.E.transpose();  // exact: products and sums of 0 and ±1
      int K_turned = 0;  // Q_i e_K = τ e_K'
      for (int k = 0; k < 3; ++k)
        if (t.Q(k, K) != 0.0) K_turned = k;
      t.kernel = kAxisJoint + K_turned;
      t.turned = true;
      t.sign = t.Q(K_turned, K) * model.axis_sign[i];  // σ' = τ σ
      // Row i1 of E is c E_T(i1, :) + σ sin q E_T(i2, :), and each row of E_T has one non-zero ±1.
      t.cos_row = i1;
      for (int c = 0; c < 3; ++c) {
        if (XT.E(i1, c) != 0.0) t.cos_col = c, t.cos_sign = XT.E(i1, c);
        if (XT.E(i2, c) != 0.0) t.sin_col = c, t.sin_sign = XT.E(i2, c) * model.axis_sign[i] * t.sign;
      }
      t.r_T = Q_parent * XT.r;
    }
    // I_i in B'_i: h' = Q h, Ī' = Q Ī Qᵀ (exact for a signed permutation).
    const RigidInertia<double>& I = model.inertia[i];
    t.inertia = {I.m, t.Q * I.h, t.Q * I.I * t.Q.transpose()};
  }
}

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
  prepareTurnedFrames(model);
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
int Model<S>::positionIndex(const std::string& position) const {
  for (int i = 0; i < nq(); ++i)
    if (position_name[i] == position) return i;
  return -1;
}
template <class S>
int Model<S>::frameIndex(const std::string& frame) const {
  for (int i = 0; i < static_cast<int>(frames.size()); ++i)
    if (frames[i].name == frame) return i;
  return -1;
}

// Argument sizes of the public algorithms, as Pinocchio's PINOCCHIO_CHECK_ARGUMENT_SIZE: a
// vector (or a Jacobian's column count) of the wrong length throws std::invalid_argument naming
// the function, the argument and both sizes, instead of reading past its end. One comparison
// per argument; the throw is out of line.
[[noreturn]] void argumentSizeError(const char* function, const char* argument, long size, int expected);
template <class S>
inline void checkArgumentSize(const Model<S>& model, long size, const char* function, const char* argument) {
  if (size != model.nv()) [[unlikely]]
    argumentSizeError(function, argument, size, model.nv());
}
// The same for a configuration q (nq entries).
template <class S>
inline void checkConfigurationSize(const Model<S>& model, long size, const char* function, const char* argument) {
  if (size != model.nq()) [[unlikely]]
    argumentSizeError(function, argument, size, model.nq());
}

}  // namespace saltus::dynamics
