// The contact layer's unit: every unilateral constraint of a scene as one ContactPair, whatever
// its kind, in one order (the scene's contacts, then its joint-limit stops). The kinematics of a
// pair (gap, contact frame, relative Jacobian and velocity) are in contact/kinematics.hpp; the
// time-stepper, the collocation, the replays and the renderer read them from there and nowhere
// else.
//
//   point on a plane  a point fixed on body A against a plane fixed in body B, or in the world
//                     (B = −1), where the plane's material may move tangentially by the
//                     surface's velocity schedule (a conveyor belt); normal along the plane's
//                     normal, Coulomb friction with a polyhedral cone of k directions in the
//                     plane (paper eq. 11), Newton restitution
//   joint stop        a joint-limit hard stop on coordinate i: gap = sign · (q_i − limit), sign
//                     +1 at a lower limit, −1 at an upper one; frictionless
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace saltus::contact {

enum class PairKind { PointOnPlane, JointStop };

struct ContactPair {
  std::string name;
  PairKind kind = PairKind::PointOnPlane;

  // PointOnPlane.
  int body_a = -1;                                     // the body the point moves with
  Eigen::Vector3d point_A = Eigen::Vector3d::Zero();  // the point in A's coordinates
  int body_b = -1;                                     // the body the plane is fixed in; −1: the world
  Eigen::Vector3d plane_point_B = Eigen::Vector3d::Zero();  // a point of the plane, in B's coordinates
  Eigen::Vector3d normal_B = Eigen::Vector3d::UnitZ();     // unit normal, in B's coordinates
  Eigen::Matrix<double, 3, 2> tangents_B = Eigen::Matrix<double, 3, 2>::Identity();  // (t1, t2) = n × t1
  Eigen::Matrix3Xd directions_B;  // 3 × k unit friction directions in the plane (B's coordinates)
  // Half-lengths of the plane's rectangle along (t1, t2) about plane_point_B (a body's plane: a
  // point beyond it touches nothing); infinite for a world surface.
  Eigen::Vector2d extent = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  int surface = -1;  // the scene surface the plane is (its velocity schedule), −1: none
  // The tangent axes (0: t1, 1: t2) along which the optimiser's contact point on B's plane is a
  // variable s (scene::Contact::free_axes); empty: the contact point is A's point. The
  // time-stepper's contact point is always A's point, over the rectangle or touching nothing.
  std::vector<int> free_axes;

  // JointStop.
  int coordinate = -1;  // velocity coordinate (v, Jacobian columns)
  int position = -1;    // its position coordinate in q (model.positionOf: shifted by a quaternion base)
  double sign = 1;  // +1 lower limit, −1 upper limit
  double limit = 0;

  double restitution = 0;
  double friction = 0;  // μ; 0 for a stop

  // Per velocity coordinate: whether the pair's kinematics (gap, contact frame, relative velocity
  // and Jacobian) can depend on it: the coordinates of the joints from the world to body A and to
  // body B; a stop's own coordinate. The others are structurally absent (the collocation's
  // Hessians skip them).
  std::vector<bool> moves_with;
  // Of those, the ones its relative Jacobian J(q) (so its relative velocity at given rates) and
  // its contact frame can depend on: moves_with less the world translations (dynamics/world_translation.hpp) that
  // move A against a world plane or move both A and B; a world translation that moves only one
  // of A and B moves the contact point against the other's rotation axes. J is affine in the
  // world translations jointly, the contact frame does not depend on them, and the gap and the
  // plane coordinates are affine in them. A stop's names none: its Jacobian is constant.
  std::vector<bool> jacobian_with;
  // Of those, the ones the Jacobian at which the reaction acts and the slip is measured, and the
  // contact frame, can depend on: jacobian_with for a point at A's point; for a free point
  // (free_axes) moves_with less every world translation, since its Jacobian
  // J_A(x_A) − J_B(p + Σ t_i s_i) at given plane coordinates s levers A's rotations about A's
  // point and B's about a point fixed in B, neither of which a world translation moves against
  // the other's axes. (The restitution's normal velocity is at A's point: jacobian_with.)
  std::vector<bool> reaction_jacobian_with;

  bool isStop() const { return kind == PairKind::JointStop; }
  bool freePoint() const { return !free_axes.empty(); }
  int freeAxes() const { return static_cast<int>(free_axes.size()); }
  int k() const { return static_cast<int>(directions_B.cols()); }  // friction directions
};

// The pairs of a scene: its contacts (in order), then its joint-limit stops (in order). A
// contact's plane is its world surface (normal and point as given, tangents and friction
// directions from Surface::tangents and Surface::coneDirections) or the plane on another body it
// names (scene::BodyPlane, with its extent).
std::vector<ContactPair> contactPairs(const scene::Scene& scene);

}  // namespace saltus::contact
