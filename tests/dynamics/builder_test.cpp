// The builder API (dynamics/builder.hpp): each validation error names the element, and the
// point-mass model.
#include "dynamics/builder.hpp"

#include <gtest/gtest.h>

#include <functional>

#include "dynamics/dynamics.hpp"

namespace saltus::dynamics {
namespace {

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

const Eigen::Matrix3d kInertia = Eigen::Vector3d(0.1, 0.2, 0.25).asDiagonal();

JointSpec joint(const std::string& name, const std::string& parent, const std::string& child,
                LinkJointType type = LinkJointType::Revolute) {
  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = parent;
  j.child = child;
  j.axis = Eigen::Vector3d::UnitZ();
  return j;
}

// world -> a -> b, all valid; tests break one thing each.
ModelBuilder chain() {
  ModelBuilder b("chain");
  b.setSource("chain.test");
  b.addLink("world");
  b.addLink("a", 1.0, Eigen::Vector3d(0, 0, 0.1), kInertia);
  b.addLink("b", 2.0, Eigen::Vector3d(0.1, 0, 0), kInertia);
  b.addJoint(joint("ja", "world", "a"));
  b.addJoint(joint("jb", "a", "b"));
  return b;
}

// The ModelError message of building b; it must start with the source.
std::string buildError(const ModelBuilder& b) {
  try {
    b.build();
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("chain.test: ", 0), 0u) << what;
    return what;
  }
  ADD_FAILURE() << "no ModelError thrown";
  return "";
}

TEST(Builder, ValidChainBuilds) {
  const Model<double> model = chain().build();
  EXPECT_EQ(model.nv(), 2);
  EXPECT_EQ(model.source, "chain.test");
  EXPECT_DOUBLE_EQ(model.totalMass(), 3.0);
}

TEST(Builder, DuplicateLink) {
  ModelBuilder b = chain();
  b.addLink("a");
  EXPECT_HAS(buildError(b), "link 'a' is defined twice");
}

TEST(Builder, UnknownParentLink) {
  ModelBuilder b = chain();
  b.addLink("c", 1.0, Eigen::Vector3d::Zero(), kInertia);
  b.addJoint(joint("jc", "nowhere", "c"));
  const std::string what = buildError(b);
  EXPECT_HAS(what, "joint 'jc'");
  EXPECT_HAS(what, "parent link 'nowhere' does not exist");
}

TEST(Builder, LoopThroughTwoParents) {
  ModelBuilder b = chain();
  b.addJoint(joint("jb2", "world", "b"));
  const std::string what = buildError(b);
  EXPECT_HAS(what, "kinematic loop");
  EXPECT_HAS(what, "link 'b'");
  EXPECT_HAS(what, "'jb'");
  EXPECT_HAS(what, "'jb2'");
}

TEST(Builder, TwoRoots) {
  ModelBuilder b = chain();
  b.addLink("island", 1.0, Eigen::Vector3d::Zero(), kInertia);
  const std::string what = buildError(b);
  EXPECT_HAS(what, "'world'");
  EXPECT_HAS(what, "'island'");
  EXPECT_HAS(what, "no parent joint");
}

TEST(Builder, ZeroAxis) {
  ModelBuilder b = chain();
  JointSpec j = joint("jc", "b", "c");
  j.axis = Eigen::Vector3d::Zero();
  b.addLink("c", 1.0, Eigen::Vector3d::Zero(), kInertia);
  b.addJoint(j);
  const std::string what = buildError(b);
  EXPECT_HAS(what, "joint 'jc'");
  EXPECT_HAS(what, "axis");
}

TEST(Builder, LowerLimitAboveUpper) {
  ModelBuilder b = chain();
  JointSpec j = joint("jc", "b", "c", LinkJointType::Prismatic);
  j.limits.lower = 1.0;
  j.limits.upper = -1.0;
  b.addLink("c", 1.0, Eigen::Vector3d::Zero(), kInertia);
  b.addJoint(j);
  const std::string what = buildError(b);
  EXPECT_HAS(what, "joint 'jc'");
  EXPECT_HAS(what, "lower limit");
}

TEST(Builder, MissingInertialOnMovingLink) {
  ModelBuilder b = chain();
  b.addLink("c");
  b.addJoint(joint("jc", "b", "c"));
  const std::string what = buildError(b);
  EXPECT_HAS(what, "link 'c'");
  EXPECT_HAS(what, "joint 'jc'");
  EXPECT_HAS(what, "<inertial>");
}

TEST(Builder, MasslessLinkFixedToMovingOneIsFine) {
  ModelBuilder b = chain();
  b.addLink("marker");
  b.addJoint(joint("jm", "b", "marker", LinkJointType::Fixed));
  const Model<double> model = b.build();
  EXPECT_EQ(model.nv(), 2);
  EXPECT_EQ(model.frames[model.frameIndex("marker")].body, model.bodyIndex("b"));
}

TEST(Builder, NonPositiveMass) {
  for (double mass : {0.0, -1.0}) {
    ModelBuilder b = chain();
    b.addLink("c", mass, Eigen::Vector3d::Zero(), kInertia);
    b.addJoint(joint("jc", "b", "c"));
    const std::string what = buildError(b);
    EXPECT_HAS(what, "link 'c'");
    EXPECT_HAS(what, "mass must be positive");
  }
}

TEST(Builder, TriangleInequality) {
  ModelBuilder b = chain();
  b.addLink("c", 1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1, 0.1, 0.5).asDiagonal());
  b.addJoint(joint("jc", "b", "c"));
  const std::string what = buildError(b);
  EXPECT_HAS(what, "link 'c'");
  EXPECT_HAS(what, "triangle inequality");
}

TEST(Builder, CheckInertiaPointMassOnlyWhenAllowed) {
  EXPECT_EQ(checkInertia(1.0, Eigen::Matrix3d::Zero(), true), "");
  EXPECT_HAS(checkInertia(1.0, Eigen::Matrix3d::Zero(), false), "not positive definite");
  EXPECT_EQ(checkInertia(1.0, kInertia, false), "");
}

TEST(Builder, PointMassModel) {
  const double m = 2.5;
  const Model<double> model = pointMassModel(m, Eigen::Vector3d(0, 0, 2));  // axis normalised
  ASSERT_EQ(model.nv(), 1);
  EXPECT_EQ(model.joint_type[0], JointType::Prismatic);
  Data<double> data(model);
  const Eigen::MatrixXd M = crba(model, data, Eigen::VectorXd::Constant(1, 0.3));
  EXPECT_DOUBLE_EQ(M(0, 0), m);
  EXPECT_THROW(pointMassModel(m, Eigen::Vector3d::Zero()), ModelError);
}

}  // namespace
}  // namespace saltus::dynamics
