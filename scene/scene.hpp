// A simulation scene: the model, its surfaces and contacts, joint-limit stops, the initial state
// and the named parameters it was made from. Built from a scenario file (scenario.hpp) or in
// C++; read by the time-stepper (stepper.hpp), the collocation transcription and the renderer.
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "dynamics/model.hpp"

namespace saltus::scene {

// An orthonormal tangent basis (t1, t2) of a plane with unit normal n, in n's coordinates: t1 is
// the x axis (else y) projected onto the plane, t2 = n × t1. For a world plane in a scene moving
// in the x–z plane with a horizontal surface, t1 = x.
inline Eigen::Matrix<double, 3, 2> planeTangents(const Eigen::Vector3d& n) {
  const Eigen::Vector3d a = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = (a - a.dot(n) * n).normalized();
  Eigen::Matrix<double, 3, 2> T;
  T << t1, n.cross(t1);
  return T;
}

// The k unit directions of a polyhedral friction cone in a plane with tangents T = (t1, t2)
// (paper eq. 11): ±t1 for k = 2, otherwise evenly spaced starting at t1.
inline Eigen::Matrix3Xd coneDirections(const Eigen::Matrix<double, 3, 2>& T, int k) {
  Eigen::Matrix3Xd d(3, k);
  for (int j = 0; j < k; ++j) {
    const double angle = 2 * std::numbers::pi * j / k;
    d.col(j) = std::cos(angle) * T.col(0) + std::sin(angle) * T.col(1);
  }
  return d;
}

// A plane {x : n·(x − p) = 0} whose material moves tangentially with a prescribed velocity
// schedule (a conveyor belt): velocity(t) = the last step's value with time ≤ t, zero before the
// first (a step at t acts from t on; velocityBefore(t) is the value just before it). The velocity
// must be tangent to the plane. The gap of a point to the plane is the contact layer's
// (contact::gap).
struct Surface {
  std::string name;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  struct Step {
    double time;
    Eigen::Vector3d velocity;
  };
  std::vector<Step> velocity_schedule;  // sorted by time

  Eigen::Vector3d velocity(double t) const {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (const Step& s : velocity_schedule)
      if (s.time <= t) v = s.velocity;
    return v;
  }
  // v(t⁻): the last step's value with time < t.
  Eigen::Vector3d velocityBefore(double t) const {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (const Step& s : velocity_schedule)
      if (s.time < t) v = s.velocity;
    return v;
  }
  // How far the material has moved from time 0 to t ≥ 0: ∫₀ᵗ velocity.
  Eigen::Vector3d displacement(double t) const {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < velocity_schedule.size(); ++k) {
      const double begin = std::max(velocity_schedule[k].time, 0.0);
      const double end = k + 1 < velocity_schedule.size() ? std::min(velocity_schedule[k + 1].time, t) : t;
      if (end > begin) d += velocity_schedule[k].velocity * (end - begin);
    }
    return d;
  }

  Eigen::Matrix<double, 3, 2> tangents() const { return planeTangents(normal); }
  Eigen::Matrix3Xd coneDirections(int k) const { return scene::coneDirections(tangents(), k); }
};

// A plane fixed in a body (a deck, a cart's top): a rectangle of half-lengths `extent` along its
// tangents about `point`. Given in a link's frame, where the tangents are planeTangents(normal)
// (the link's x axis projected onto the plane, then n × t1), and stored in the body's
// coordinates. A point beyond the rectangle touches nothing.
struct BodyPlane {
  std::string link;  // URDF link (frame) the plane is given in
  int body = -1;     // the body the plane moves with
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // the rectangle's centre, body coordinates
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, body coordinates
  Eigen::Matrix<double, 3, 2> tangents = planeTangents(Eigen::Vector3d::UnitZ());  // (t1, t2), body coordinates
  Eigen::Vector2d extent = Eigen::Vector2d::Zero();   // half-lengths along t1, t2 [m]
};

// A point fixed on a body touching a world surface or a plane on another body (unilateral
// normal, Coulomb friction with a polyhedral cone of `directions` unit vectors in the tangent
// plane, Newton restitution). On a body's plane the reaction on the point's body has its
// opposite on the plane's body.
struct Contact {
  std::string name;
  std::string link;   // URDF link (frame) the point is given in
  int body = -1;      // body the point moves with
  Eigen::Vector3d p_B = Eigen::Vector3d::Zero();  // the point in body coordinates
  int surface = 0;    // index into Scene::surfaces; −1: on `plane`
  BodyPlane plane;    // when surface = −1
  double restitution = 0;
  double friction = 0;
  int directions = 0;  // k: 0 frictionless, 2 planar, ≥ 4 spatial
  // On a body's plane with `free_point: true`: the plane's tangent axes (0: t1, 1: t2) along which
  // the optimiser's contact point on the plane is a variable, bounded by the extent, that the
  // point of A is complementary to while it carries a reaction (so A may leave the rectangle when
  // it does not): both axes, or t1 alone in a planar model where t2 is the normal to the plane
  // of motion. Empty: the contact point is A's point, kept over the rectangle at every mesh point.
  std::vector<int> free_axes;
};

// A joint-limit hard stop: a frictionless unilateral contact on coordinate `coordinate`,
// gap = q − lower (upper = false) or upper − q (upper = true).
struct LimitStop {
  std::string name;
  int coordinate = 0;
  bool upper = false;
  double limit = 0;
  double restitution = 0;
};

struct Scene {
  std::string name;
  std::string description;
  std::string source;  // scenario file, or "builtin:<name>"
  dynamics::Model<double> model;
  std::vector<std::string> model_files;  // URDF files the model was read from (none for one written in the file)
  std::vector<Surface> surfaces;
  std::vector<Contact> contacts;
  std::vector<LimitStop> limits;
  Eigen::VectorXd q0, v0;     // initial state (model coordinate order)
  std::string initial_location;  // where the initial state was read ("file:line:column: initial"); empty: built in C++
  Eigen::VectorXd tau;        // constant generalised input (zero when the scene has none)
  double duration = 1.0;      // default simulated time [s]
  std::map<std::string, double> parameters;  // the values used, after --set overrides
};

}  // namespace saltus::scene
