// Random robots as URDF text, for cross-checks that must start from the same file (URDF reader,
// Bullet). Every random choice comes from the std::mt19937 passed in, so a seed fixes the robot.
//
// Each robot is produced twice: as URDF text, and as the equivalent ModelBuilder (built with the
// URDF conventions applied here, independently of the URDF reader), so tests can also compare
// the reader's model with the builder's.
//
// URDF conventions used (ROS URDF spec): <origin xyz rpy> is a translation then the rotation
// R = Rz(yaw) Ry(pitch) Rx(roll) (fixed-axis roll, pitch, yaw); a joint's origin is the child
// link frame in the parent link frame; <axis> is in the joint frame; <inertial><origin> places the
// inertial frame (com, axes) in the link frame, and <inertia> is the rotational inertia about the
// com in the inertial frame's axes.
#pragma once

#include <cmath>
#include <iomanip>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "dynamics/builder.hpp"

namespace saltus::testing {

struct RandomUrdfOptions {
  double fixed_probability = 0.2;         // a joint is fixed (merged by the reader) with this chance
  double massless_fixed_probability = 0.4;  // a fixed-joint child has no <inertial> with this chance
  double max_offset = 0.5;                // joint origins within ±max_offset per axis [m]
  double max_com = 0.3;                   // coms within ±max_com per axis [m]
};

struct RandomUrdfRobot {
  std::string urdf;
  dynamics::ModelBuilder builder;  // the same robot through the C++ API
  int moving_joints = 0;
  int links = 0;
};

// R = Rz(y) Ry(p) Rx(r), the URDF rpy convention.
inline Eigen::Matrix3d urdfRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

namespace detail {
inline std::string urdfTriple(const Eigen::Vector3d& x) {
  std::ostringstream s;
  s << std::setprecision(17) << x.x() << ' ' << x.y() << ' ' << x.z();
  return s.str();
}
inline std::string urdfNumber(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}
// A value printed with 17 significant digits reads back as the same double.
inline double roundTrip(double x) { return std::stod(urdfNumber(x)); }
inline Eigen::Vector3d roundTrip(const Eigen::Vector3d& x) {
  return {roundTrip(x.x()), roundTrip(x.y()), roundTrip(x.z())};
}
}  // namespace detail

// A random tree of `moving_joints` revolute, continuous or prismatic joints (plus fixed joints,
// about fixed_probability of all joints), random unit axes (some along ±x, ±y, ±z), rotated joint
// origins, and random physically valid inertias: principal moments of a solid box with random
// extents (so the triangle inequality holds), expressed in a randomly rotated frame (full
// tensor with off-diagonal terms) and placed by an <inertial><origin> with random xyz and rpy.
inline RandomUrdfRobot randomUrdfRobot(std::mt19937& rng, int moving_joints,
                                       const RandomUrdfOptions& opt = {},
                                       const std::string& name = "random_robot") {
  using namespace dynamics;
  using detail::roundTrip;
  using detail::urdfNumber;
  using detail::urdfTriple;
  std::uniform_real_distribution<double> unit(-1.0, 1.0), angle(-M_PI, M_PI), prob(0.0, 1.0);
  std::uniform_real_distribution<double> extent(0.05, 1.0), mass_d(0.2, 5.0);

  RandomUrdfRobot out{"", ModelBuilder(name), moving_joints, 0};
  std::ostringstream x;
  x << "<?xml version=\"1.0\"?>\n<robot name=\"" << name << "\">\n";

  auto addLink = [&](const std::string& link, bool with_inertial) {
    if (!with_inertial) {
      x << "  <link name=\"" << link << "\"/>\n";
      out.builder.addLink(link);
      return;
    }
    const double m = roundTrip(mass_d(rng));
    const Eigen::Vector3d com = roundTrip(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * opt.max_com);
    const Eigen::Vector3d rpy = roundTrip(Eigen::Vector3d(angle(rng), angle(rng) / 2, angle(rng)));
    const double a = extent(rng), b = extent(rng), c = extent(rng);
    const Eigen::Vector3d principal(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12);
    const Eigen::Matrix3d Q = urdfRpy(Eigen::Vector3d(angle(rng), angle(rng) / 2, angle(rng)));
    Eigen::Matrix3d I = Q * principal.asDiagonal() * Q.transpose();
    // The six numbers written to the file define the tensor.
    const double ixx = roundTrip(I(0, 0)), iyy = roundTrip(I(1, 1)), izz = roundTrip(I(2, 2));
    const double ixy = roundTrip(0.5 * (I(0, 1) + I(1, 0))), ixz = roundTrip(0.5 * (I(0, 2) + I(2, 0))),
                 iyz = roundTrip(0.5 * (I(1, 2) + I(2, 1)));
    I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
    x << "  <link name=\"" << link << "\">\n"
      << "    <inertial>\n"
      << "      <origin xyz=\"" << urdfTriple(com) << "\" rpy=\"" << urdfTriple(rpy) << "\"/>\n"
      << "      <mass value=\"" << urdfNumber(m) << "\"/>\n"
      << "      <inertia ixx=\"" << urdfNumber(ixx) << "\" ixy=\"" << urdfNumber(ixy) << "\" ixz=\""
      << urdfNumber(ixz) << "\" iyy=\"" << urdfNumber(iyy) << "\" iyz=\"" << urdfNumber(iyz)
      << "\" izz=\"" << urdfNumber(izz) << "\"/>\n"
      << "    </inertial>\n"
      << "  </link>\n";
    const Eigen::Matrix3d R = urdfRpy(rpy);
    out.builder.addLink(link, m, com, R * I * R.transpose());
  };

  addLink("link0", true);
  out.links = 1;
  int moving = 0;
  std::ostringstream joints;
  while (moving < moving_joints) {
    const int l = out.links;
    // Parent: half the time one of the three newest links (long chains), else any link.
    std::uniform_int_distribution<int> any(0, l - 1), recent(std::max(0, l - 3), l - 1);
    const int parent = prob(rng) < 0.5 ? recent(rng) : any(rng);
    JointSpec j;
    j.name = "joint" + std::to_string(l);
    j.parent = "link" + std::to_string(parent);
    j.child = "link" + std::to_string(l);
    const double kind = prob(rng);
    if (kind < opt.fixed_probability) j.type = LinkJointType::Fixed;
    else {
      const double k = prob(rng);
      j.type = k < 0.45 ? LinkJointType::Revolute : k < 0.7 ? LinkJointType::Continuous : LinkJointType::Prismatic;
    }
    const Eigen::Vector3d xyz = roundTrip(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * opt.max_offset);
    const Eigen::Vector3d rpy = roundTrip(Eigen::Vector3d(angle(rng), angle(rng) / 2, angle(rng)));
    Eigen::Vector3d axis;
    if (prob(rng) < 0.3) {
      axis = Eigen::Vector3d::Unit(std::uniform_int_distribution<int>(0, 2)(rng));
      if (prob(rng) < 0.5) axis = -axis;
    } else {
      do axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      while (axis.norm() < 0.2);
      axis = roundTrip(axis.normalized());
    }
    j.R_PJ = urdfRpy(rpy);
    j.p_PJ = xyz;
    j.axis = axis;
    static const char* type_names[] = {"revolute", "continuous", "prismatic", "fixed"};
    joints << "  <joint name=\"" << j.name << "\" type=\"" << type_names[static_cast<int>(j.type)] << "\">\n"
           << "    <parent link=\"" << j.parent << "\"/>\n"
           << "    <child link=\"" << j.child << "\"/>\n"
           << "    <origin xyz=\"" << urdfTriple(xyz) << "\" rpy=\"" << urdfTriple(rpy) << "\"/>\n";
    if (j.type != LinkJointType::Fixed) joints << "    <axis xyz=\"" << urdfTriple(axis) << "\"/>\n";
    if (j.type == LinkJointType::Revolute || j.type == LinkJointType::Prismatic) {
      j.limits = {-2.0, 2.0, 10.0, 100.0};
      joints << "    <limit lower=\"-2\" upper=\"2\" effort=\"100\" velocity=\"10\"/>\n";
    }
    joints << "  </joint>\n";
    const bool with_inertial = j.type != LinkJointType::Fixed || prob(rng) >= opt.massless_fixed_probability;
    addLink(j.child, with_inertial);
    out.builder.addJoint(j);
    if (j.type != LinkJointType::Fixed) ++moving;
    ++out.links;
  }
  x << joints.str() << "</robot>\n";
  out.urdf = x.str();
  return out;
}

}  // namespace saltus::testing
