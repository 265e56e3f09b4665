// What the renderer reads from a trajectory: the pose q(t), the finite contact forces at t, the
// impulses and the time range. One implementation reads the CSV rows of `saltus simulate` /
// `saltus optimize` (csv_trajectory.hpp); another can evaluate collocation polynomials.
// Contacts are the scene's contacts (Scene::contacts, in order); joint-limit stops are not drawn.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace saltus::render {

// A force or impulse on the body at a contact (on body A of the pair; its opposite acts on B), in
// the contact layer's frame of the pair's plane (n, t1, t2) (contact::planeFrame): world vector =
// normal n + tangent(0) t1 + tangent(1) t2.
struct ContactLoad {
  double normal = 0;
  Eigen::Vector2d tangent = Eigen::Vector2d::Zero();
  Eigen::Vector3d world(const Eigen::Vector3d& n, const Eigen::Matrix<double, 3, 2>& T) const {
    return normal * n + T * tangent;
  }
  double magnitude() const { return std::sqrt(normal * normal + tangent.squaredNorm()); }
};

// An impulse at instant t on contact `contact` (index into Scene::contacts) [N s].
struct Impulse {
  double t = 0;
  int contact = 0;
  ContactLoad p;
};

class TrajectorySource {
 public:
  virtual ~TrajectorySource() = default;
  virtual double startTime() const = 0;
  virtual double endTime() const = 0;
  // Generalised coordinates at t (model coordinate order); t is clamped to the time range.
  // Positions are continuous at an impulse, so q(t) has one value there.
  virtual Eigen::VectorXd q(double t) const = 0;
  // Finite contact forces at t, one per scene contact [N].
  virtual std::vector<ContactLoad> contactForces(double t) const = 0;
  // Every impulse, sorted by time.
  virtual const std::vector<Impulse>& impulses() const = 0;
};

}  // namespace saltus::render
