// Random kinematic trees with random inertias, joints and poses, for consistency tests. Every
// random choice comes from the std::mt19937 passed in, so a seed fixes the model.
#pragma once

#include <algorithm>
#include <random>
#include <tuple>

#include <Eigen/Geometry>

#include "dynamics/builder.hpp"
#include "dynamics/data.hpp"

namespace saltus::testing {

// A valid random inertia: principal moments from random positive "box" extents, rotated.
inline void randomInertia(std::mt19937& rng, double& mass, Eigen::Vector3d& com, Eigen::Matrix3d& Ic) {
  std::uniform_real_distribution<double> u(0.1, 1.0), s(-0.3, 0.3);
  mass = 0.5 + 2 * u(rng);
  com = Eigen::Vector3d(s(rng), s(rng), s(rng));
  const double a = u(rng), b = u(rng), c = u(rng);
  const Eigen::Vector3d d(mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12);
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized().toRotationMatrix();
  Ic = R * d.asDiagonal() * R.transpose();
}

// A random tree of n moving joints grown link by link, each new link hung from a random earlier
// one with a random inertia; `choose(rng, joint)` sets the new joint's type, limits, origin and axis
// and returns whether it moves (fixed joints are merged by the builder).
template <class ChooseJoint>
dynamics::ModelBuilder randomTree(std::mt19937& rng, int n, const std::string& name, const ChooseJoint& choose) {
  using namespace dynamics;
  ModelBuilder b(name);
  double m;
  Eigen::Vector3d c;
  Eigen::Matrix3d I;
  randomInertia(rng, m, c, I);
  b.addLink("link0", m, c, I);
  int links = 1;
  for (int moving = 0; moving < n;) {
    std::uniform_int_distribution<int> pick(0, links - 1);
    JointSpec j;
    j.parent = "link" + std::to_string(pick(rng));
    j.child = "link" + std::to_string(links);
    j.name = "joint" + std::to_string(links);
    if (choose(rng, j)) ++moving;
    randomInertia(rng, m, c, I);
    b.addLink(j.child, m, c, I);
    b.addJoint(j);
    ++links;
  }
  return b;
}

// Revolute, continuous or prismatic joints with random axes (half of them along a coordinate
// axis), random origins, about one in ten fixed.
inline dynamics::ModelBuilder randomTreeBuilder(std::mt19937& rng, int n) {
  using namespace dynamics;
  return randomTree(rng, n, "random", [](std::mt19937& r, JointSpec& j) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int k = std::uniform_int_distribution<int>(0, 9)(r);
    j.type = k < 5 ? LinkJointType::Revolute : k < 7 ? LinkJointType::Continuous
           : k < 9 ? LinkJointType::Prismatic : LinkJointType::Fixed;
    if (j.type == LinkJointType::Revolute || j.type == LinkJointType::Prismatic) j.limits = {-2, 2, 10, 100};
    j.R_PJ = Eigen::Quaterniond(u(r), u(r), u(r), u(r)).normalized().toRotationMatrix();
    j.p_PJ = Eigen::Vector3d(u(r), u(r), u(r)) * 0.5;
    j.axis = k % 2 == 0 ? Eigen::Vector3d(Eigen::Vector3d::Unit((k / 2) % 3)) : Eigen::Vector3d(u(r), u(r), u(r));
    return j.type != LinkJointType::Fixed;
  });
}

// The random tree of randomTreeBuilder(rng, n) hung from the world through the base's
// one-coordinate joints (prismatic x, y, z, revolute z, y, x for Free; prismatic x, z, revolute y
// for Planar), as a fixed-base model.
inline dynamics::Model<double> explicitChain(dynamics::ModelBuilder b, dynamics::BaseType base) {
  using namespace dynamics;
  b.addLink("world");
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  struct Axis {
    const char* name;
    LinkJointType type;
    Eigen::Vector3d axis;
  };
  std::vector<Axis> axes;
  if (base == BaseType::Free)
    axes = {{"base_x", LinkJointType::Prismatic, ex}, {"base_y", LinkJointType::Prismatic, ey},
            {"base_z", LinkJointType::Prismatic, ez}, {"base_yaw", LinkJointType::Continuous, ez},
            {"base_pitch", LinkJointType::Continuous, ey}, {"base_roll", LinkJointType::Continuous, ex}};
  else
    axes = {{"base_x", LinkJointType::Prismatic, ex}, {"base_z", LinkJointType::Prismatic, ez},
            {"base_theta", LinkJointType::Continuous, ey}};
  std::string parent = "world";
  for (std::size_t k = 0; k < axes.size(); ++k) {
    const bool last = k + 1 == axes.size();
    const std::string child = last ? "link0" : std::string("v_") + axes[k].name;
    if (!last) b.addLink(child);
    JointSpec j;
    j.name = axes[k].name;
    j.type = axes[k].type;
    j.parent = parent;
    j.child = child;
    j.axis = axes[k].axis;
    b.addJoint(j);
    parent = child;
  }
  return b.build(BaseType::Fixed);
}

// One of the 24 rotations by multiples of π/2 about the coordinate axes (a signed permutation of
// determinant +1), turned further by `off` radians about a random axis, as URDF rpy written to a
// dozen digits give (dynamics/model.hpp, snapToSignedPermutation).
inline Eigen::Matrix3d randomSignedPermutationRotation(std::mt19937& rng, double off) {
  int perm[3] = {0, 1, 2};
  for (int k = std::uniform_int_distribution<int>(0, 5)(rng); k > 0; --k) std::next_permutation(perm, perm + 3);
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  for (int r = 0; r < 3; ++r) P(r, perm[r]) = std::uniform_int_distribution<int>(0, 1)(rng) ? 1.0 : -1.0;
  if (P.determinant() < 0) P.row(2) *= -1.0;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  return P * Eigen::AngleAxisd(off, axis).toRotationMatrix();
}

// Revolute joints about ±x, ±y, ±z, each with a random joint origin whose rotation is, for about
// half of them, random, for a quarter a multiple of π/2 about the coordinate axes 1e-12 rad off
// (randomSignedPermutationRotation) and for a quarter none (URDF rpy 0 0 0): every joint kernel
// of Model::joint_kernel other than the generic one, and turned frames (Model::turned_frame) down
// chains of signed permutations. About one in eight joints is fixed (merged).
inline dynamics::ModelBuilder randomAxisTreeBuilder(std::mt19937& rng, int n) {
  using namespace dynamics;
  return randomTree(rng, n, "random_axes", [](std::mt19937& r, JointSpec& j) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int k = std::uniform_int_distribution<int>(0, 7)(r);
    j.type = k == 0 ? LinkJointType::Fixed : k < 4 ? LinkJointType::Revolute : LinkJointType::Continuous;
    if (j.type == LinkJointType::Revolute) j.limits = {-2, 2, 10, 100};
    if (k % 2 == 1) j.R_PJ = Eigen::Quaterniond(u(r), u(r), u(r), u(r)).normalized().toRotationMatrix();
    else if (std::uniform_int_distribution<int>(0, 1)(r)) j.R_PJ = randomSignedPermutationRotation(r, 1e-12);
    j.p_PJ = Eigen::Vector3d(u(r), u(r), u(r)) * 0.5;
    const int a = std::uniform_int_distribution<int>(0, 5)(r);
    j.axis = Eigen::Vector3d::Unit(a % 3) * (a < 3 ? 1.0 : -1.0);
    return j.type != LinkJointType::Fixed;
  });
}

inline Eigen::VectorXd randomVector(std::mt19937& rng, int n, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = u(rng);
  return x;
}

// For the argument-size checks of the dynamics functions: a 3-coordinate random tree, its
// workspace, and zero vectors of the right length and of one more.
struct ArgumentSizes {
  dynamics::Model<double> model;
  dynamics::Data<double> data;
  Eigen::VectorXd ok, bad;
  ArgumentSizes()
      : model([] {
          std::mt19937 rng(3);
          return randomTreeBuilder(rng, 3).build(dynamics::BaseType::Fixed);
        }()),
        data(model),
        ok(Eigen::VectorXd::Zero(model.nv())),
        bad(Eigen::VectorXd::Zero(model.nv() + 1)) {}
};

}  // namespace saltus::testing
