// Scenes built in C++ for the time-stepper and collocation tests, with no more coordinates than each needs.
#pragma once

#include <cmath>
#include <string>

#include "dynamics/builder.hpp"
#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"
#include "scene/scene.hpp"

namespace saltus::testing {

inline scene::Surface plane(const std::string& name, const Eigen::Vector3d& normal = Eigen::Vector3d::UnitZ(),
                                  const Eigen::Vector3d& point = Eigen::Vector3d::Zero()) {
  scene::Surface s;
  s.name = name;
  s.normal = normal.normalized();
  s.point = point;
  return s;
}

inline scene::Contact contactAt(const dynamics::Model<double>& model, const std::string& name,
                                      const std::string& frame, const Eigen::Vector3d& p_F, double e, double mu,
                                      int k) {
  scene::Contact c;
  c.name = name;
  c.link = frame;
  const dynamics::Frame& f = model.frames.at(model.frameIndex(frame));
  c.body = f.body;
  c.p_B = f.p_BF + f.R_BF * p_F;
  c.restitution = e;
  c.friction = mu;
  c.directions = k;
  return c;
}

// A point mass on one vertical coordinate z above the ground z = 0.
inline scene::Scene ballDrop(double height, double e) {
  scene::Scene s;
  s.name = "ball_drop";
  s.model = dynamics::pointMassModel(1.0, Eigen::Vector3d::UnitZ(), "z");
  s.surfaces.push_back(plane("ground"));
  s.contacts.push_back(contactAt(s.model, "ball", "mass", Eigen::Vector3d::Zero(), e, 0, 0));
  s.q0 = Eigen::VectorXd::Constant(1, height);
  s.v0 = Eigen::VectorXd::Zero(1);
  return s;
}

// A particle on a plane inclined by `incline`, in the plane's frame: coordinates s (down the
// slope, along x) and n (normal, along z); gravity rotated accordingly.
inline scene::Scene blockSlide(double incline, double speed, double mu, double g = 9.81) {
  dynamics::ModelBuilder b("particle");
  b.addLink("world");
  b.addLink("slider");
  b.addLink("block", 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  dynamics::JointSpec js;
  js.name = "s";
  js.type = dynamics::LinkJointType::Prismatic;
  js.parent = "world";
  js.child = "slider";
  js.axis = Eigen::Vector3d::UnitX();
  b.addJoint(js);
  dynamics::JointSpec jn;
  jn.name = "n";
  jn.type = dynamics::LinkJointType::Prismatic;
  jn.parent = "slider";
  jn.child = "block";
  jn.axis = Eigen::Vector3d::UnitZ();
  b.addJoint(jn);
  scene::Scene s;
  s.name = "block_slide";
  s.model = b.build(dynamics::BaseType::Fixed, Eigen::Vector3d(g * std::sin(incline), 0, -g * std::cos(incline)));
  s.surfaces.push_back(plane("slope"));
  s.contacts.push_back(contactAt(s.model, "block", "block", Eigen::Vector3d::Zero(), 0, mu, 2));
  s.q0 = Eigen::VectorXd::Zero(2);
  s.v0 = Eigen::Vector2d(speed, 0);
  return s;
}

// A particle on three prismatic coordinates x, y, z on the ground, friction cone with k facets.
inline scene::Scene particle3d(const Eigen::Vector2d& velocity, double mu, int k) {
  dynamics::ModelBuilder b("particle3d");
  b.addLink("world");
  b.addLink("px");
  b.addLink("py");
  b.addLink("p", 1.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  const char* names[3] = {"x", "y", "z"};
  const char* links[4] = {"world", "px", "py", "p"};
  for (int i = 0; i < 3; ++i) {
    dynamics::JointSpec j;
    j.name = names[i];
    j.type = dynamics::LinkJointType::Prismatic;
    j.parent = links[i];
    j.child = links[i + 1];
    j.axis = Eigen::Vector3d::Unit(i);
    b.addJoint(j);
  }
  scene::Scene s;
  s.name = "particle3d";
  s.model = b.build();
  s.surfaces.push_back(plane("ground"));
  s.contacts.push_back(contactAt(s.model, "p", "p", Eigen::Vector3d::Zero(), 0, mu, k));
  s.q0 = Eigen::VectorXd::Zero(3);
  s.v0 = Eigen::Vector3d(velocity.x(), velocity.y(), 0);
  return s;
}

// A point mass (x, z) on a paddle that turns about the world y axis through the origin: a point
// against a plane fixed in a rotating body, so the plane's normal and tangents depend on q. The
// paddle is a thin bar along its x (inertia about y `paddle_inertia`); the ball starts `height`
// above its surface at x = `offset`.
inline scene::Scene ballOnPaddle(double e, double mu, double height = 0.1, double offset = 0.2,
                                 double paddle_inertia = 0.05) {
  dynamics::ModelBuilder b("ball_on_paddle");
  b.addLink("world");
  b.addLink("paddle", 1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(1e-3, paddle_inertia, paddle_inertia).asDiagonal());
  b.addLink("ball_x");
  b.addLink("ball", 0.5, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  auto joint = [&](const char* name, dynamics::LinkJointType type, const char* parent, const char* child,
                   const Eigen::Vector3d& axis) {
    dynamics::JointSpec j;
    j.name = name;
    j.type = type;
    j.parent = parent;
    j.child = child;
    j.axis = axis;
    b.addJoint(j);
  };
  joint("paddle_angle", dynamics::LinkJointType::Revolute, "world", "paddle", Eigen::Vector3d::UnitY());
  joint("x", dynamics::LinkJointType::Prismatic, "world", "ball_x", Eigen::Vector3d::UnitX());
  joint("z", dynamics::LinkJointType::Prismatic, "ball_x", "ball", Eigen::Vector3d::UnitZ());
  scene::Scene s;
  s.name = "ball_on_paddle";
  s.model = b.build();
  scene::Contact c = contactAt(s.model, "ball", "ball", Eigen::Vector3d::Zero(), e, mu, mu > 0 ? 2 : 0);
  c.surface = -1;
  c.plane.link = "paddle";
  c.plane.body = s.model.frames.at(s.model.frameIndex("paddle")).body;
  c.plane.normal = Eigen::Vector3d::UnitZ();
  c.plane.tangents = scene::planeTangents(c.plane.normal);
  c.plane.extent = Eigen::Vector2d(1.0, 0.5);
  s.contacts.push_back(c);
  s.q0 = Eigen::Vector3d(0, offset, height);
  s.v0 = Eigen::VectorXd::Zero(3);
  return s;
}

// The paper's two-link pendulum (unit masses, 0.5 m links) with its tip resting on a belt at
// θ1 = 0, θ2 = π/4; the belt steps from rest to `belt_speed` along +x at `step_time`.
inline scene::Scene pendulumConveyor(double mu, double belt_speed, double step_time) {
  scene::Scene s;
  s.name = "pendulum_conveyor";
  s.model = dynamics::loadUrdfFile(std::string(SALTUS_SOURCE_DIR) + "/models/pendulum/double_pendulum.urdf");
  const double th1 = 0, th2 = M_PI / 4;
  const double z_tip = -0.5 * std::cos(th1) - 0.5 * std::cos(th1 + th2);
  scene::Surface belt = plane("belt", Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, z_tip));
  belt.velocity_schedule.push_back({step_time, Eigen::Vector3d(belt_speed, 0, 0)});
  s.surfaces.push_back(belt);
  s.contacts.push_back(contactAt(s.model, "tip", "tip", Eigen::Vector3d::Zero(), 0, mu, 2));
  s.q0 = Eigen::Vector2d(th1, th2);
  s.v0 = Eigen::VectorXd::Zero(2);
  return s;
}

// A uniform rod (half-length l, mass m) on a planar base, one end on the ground at angle θ to
// it, sliding with that end leading at `speed`.
inline scene::Scene painleveRod(double mu, double angle, double speed, double l = 0.5, double m = 1.0) {
  dynamics::ModelBuilder b("rod");
  const double I = m * (2 * l) * (2 * l) / 12;
  b.addLink("rod", m, Eigen::Vector3d::Zero(), Eigen::Vector3d(1e-6, I, I).asDiagonal());
  scene::Scene s;
  s.name = "painleve_rod";
  s.model = b.build(dynamics::BaseType::Planar);
  s.surfaces.push_back(plane("ground"));
  s.contacts.push_back(contactAt(s.model, "end", "rod", Eigen::Vector3d(l, 0, 0), 0, mu, 2));
  s.q0 = Eigen::Vector3d(0, l * std::sin(angle), angle);
  s.v0 = Eigen::Vector3d(speed, 0, 0);
  return s;
}

}  // namespace saltus::testing
