// A simulation scene: the model, its surfaces and contacts, joint-limit stops, the initial state
// and the named parameters it was made from. Built from a scenario file (scenario.hpp) or in
// C++; read by the time-stepper (stepper.hpp), the collocation transcription and the renderer.
#pragma once

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "dynamics/model.hpp"

namespace saltus::scene {

// A plane {x : n·(x − p) = 0} whose material moves tangentially with a prescribed velocity
// schedule (a conveyor belt): velocity(t) = the last step's value with time ≤ t, zero before the
// first. The velocity must be tangent to the plane.
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
  double gap(const Eigen::Vector3d& x) const { return normal.dot(x - point); }

  // An orthonormal tangent basis (t1, t2): t1 is the world x axis (else y) projected onto the
  // plane, t2 = n × t1. In a scene moving in the x–z plane with a horizontal surface, t1 = x.
  Eigen::Matrix<double, 3, 2> tangents() const {
    const Eigen::Vector3d a = std::abs(normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d t1 = (a - a.dot(normal) * normal).normalized();
    Eigen::Matrix<double, 3, 2> T;
    T << t1, normal.cross(t1);
    return T;
  }
  // The k unit directions of a polyhedral friction cone on this surface (paper eq. 11): ±t1 for
  // k = 2, otherwise evenly spaced in the tangent plane starting at t1.
  Eigen::Matrix3Xd coneDirections(int k) const {
    const Eigen::Matrix<double, 3, 2> T = tangents();
    Eigen::Matrix3Xd d(3, k);
    for (int j = 0; j < k; ++j) {
      const double angle = 2 * std::numbers::pi * j / k;
      d.col(j) = std::cos(angle) * T.col(0) + std::sin(angle) * T.col(1);
    }
    return d;
  }
};

// A point fixed on a body touching a surface (unilateral normal, Coulomb friction with a
// polyhedral cone of `directions` unit vectors in the tangent plane, Newton restitution).
struct Contact {
  std::string name;
  std::string link;   // URDF link (frame) the point is given in
  int body = -1;      // body the point moves with
  Eigen::Vector3d p_B = Eigen::Vector3d::Zero();  // the point in body coordinates
  int surface = 0;    // index into Scene::surfaces
  double restitution = 0;
  double friction = 0;
  int directions = 0;  // k: 0 frictionless, 2 planar, ≥ 4 spatial
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
  std::vector<Surface> surfaces;
  std::vector<Contact> contacts;
  std::vector<LimitStop> limits;
  Eigen::VectorXd q0, v0;     // initial state (model coordinate order)
  Eigen::VectorXd tau;        // constant generalised input (zero when the scene has none)
  double duration = 1.0;      // default simulated time [s]
  std::map<std::string, double> parameters;  // the values used, after --set overrides
};

}  // namespace saltus::scene
