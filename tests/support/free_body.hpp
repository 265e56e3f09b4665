// A single rigid body on a free base, and an independent map from its Euler coordinates
// (x, y, z, yaw ψ, pitch θ, roll φ; R = Rz(ψ) Ry(θ) Rx(φ)) to world velocities.
#pragma once

#include <Eigen/Geometry>

#include "dynamics/builder.hpp"

namespace saltus::testing {

inline dynamics::Model<double> freeBodyModel(double mass, const Eigen::Vector3d& com, const Eigen::Matrix3d& Ic,
                                             const Eigen::Vector3d& gravity = Eigen::Vector3d(0, 0, -9.81)) {
  dynamics::ModelBuilder b("free_body");
  b.addLink("body", mass, com, Ic);
  return b.build(dynamics::BaseType::Free, gravity);
}

inline Eigen::Matrix3d eulerRotation(const Eigen::VectorXd& q) {
  using Eigen::AngleAxisd;
  return (AngleAxisd(q[3], Eigen::Vector3d::UnitZ()) * AngleAxisd(q[4], Eigen::Vector3d::UnitY()) *
          AngleAxisd(q[5], Eigen::Vector3d::UnitX())).toRotationMatrix();
}

// World angular velocity from Euler rates: ω = ψ̇ z + Rz(ψ) θ̇ y + Rz(ψ) Ry(θ) φ̇ x.
inline Eigen::Vector3d eulerAngularVelocity(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  using Eigen::AngleAxisd;
  const Eigen::Matrix3d Rz = AngleAxisd(q[3], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d Ry = AngleAxisd(q[4], Eigen::Vector3d::UnitY()).toRotationMatrix();
  return v[3] * Eigen::Vector3d::UnitZ() + Rz * (v[4] * Eigen::Vector3d::UnitY()) +
         Rz * Ry * (v[5] * Eigen::Vector3d::UnitX());
}

}  // namespace saltus::testing
