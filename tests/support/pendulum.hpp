// Planar chains of uniform rods hanging along −z, hinged about y: closed-form references.
#pragma once

#include <cmath>
#include <vector>

#include "dynamics/builder.hpp"

namespace saltus::testing {

// Links i = 1..n: uniform rods of mass m[i] and length L[i]; joint i at the end of rod i−1.
inline dynamics::Model<double> pendulumModel(const std::vector<double>& m, const std::vector<double>& L) {
  using namespace dynamics;
  ModelBuilder b("pendulum");
  b.addLink("world");
  std::string parent = "world";
  for (size_t i = 0; i < m.size(); ++i) {
    const std::string link = "rod" + std::to_string(i + 1);
    // Thin rod along z: m L²/12 across, a small positive value about its own axis.
    const Eigen::Matrix3d Ic = Eigen::Vector3d(m[i] * L[i] * L[i] / 12, m[i] * L[i] * L[i] / 12, 1e-6).asDiagonal();
    b.addLink(link, m[i], Eigen::Vector3d(0, 0, -L[i] / 2), Ic);
    JointSpec j;
    j.name = "joint" + std::to_string(i + 1);
    j.type = LinkJointType::Revolute;
    j.parent = parent;
    j.child = link;
    j.p_PJ = i == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0, -L[i - 1]);
    j.axis = Eigen::Vector3d::UnitY();
    b.addJoint(j);
    parent = link;
  }
  return b.build();
}

// M(θ2) of two uniform rods (com at half length, I = m L²/12 about the com).
inline Eigen::Matrix2d doublePendulumMassMatrix(double m1, double m2, double L1, double L2, double th2) {
  const double c1 = L1 / 2, c2 = L2 / 2, I1 = m1 * L1 * L1 / 12, I2 = m2 * L2 * L2 / 12;
  Eigen::Matrix2d M;
  M(0, 0) = m1 * c1 * c1 + I1 + m2 * (L1 * L1 + c2 * c2 + 2 * L1 * c2 * std::cos(th2)) + I2;
  M(0, 1) = M(1, 0) = m2 * (c2 * c2 + L1 * c2 * std::cos(th2)) + I2;
  M(1, 1) = m2 * c2 * c2 + I2;
  return M;
}

// h = C(θ, θ̇) θ̇ + g(θ), gravity 9.81 along −z, θ = 0 hanging down.
inline Eigen::Vector2d doublePendulumBias(double m1, double m2, double L1, double L2, const Eigen::VectorXd& q,
                                          const Eigen::VectorXd& v, double g = 9.81) {
  const double c1 = L1 / 2, c2 = L2 / 2, s2 = std::sin(q[1]);
  Eigen::Vector2d h;
  h[0] = -m2 * L1 * c2 * s2 * (2 * v[0] * v[1] + v[1] * v[1]) +
         g * (m1 * c1 * std::sin(q[0]) + m2 * (L1 * std::sin(q[0]) + c2 * std::sin(q[0] + q[1])));
  h[1] = m2 * L1 * c2 * s2 * v[0] * v[0] + g * m2 * c2 * std::sin(q[0] + q[1]);
  return h;
}

}  // namespace saltus::testing
