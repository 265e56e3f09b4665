// Scenario files (scene/scenario.hpp), bad input: one test per kind (tests/data/scenes/), each
// checking that the message names the file, the line marked in the fixture, the key path and what
// was expected.
#include "scene/scenario.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "saltus/build_paths.hpp"
#include "tests/support/errors.hpp"

// A namespace of its own: the test programs are unity builds, and scenario_test.cpp has helpers of
// the same names.
namespace saltus::scene::errors_test {
namespace {

const std::string kSceneDir = std::string(SALTUS_SOURCE_DIR) + "/models/scenes/";
const std::string kDataDir = std::string(SALTUS_SOURCE_DIR) + "/tests/data/scenes/";

std::string errorOf(const std::function<void()>& f) {
  const std::string what = testing::messageOf<ScenarioError>(f);
  if (what.empty()) ADD_FAILURE() << "no ScenarioError thrown";
  return what;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// Loads the fixture; returns the message after checking file, line and key path.
std::string expectError(const std::string& fixture, const std::string& key_path,
                        const std::vector<std::string>& parts) {
  const std::string path = kDataDir + fixture;
  return testing::expectMarkedError<ScenarioError>(path, [&] { loadScene(path); }, key_path, parts);
}

TEST(ScenarioErrors, UnknownKey) {
  expectError("unknown_key.yaml", "contacts[0].restitutoin",
              {"unknown key 'restitutoin'", "did you mean 'restitution'", "expected one of: name, link, point"});
}
TEST(ScenarioErrors, UnknownKeyNested) {
  expectError("unknown_key_nested.yaml", "model.point_mass.axis", {"unknown key 'axis'", "did you mean 'axes'"});
}
TEST(ScenarioErrors, UnknownKeyTopLevel) {
  expectError("unknown_key_top.yaml", "durration", {"unknown key 'durration'", "did you mean 'duration'"});
}
TEST(ScenarioErrors, DuplicateKey) {
  expectError("duplicate_key.yaml", "duration", {"given twice"});
}
TEST(ScenarioErrors, MissingKey) {
  expectError("missing_key.yaml", "contacts[0].surface", {"missing required key 'surface'"});
}
TEST(ScenarioErrors, PlaneOnThePointsOwnBody) {
  expectError("plane_same_body.yaml", "contacts[0].plane", {"same body as the point", "cannot touch itself"});
}
TEST(ScenarioErrors, FreePointOnAWorldSurface) {
  expectError("free_point_on_surface.yaml", "contacts[0].free_point", {"needs a plane on a body", "unbounded"});
}
TEST(ScenarioErrors, PlaneWithoutExtent) {
  expectError("plane_bad_extent.yaml", "contacts[0].plane.extent", {"half-lengths", "must be positive"});
}
TEST(ScenarioErrors, PlaneAndSurfaceBoth) {
  expectError("plane_and_surface.yaml", "contacts[0].plane", {"not both"});
}
TEST(ScenarioErrors, PlaneOnAnUnknownLink) {
  expectError("plane_unknown_link.yaml", "contacts[0].plane.link", {"unknown link 'slab_top'", "the model's links are: "});
}
TEST(ScenarioErrors, PointMassesShareACoordinateName) {
  expectError("point_masses_same_coordinate.yaml", "model.point_masses[1].axes.z", {"coordinate 'z' is used twice"});
}
TEST(ScenarioErrors, MissingModel) {
  expectError("missing_model.yaml", "model", {"missing required key 'model'"});
}
TEST(ScenarioErrors, WrongTypeScalarForVector) {
  expectError("wrong_type.yaml", "gravity", {"expected a sequence of 3 numbers", "'-9.81'"});
}
TEST(ScenarioErrors, WrongTypeMapForSequence) {
  expectError("wrong_type_sequence.yaml", "surfaces", {"expected a sequence", "got a map"});
}
TEST(ScenarioErrors, BadExpressionUnknownName) {
  expectError("bad_expression.yaml", "initial.q.z",
              {"bad expression '2 * hieght'", "Unexpected token \"hieght\"", "parameters height"});
}
TEST(ScenarioErrors, BadExpressionSyntax) {
  expectError("bad_expression_syntax.yaml", "parameters.double_height", {"bad expression '2 * (height'"});
}
TEST(ScenarioErrors, UnknownSurface) {
  expectError("unknown_surface.yaml", "contacts[0].surface",
              {"unknown surface 'groud'", "did you mean 'ground'", "surfaces are: ground"});
}
TEST(ScenarioErrors, UnknownLink) {
  expectError("unknown_link.yaml", "contacts[0].link",
              {"unknown link 'tipp'", "did you mean 'tip'", "links are: link1, link2, tip, world"});
}
TEST(ScenarioErrors, UnknownCoordinate) {
  expectError("unknown_coordinate.yaml", "initial.v.theta3",
              {"unknown coordinate 'theta3'", "coordinates are: theta1, theta2"});
}
TEST(ScenarioErrors, RestitutionOutOfRange) {
  expectError("bad_restitution.yaml", "contacts[0].restitution", {"[0, 1]", "1.5"});
}
TEST(ScenarioErrors, NegativeFriction) {
  expectError("negative_friction.yaml", "contacts[0].friction", {"non-negative", "-0.1"});
}
TEST(ScenarioErrors, TooFewDirections) {
  expectError("few_directions.yaml", "contacts[0].directions", {"at least 2 directions", "got 1"});
}
TEST(ScenarioErrors, ZeroNormal) {
  expectError("zero_normal.yaml", "surfaces[0].normal", {"non-zero"});
}
TEST(ScenarioErrors, NonTangentBeltVelocity) {
  expectError("nontangent_belt.yaml", "surfaces[0].velocity_schedule[1].velocity", {"tangent", "0.1 m/s"});
}
TEST(ScenarioErrors, UnsortedSchedule) {
  expectError("unsorted_schedule.yaml", "surfaces[0].velocity_schedule[1].time", {"increase"});
}
TEST(ScenarioErrors, YamlSyntax) {
  const std::string what = errorOf([] { loadScene(kDataDir + "yaml_syntax.yaml"); });
  EXPECT_EQ(what.rfind(kDataDir + "yaml_syntax.yaml:", 0), 0u) << what;
  EXPECT_TRUE(contains(what, "YAML syntax error")) << what;
}
// A second document (after '---', here with a negative mass) would be silently ignored: refused,
// naming the line where it starts.
TEST(ScenarioErrors, ASecondYamlDocumentIsRefused) {
  const std::string path = (std::filesystem::temp_directory_path() / ("saltus_two_documents_" + std::to_string(::getpid()) + ".yaml")).string();
  {
    std::ifstream in(kSceneDir + "ball_drop.yaml");
    std::ofstream out(path);
    out << in.rdbuf() << "---\nname: other\nmass: -5\n";
  }
  const std::string what = errorOf([&] { loadScene(path); });
  std::filesystem::remove(path);
  EXPECT_EQ(what.rfind(path + ":", 0), 0u) << what;
  EXPECT_TRUE(contains(what, "a second YAML document")) << what;
}
TEST(ScenarioErrors, UrdfErrorPassesThrough) {
  expectError("bad_urdf.yaml", "model.urdf", {"missing_inertial.urdf: ", "inertial"});
}
TEST(ScenarioErrors, JointLimitWithoutLimit) {
  expectError("bad_limit.yaml", "joint_limits[1]", {"'cont' has no finite position limit"});
}
TEST(ScenarioErrors, RigidBodyNeedsAMovingBase) {
  expectError("rigid_body_fixed.yaml", "base", {"planar or free"});
}
TEST(ScenarioErrors, BadInertia) {
  expectError("bad_inertia.yaml", "model.rigid_body.inertia", {"triangle inequality"});
}
TEST(ScenarioErrors, UnknownBase) {
  expectError("unknown_base.yaml", "base", {"floating", "fixed", "planar", "free", "free_quaternion"});
}
TEST(ScenarioErrors, TwoModels) {
  expectError("two_models.yaml", "model.point_mass", {"exactly one of: urdf, point_mass, point_masses, rigid_body"});
}

TEST(ScenarioErrors, QuaternionAndEulerAnglesBoth) {
  expectError("quaternion_and_euler.yaml", "initial.q", {"either as a quaternion", "not both"});
}
TEST(ScenarioErrors, QuaternionNotOfUnitLength) {
  expectError("quaternion_not_unit.yaml", "initial.q", {"must have unit length", "0.948683"});
}
TEST(ScenarioErrors, QuaternionBaseVelocityNameInPositions) {
  expectError("quaternion_unknown_coordinate.yaml", "initial.q.base_wx", {"unknown coordinate 'base_wx'", "base_qw"});
}

}  // namespace
}  // namespace saltus::scene::errors_test
