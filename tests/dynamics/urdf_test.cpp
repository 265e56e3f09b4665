// The URDF reader (dynamics/urdf.hpp): error messages, inertial frames, fixed-joint merging,
// limits, visuals, the bundled models.
#include "dynamics/urdf.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iomanip>
#include <random>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <console_bridge/console.h>

#include "dynamics/dynamics.hpp"
#include "saltus/build_paths.hpp"
#include "tests/support/errors.hpp"

namespace saltus::dynamics {
namespace {

const std::string kDataDir = std::string(SALTUS_SOURCE_DIR) + "/tests/data/urdf/";
const std::string kModelDir = std::string(SALTUS_SOURCE_DIR) + "/models/";

// The ModelError message of f, or a test failure.
std::string errorOf(const std::function<void()>& f) { return testing::expectedMessageOf<ModelError>(f); }

// Error of loading a fixture: the message must start with the file's path.
std::string loadError(const std::string& fixture, BaseType base = BaseType::Fixed) {
  const std::string path = kDataDir + fixture;
  const std::string what = errorOf([&] { loadUrdfFile(path, base); });
  EXPECT_EQ(what.rfind(path + ":", 0), 0u) << what;  // "path: " or "path:LINE: "
  return what;
}

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

// R = Rz(yaw) Ry(pitch) Rx(roll), the URDF rpy convention.
Eigen::Matrix3d rpyRotation(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}
Eigen::Vector3d rpyOf(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d ypr = R.eulerAngles(2, 1, 0);
  return {ypr.z(), ypr.y(), ypr.x()};
}

std::string num(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}
std::string triple(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

// An <inertial> element.
std::string inertialXml(double m, const Eigen::Vector3d& com, const Eigen::Vector3d& rpy, const Eigen::Matrix3d& I) {
  return "<inertial><origin xyz=\"" + triple(com) + "\" rpy=\"" + triple(rpy) + "\"/><mass value=\"" + num(m) +
         "\"/><inertia ixx=\"" + num(I(0, 0)) + "\" ixy=\"" + num(I(0, 1)) + "\" ixz=\"" + num(I(0, 2)) +
         "\" iyy=\"" + num(I(1, 1)) + "\" iyz=\"" + num(I(1, 2)) + "\" izz=\"" + num(I(2, 2)) + "\"/></inertial>";
}
std::string jointXml(const std::string& name, const std::string& type, const std::string& parent,
                     const std::string& child, const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy,
                     const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ()) {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" +
         child + "\"/><origin xyz=\"" + triple(xyz) + "\" rpy=\"" + triple(rpy) + "\"/><axis xyz=\"" +
         triple(axis) + "\"/></joint>";
}

Eigen::VectorXd randomVector(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = u(rng);
  return x;
}

// ---- errors: each names the file and the element --------------------------------------------------

TEST(UrdfErrors, MissingFile) {
  const std::string what = loadError("no_such_file.urdf");
  EXPECT_HAS(what, "cannot open");
  EXPECT_HAS(what, "No such file");
}

TEST(UrdfErrors, AFolderOrADeviceIsNotRead) {  // /dev/zero would be read for ever
  for (const std::string& path : {std::string(kDataDir), std::string("/dev/zero")}) {
    const std::string what = errorOf([&] { readUrdfFile(path); });
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_HAS(what, path == kDataDir ? "is a folder" : "not a regular file");
  }
}

TEST(UrdfErrors, MalformedXmlQuotesTheParser) {
  const std::string what = loadError("malformed.urdf");
  EXPECT_HAS(what, "malformed.urdf:5: not well-formed XML");  // the row TinyXML stopped at
  EXPECT_HAS(what, "Error reading end tag");                  // TinyXML's message
}

TEST(UrdfErrors, MissingInertialOnMovingLink) {
  const std::string what = loadError("missing_inertial.urdf");
  EXPECT_HAS(what, "link 'arm'");
  EXPECT_HAS(what, "joint 'shoulder'");
  EXPECT_HAS(what, "<inertial>");
}

TEST(UrdfErrors, NonPositiveMass) {
  const std::string what = loadError("zero_mass.urdf");
  EXPECT_HAS(what, "link 'arm'");
  EXPECT_HAS(what, "mass must be positive");
}

// A two-axis (Hooke) joint: roll about x, then pitch about y, through a cross declared massless
// (mass 0, inertia 0). An arm of mass m, com l below the joint, inertia diag(Ixx, Iyy, Izz) about
// its com: M = diag(Ixx + m l², Iyy + m l²) hanging down; pitched by π/2 the arm lies along the
// roll axis, so the roll sees only Izz.
std::string hookeJoint(const std::string& cross_inertial, bool arm = true) {
  return "<robot name=\"hooke\"><link name=\"base\"/>"
         "<link name=\"cross\">" + cross_inertial + "</link>" +
         (arm ? "<link name=\"arm\"><inertial><origin xyz=\"0 0 -0.5\"/><mass value=\"2\"/>"
                "<inertia ixx=\"0.3\" ixy=\"0\" ixz=\"0\" iyy=\"0.25\" iyz=\"0\" izz=\"0.06\"/></inertial></link>"
              : "") +
         "<joint name=\"roll\" type=\"continuous\"><parent link=\"base\"/><child link=\"cross\"/><axis xyz=\"1 0 0\"/></joint>" +
         (arm ? "<joint name=\"pitch\" type=\"continuous\"><parent link=\"cross\"/><child link=\"arm\"/><axis xyz=\"0 1 0\"/></joint>"
              : "") +
         "</robot>";
}

TEST(Urdf, ADeclaredMasslessCrossCarriesATwoAxisJoint) {
  const std::string massless = "<inertial><mass value=\"0\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial>";
  const Model<double> model = loadUrdfString(hookeJoint(massless), BaseType::Fixed, "hooke.urdf");
  ASSERT_EQ(model.nv(), 2);
  Data<double> data(model);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(2);
  Eigen::MatrixXd M = crba(model, data, q);  // both triangles
  EXPECT_NEAR(M(0, 0), 0.3 + 2 * 0.25, 1e-12);
  EXPECT_NEAR(M(1, 1), 0.25 + 2 * 0.25, 1e-12);
  EXPECT_NEAR(M(0, 1), 0.0, 1e-12);
  q << 0.3, M_PI / 2;
  M = crba(model, data, q);
  EXPECT_NEAR(M(0, 0), 0.06, 1e-12);  // the arm along the roll axis: its own Izz only
  EXPECT_NEAR(M(1, 1), 0.25 + 2 * 0.25, 1e-12);

  // Declared massless with nothing below: the mass matrix would be singular.
  const std::string leaf = errorOf([&] { loadUrdfString(hookeJoint(massless, false), BaseType::Fixed, "leaf.urdf"); });
  EXPECT_HAS(leaf, "link 'cross' moves (joint 'roll') but its <inertial> has no mass, and no body below it has mass");
  // Mass 0 with an inertia is no declaration: still refused.
  const std::string half = errorOf([&] {
    loadUrdfString(hookeJoint("<inertial><mass value=\"0\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>"),
                   BaseType::Fixed, "half.urdf");
  });
  EXPECT_HAS(half, "mass must be positive");
}

TEST(UrdfErrors, InertiaNotPositiveDefinite) {
  const std::string what = loadError("inertia_not_positive_definite.urdf");
  EXPECT_HAS(what, "link 'forearm': inertia is not positive definite (principal moments");
}

TEST(UrdfErrors, InertiaBreaksTriangleInequality) {
  const std::string what = loadError("inertia_triangle.urdf");
  EXPECT_HAS(what, "link 'forearm'");
  EXPECT_HAS(what, "triangle inequality");
}

TEST(UrdfErrors, LoopWithoutRootRejectedByUrdfdom) {
  const std::string what = loadError("loop_closed.urdf");
  EXPECT_HAS(what, "kinematic loop");
  EXPECT_HAS(what, "'a'");
  EXPECT_HAS(what, "'b'");
  EXPECT_HAS(what, "urdfdom:");
}

TEST(UrdfErrors, LoopThroughLinkWithTwoParents) {
  const std::string what = loadError("loop_two_parents.urdf");
  EXPECT_HAS(what, "kinematic loop");
  EXPECT_HAS(what, "link 'b'");
  EXPECT_HAS(what, "'a_to_b'");
  EXPECT_HAS(what, "'base_to_b'");
}

TEST(UrdfErrors, LoopDetachedFromTheTree) {
  const std::string what = loadError("loop_detached.urdf");
  EXPECT_HAS(what, "kinematic loop");
  EXPECT_HAS(what, "link 'a'");
  EXPECT_HAS(what, "'base'");
}

TEST(UrdfErrors, FloatingJointUnsupported) {
  const std::string what = loadError("joint_floating.urdf");
  EXPECT_HAS(what, "joint 'free_flyer'");
  EXPECT_HAS(what, "'floating'");
}

TEST(UrdfErrors, PlanarJointUnsupported) {
  const std::string what = loadError("joint_planar.urdf");
  EXPECT_HAS(what, "joint 'slider_plane'");
  EXPECT_HAS(what, "'planar'");
}

TEST(UrdfErrors, StringUsesSourceName) {
  const std::string what = errorOf([] { loadUrdfString("<robot name=\"r\"><link name=\"a\"></robot>", BaseType::Fixed, "my_source"); });
  EXPECT_EQ(what.rfind("my_source:1: ", 0), 0u) << what;
  const std::string unnamed = errorOf([] { readUrdfString("<robot"); });
  EXPECT_EQ(unnamed.rfind("<string>:1: ", 0), 0u) << unnamed;
}

// A hostile file of 100,000 nested elements after valid content overflowed TinyXML's recursive
// parser (SIGSEGV): it is refused before parsing, naming the line of the element too deep. Valid
// content nested a few levels, comments, CDATA and '>' inside quoted values are not counted.
TEST(UrdfErrors, ElementsNestedTooDeepAreRefusedBeforeParsing) {
  const std::string valid =
      "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n<!-- <a><b><c> -->\n<link name=\"base\"/>\n"
      "<link name=\"l1\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" "
      "iyz=\"0\" izz=\"1\"/></inertial><visual name=\"a>b\"><geometry><box size=\"1 1 1\"/></geometry>"
      "</visual></link>\n<joint name=\"j\" type=\"revolute\"><parent link=\"base\"/><child link=\"l1\"/>"
      "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n";
  EXPECT_EQ(loadUrdfString(valid + "</robot>").nq(), 1);
  std::string deep = valid;
  for (int i = 0; i < 100000; ++i) deep += "<a>";
  const std::string what = errorOf([&] { loadUrdfString(deep + "</robot>", BaseType::Fixed, "deep.urdf"); });
  EXPECT_EQ(what.rfind("deep.urdf:7: XML elements nested deeper than 100 levels", 0), 0u) << what;
  std::string at_limit = valid;  // robot + 99 levels: accepted by the scan, then urdfdom's own message
  for (int i = 0; i < 99; ++i) at_limit += "<a>";
  EXPECT_EQ(errorOf([&] { loadUrdfString(at_limit + "</robot>"); }).find("nested deeper"), std::string::npos);
}

// Negative or non-finite joint maxima and shape sizes are typos the model would carry on with:
// refused, naming the joint or link and the value; so is what urdfdom reports as an error and drops.
TEST(UrdfErrors, NegativeLimitsAndShapeSizesAreRefused) {
  auto robot = [](const std::string& limit, const std::string& geometry) {
    return "<robot name=\"r\"><link name=\"base\"/><link name=\"l1\"><inertial><mass value=\"1\"/>"
           "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial><visual><geometry>" +
           geometry + "</geometry></visual></link><joint name=\"j\" type=\"revolute\"><parent link=\"base\"/>"
           "<child link=\"l1\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" " + limit + "/></joint></robot>";
  };
  const std::string good_limit = "effort=\"10\" velocity=\"3\"", good_box = "<box size=\"1 2 3\"/>";
  EXPECT_EQ(loadUrdfString(robot(good_limit, good_box)).nq(), 1);
  EXPECT_EQ(loadUrdfString(robot(good_limit, "<mesh filename=\"m.stl\" scale=\"-1 1 1\"/>")).nq(), 1);  // mirrored
  std::string what = errorOf([&] { loadUrdfString(robot("effort=\"-10\" velocity=\"3\"", good_box)); });
  EXPECT_HAS(what, "joint 'j': <limit effort>: expected a non-negative, finite maximum, got <limit ");
  EXPECT_HAS(what, "effort=\"-10\"");  // as written
  what = errorOf([&] { loadUrdfString(robot("effort=\"10\" velocity=\"-3\"", good_box)); });
  EXPECT_HAS(what, "joint 'j': <limit velocity>");
  what = errorOf([&] { loadUrdfString(robot(good_limit, "<box size=\"-1 2 0\"/>")); });
  EXPECT_HAS(what, "link 'l1': visual box size: expected positive lengths of at most 1e6 m, got '-1 2 0'");
  // urdfdom cannot read "nan": it reports an error and drops the visual; the error is the refusal.
  what = errorOf([&] { loadUrdfString(robot(good_limit, "<box size=\"1 nan 1\"/>")); });
  EXPECT_HAS(what, "not a valid URDF (urdfdom: Unable to parse component [nan]");
  what = errorOf([&] { loadUrdfString(robot(good_limit, "<sphere radius=\"0\"/>")); });
  EXPECT_HAS(what, "link 'l1': visual sphere size");
}

// console_bridge: urdfdom's messages go into the error, never to stderr; the user's handler and
// log level are restored.
TEST(UrdfErrors, ParserOutputCapturedAndHandlerRestored) {
  struct Recorder : console_bridge::OutputHandler {
    std::vector<std::string> texts;
    void log(const std::string& text, console_bridge::LogLevel, const char*, int) override { texts.push_back(text); }
  } recorder;
  console_bridge::OutputHandler* const original = console_bridge::getOutputHandler();
  const console_bridge::LogLevel original_level = console_bridge::getLogLevel();
  console_bridge::useOutputHandler(&recorder);
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);

  ::testing::internal::CaptureStderr();
  ::testing::internal::CaptureStdout();
  errorOf([] { loadUrdfFile(kDataDir + "malformed.urdf"); });
  // Succeeds although urdfdom warns about the undefined material.
  const Model<double> model = loadUrdfString(
      "<robot name=\"r\"><link name=\"a\"><visual><geometry><sphere radius=\"1\"/></geometry>"
      "<material name=\"undefined_here\"/></visual></link></robot>");
  const std::string err = ::testing::internal::GetCapturedStderr();
  const std::string out = ::testing::internal::GetCapturedStdout();

  EXPECT_EQ(console_bridge::getOutputHandler(), &recorder);
  EXPECT_EQ(console_bridge::getLogLevel(), console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
  EXPECT_TRUE(recorder.texts.empty()) << recorder.texts.front();
  EXPECT_EQ(err, "");
  EXPECT_EQ(out, "");
  EXPECT_EQ(model.visuals.size(), 1u);
  CONSOLE_BRIDGE_logError("after the parse");  // the user's handler receives messages again
  EXPECT_EQ(recorder.texts, std::vector<std::string>{"after the parse"});

  console_bridge::useOutputHandler(original);
  console_bridge::setLogLevel(original_level);
}

TEST(Urdf, ParseBaseType) {
  EXPECT_EQ(parseBaseType("fixed"), BaseType::Fixed);
  EXPECT_EQ(parseBaseType("planar"), BaseType::Planar);
  EXPECT_EQ(parseBaseType("free"), BaseType::Free);
  try {
    parseBaseType("floating");
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_HAS(what, "'floating'");
    EXPECT_HAS(what, "fixed");
    EXPECT_HAS(what, "planar");
    EXPECT_HAS(what, "free");
  }
}

// ---- what the reader keeps -----------------------------------------------------------------------

// I_link = R I_inertial Rᵀ: a rotated inertial frame equals the unrotated full tensor.
TEST(Urdf, RotatedInertialFrameEqualsUnrotatedDescription) {
  const double m = 2.5;
  const Eigen::Vector3d com(0.1, -0.2, 0.05), rpy(0.3, -0.7, 1.1);
  const Eigen::Matrix3d I_inertial = Eigen::Vector3d(0.2, 0.3, 0.4).asDiagonal();
  const Eigen::Matrix3d R = rpyRotation(rpy);
  const Eigen::Matrix3d I_link = R * I_inertial * R.transpose();
  auto robot = [&](const std::string& inertial) {
    return "<robot name=\"r\"><link name=\"world\"/><link name=\"body\">" + inertial + "</link>" +
           jointXml("hinge", "continuous", "world", "body", {0.3, 0, 1}, {0.2, 0, 0}) + "</robot>";
  };
  const Model<double> rotated = loadUrdfString(robot(inertialXml(m, com, rpy, I_inertial)));
  const Model<double> plain = loadUrdfString(robot(inertialXml(m, com, Eigen::Vector3d::Zero(), I_link)));
  ASSERT_EQ(rotated.nv(), 1);
  EXPECT_DOUBLE_EQ(rotated.inertia[0].m, m);
  EXPECT_LT((rotated.inertia[0].h - m * com).norm(), 1e-14);
  EXPECT_LT((rotated.inertia[0].h - plain.inertia[0].h).norm(), 1e-14);
  EXPECT_LT((rotated.inertia[0].I - plain.inertia[0].I).norm(), 1e-14);
  const Eigen::Matrix3d cx = skew(com);
  EXPECT_LT((rotated.inertia[0].I - (I_link - m * cx * cx)).norm(), 1e-14);
}

// upper --fixed--> lower is one body: same M as the hand-combined inertia, and 'lower' stays a
// Frame on the body of 'upper' at the fixed joint's pose.
TEST(Urdf, FixedJointMergedIntoParentBody) {
  const double m1 = 1.5, m2 = 0.7, m3 = 1.1;
  const Eigen::Vector3d c1(0.1, 0, 0.2), c2(0, 0.05, -0.1), c3(0.2, 0.1, 0);
  const Eigen::Matrix3d I1 = Eigen::Vector3d(0.05, 0.06, 0.07).asDiagonal(),
                        I2 = Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal(),
                        I3 = Eigen::Vector3d(0.01, 0.02, 0.025).asDiagonal();
  const Eigen::Vector3d rpy2(0.1, 0.2, 0.3);  // lower's inertial frame rotation
  const Eigen::Vector3d p_UL(0.3, 0.1, -0.2), rpy_UL(0.4, 0.2, -0.5);  // fixed joint: lower in upper
  const Eigen::Vector3d p_LH(0.2, 0, 0), rpy_LH(0.1, 0, 0);             // elbow: hand in lower
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d R_UL = rpyRotation(rpy_UL);

  // With the fixed joint.
  const std::string merged =
      "<robot name=\"merged\"><link name=\"world\"/>"
      "<link name=\"upper\">" + inertialXml(m1, c1, zero, I1) + "</link>"
      "<link name=\"lower\">" + inertialXml(m2, c2, rpy2, I2) + "</link>"
      "<link name=\"hand\">" + inertialXml(m3, c3, zero, I3) + "</link>" +
      jointXml("shoulder", "continuous", "world", "upper", {0, 0, 1}, {0, 0.3, 0}, {0, 1, 0}) +
      jointXml("weld", "fixed", "upper", "lower", p_UL, rpy_UL) +
      jointXml("elbow", "continuous", "lower", "hand", p_LH, rpy_LH, {1, 0, 0}) + "</robot>";

  // Combined by hand in upper's frame U: com and inertia about it (parallel axis theorem).
  const Eigen::Vector3d c2_U = p_UL + R_UL * c2;
  const Eigen::Matrix3d R2 = R_UL * rpyRotation(rpy2);
  const Eigen::Matrix3d I2_U = R2 * I2 * R2.transpose();
  const double m = m1 + m2;
  const Eigen::Vector3d c = (m1 * c1 + m2 * c2_U) / m;
  auto shift = [&](double mi, const Eigen::Vector3d& d) {
    return Eigen::Matrix3d(mi * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose()));
  };
  const Eigen::Matrix3d I = I1 + shift(m1, c1 - c) + I2_U + shift(m2, c2_U - c);
  const Eigen::Vector3d p_UH = p_UL + R_UL * p_LH;
  const Eigen::Matrix3d R_UH = R_UL * rpyRotation(rpy_LH);
  const std::string combined =
      "<robot name=\"combined\"><link name=\"world\"/>"
      "<link name=\"upper\">" + inertialXml(m, c, zero, I) + "</link>"
      "<link name=\"hand\">" + inertialXml(m3, c3, zero, I3) + "</link>" +
      jointXml("shoulder", "continuous", "world", "upper", {0, 0, 1}, {0, 0.3, 0}, {0, 1, 0}) +
      jointXml("elbow", "continuous", "upper", "hand", p_UH, rpyOf(R_UH), {1, 0, 0}) + "</robot>";

  const Model<double> a = loadUrdfString(merged), b = loadUrdfString(combined);
  ASSERT_EQ(a.nv(), 2);
  ASSERT_EQ(b.nv(), 2);
  Data<double> da(a), db(b);
  std::mt19937 rng(7);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd q = randomVector(rng, 2) * 3;
    const Eigen::MatrixXd Ma = crba(a, da, q), Mb = crba(b, db, q);
    EXPECT_LT((Ma - Mb).norm(), 1e-12 * Ma.norm()) << "q = " << q.transpose() << "\n" << Ma << "\n\n" << Mb;
  }

  // The merged link keeps its frame, on upper's body, at the fixed joint's pose.
  const int f = a.frameIndex("lower");
  ASSERT_GE(f, 0);
  EXPECT_EQ(a.bodyIndex("lower"), -1);
  EXPECT_EQ(a.frames[f].body, a.bodyIndex("upper"));
  EXPECT_LT((a.frames[f].R_BF - R_UL).norm(), 1e-14);
  EXPECT_LT((a.frames[f].p_BF - p_UL).norm(), 1e-14);
  const int h = a.frameIndex("hand");
  ASSERT_GE(h, 0);
  EXPECT_EQ(a.frames[h].body, a.bodyIndex("hand"));
  EXPECT_TRUE(a.frames[h].R_BF.isIdentity(0) && a.frames[h].p_BF.isZero(0));
}

TEST(Urdf, JointLimits) {
  const Model<double> model = loadUrdfFile(kDataDir + "limits.urdf");
  ASSERT_EQ(model.nv(), 4);
  auto limits = [&](const std::string& joint) {
    const int i = model.coordinateIndex(joint);
    EXPECT_GE(i, 0) << joint;
    return i < 0 ? JointLimits{} : model.limits[i];
  };
  const JointLimits rev = limits("rev"), cont = limits("cont"), free = limits("cont_free"), pris = limits("pris");
  EXPECT_EQ(rev.lower, -1.0);
  EXPECT_EQ(rev.upper, 2.0);
  EXPECT_EQ(rev.velocity, 4.0);
  EXPECT_EQ(rev.effort, 30.0);
  EXPECT_FALSE(cont.hasPositionLimits());  // continuous: no position limits, rates kept
  EXPECT_EQ(cont.velocity, 6.0);
  EXPECT_EQ(cont.effort, 5.0);
  EXPECT_FALSE(free.hasPositionLimits());
  EXPECT_EQ(free.velocity, kInf);
  EXPECT_EQ(free.effort, kInf);
  EXPECT_EQ(pris.lower, -0.1);
  EXPECT_EQ(pris.upper, 0.3);
  EXPECT_EQ(pris.velocity, 0.5);
  EXPECT_EQ(pris.effort, 100.0);
  EXPECT_EQ(model.joint_type[model.coordinateIndex("pris")], JointType::Prismatic);
}

TEST(Urdf, VisualsInBodyFrames) {
  const Model<double> model = loadUrdfFile(kDataDir + "visuals.urdf");
  ASSERT_EQ(model.nv(), 1);
  ASSERT_EQ(model.visuals.size(), 5u);
  const int arm = model.bodyIndex("arm");
  auto find = [&](const std::string& link, Visual::Shape shape) -> const Visual& {
    for (const Visual& v : model.visuals)
      if (v.link == link && v.shape == shape) return v;
    ADD_FAILURE() << "no visual on " << link;
    return model.visuals.front();
  };
  const Eigen::Vector4d grey = Visual().rgba, red(1, 0, 0, 1);

  const Visual& ground = find("world", Visual::Shape::Box);
  EXPECT_EQ(ground.body, -1);
  EXPECT_LT((ground.p_BG - Eigen::Vector3d(0, 0, -0.05)).norm(), 1e-15);
  EXPECT_EQ(ground.size, Eigen::Vector3d(2, 2, 0.1));
  EXPECT_EQ(ground.rgba, grey);

  const Visual& box = find("arm", Visual::Shape::Box);  // named robot-level material
  EXPECT_EQ(box.body, arm);
  EXPECT_LT((box.p_BG - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 1e-15);
  EXPECT_LT((box.R_BG - rpyRotation({0, 0, M_PI / 2})).norm(), 1e-15);
  EXPECT_EQ(box.size, Eigen::Vector3d(0.4, 0.5, 0.6));
  EXPECT_EQ(box.rgba, red);

  const Visual& cylinder = find("arm", Visual::Shape::Cylinder);  // material defined in place
  EXPECT_EQ(cylinder.body, arm);
  EXPECT_EQ(cylinder.size, Eigen::Vector3d(0.05, 0.7, 0));
  EXPECT_EQ(cylinder.rgba, Eigen::Vector4d(0, 1, 0, 0.5));

  const Visual& mesh = find("arm", Visual::Shape::Mesh);
  EXPECT_EQ(mesh.mesh_file, "package://meshes/arm.stl");
  EXPECT_EQ(mesh.mesh_scale, Eigen::Vector3d(0.001, 0.002, 0.003));

  // 'hand' is welded to 'arm' at (0.5, 0, 0) turned by π/2 about y: its sphere at z = 0.1 in the
  // hand frame lies at (0.6, 0, 0) in arm's body frame.
  const Visual& sphere = find("hand", Visual::Shape::Sphere);
  EXPECT_EQ(sphere.body, arm);
  EXPECT_LT((sphere.p_BG - Eigen::Vector3d(0.6, 0, 0)).norm(), 1e-15);
  EXPECT_LT((sphere.R_BG - rpyRotation({0, M_PI / 2, 0})).norm(), 1e-15);
  EXPECT_EQ(sphere.size.x(), 0.08);
  EXPECT_EQ(sphere.rgba, red);
}

// ---- bundled models ------------------------------------------------------------------------------

struct BenchmarkCase {
  const char* file;
  BaseType base;
  int joints;  // moving joints in the file
};

TEST(UrdfModels, BenchmarksLoadWithPositiveDefiniteMassMatrix) {
  std::mt19937 rng(3);
  for (const BenchmarkCase& c : {BenchmarkCase{"benchmark/iiwa.urdf", BaseType::Fixed, 7},
                                 BenchmarkCase{"benchmark/hyq.urdf", BaseType::Free, 12},
                                 BenchmarkCase{"benchmark/atlas.urdf", BaseType::Free, 30},
                                 BenchmarkCase{"benchmark/hyq.urdf", BaseType::Fixed, 12}}) {
    SCOPED_TRACE(c.file);
    const Model<double> model = loadUrdfFile(kModelDir + c.file, c.base);
    EXPECT_EQ(model.n_base, c.base == BaseType::Free ? 6 : 0);
    EXPECT_EQ(model.nv(), model.n_base + c.joints);
    EXPECT_GT(model.totalMass(), 0);
    // Their joint origins' rpy are multiples of π/2 to 12 digits, made exact by the builder: every
    // joint is an axis joint in the CRBA's turned frames (model.hpp, TurnedFrame).
    for (int i = model.n_base > 0 ? 1 : 0; i < model.nbodies(); ++i) {
      EXPECT_TRUE(isSignedPermutationRotation(model.X_tree[i].E)) << i;
      EXPECT_TRUE(model.turned_frame[i].turned) << i;
    }
    Data<double> data(model);
    for (int k = 0; k < 10; ++k) {
      const Eigen::VectorXd q = randomVector(rng, model.nv());  // |pitch| ≤ 1: away from gimbal lock
      const Eigen::MatrixXd M = crba(model, data, q);
      EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
      const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff();
      EXPECT_GT(smallest, 0) << "q = " << q.transpose();
    }
  }
}

// Closed-form mass matrix of a double pendulum of uniform rods (relative angle θ2, rods of mass m,
// length l, inertia m l²/12 about the com):
//   M11 = 2I + m (l/2)² + m (l² + (l/2)² + 2 l (l/2) cos θ2)
//   M12 = I + m ((l/2)² + l (l/2) cos θ2),  M22 = I + m (l/2)².
TEST(UrdfModels, DoublePendulumMatchesClosedForm) {
  const Model<double> model = loadUrdfFile(kModelDir + "pendulum/double_pendulum.urdf");
  ASSERT_EQ(model.nv(), 2);
  EXPECT_EQ(model.coordinate_name[0], "theta1");
  EXPECT_EQ(model.coordinate_name[1], "theta2");
  EXPECT_DOUBLE_EQ(model.totalMass(), 2.0);
  const double m = 1, l = 0.5, lc = l / 2, I = m * l * l / 12;
  Data<double> data(model);
  std::mt19937 rng(11);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector2d q = randomVector(rng, 2) * M_PI;
    const double c2 = std::cos(q[1]);
    Eigen::Matrix2d M_exact;
    M_exact(0, 0) = 2 * I + m * lc * lc + m * (l * l + lc * lc + 2 * l * lc * c2);
    M_exact(0, 1) = M_exact(1, 0) = I + m * (lc * lc + l * lc * c2);
    M_exact(1, 1) = I + m * lc * lc;
    EXPECT_LT((crba(model, data, q) - M_exact).norm(), 1e-14) << "q = " << q.transpose();
  }
  // 'tip' is a frame at the end of link 2 (merged fixed joint), hanging 1 m below the pivot at q = 0.
  const int tip = model.frameIndex("tip");
  ASSERT_GE(tip, 0);
  EXPECT_EQ(model.frames[tip].body, model.bodyIndex("link2"));
  EXPECT_LT((model.frames[tip].p_BF - Eigen::Vector3d(0, 0, -0.5)).norm(), 1e-15);
  forwardKinematics(model, data, Eigen::Vector2d::Zero());
  EXPECT_LT((pointPosition(data, model.frames[tip].body, model.frames[tip].p_BF) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);
  // Both joints turn about y: motion stays in the x–z plane.
  EXPECT_EQ(model.axis[0], Eigen::Vector3d::UnitY());
  EXPECT_EQ(model.axis[1], Eigen::Vector3d::UnitY());
  EXPECT_EQ(model.visuals.size(), 3u);
}

}  // namespace
}  // namespace saltus::dynamics
