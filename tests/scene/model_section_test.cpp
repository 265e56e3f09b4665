// The model section of scenario files (scene/model_section.hpp), for the kinds of model other
// than parts through tests/scene/scenario_test.cpp's scenes; here the parts: a part's planar or
// Euler base as a chain of one-coordinate joints has the same mass matrix, bias forces, forward
// dynamics and kinematics as the multi-coordinate base joint of the model of that part alone (two
// implementations of RBDA's algorithms, one through dynamics' multi-joint kernels, one through
// its axis kernels); parts do not couple in the mass matrix; and every bad input is refused with
// the file, line and key.
#include "scene/model_section.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <random>
#include <string>

#include "dynamics/aba.hpp"
#include "dynamics/builder.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/urdf.hpp"
#include "saltus/build_paths.hpp"
#include "scene/scenario.hpp"
#include "tests/support/files.hpp"

namespace saltus::scene {
namespace {

namespace fs = std::filesystem;
using dynamics::BaseType;
using dynamics::Model;

const std::string kBiped = std::string(SALTUS_SOURCE_DIR) + "/models/biped/biped.urdf";
const std::string kMonopod = std::string(SALTUS_SOURCE_DIR) + "/models/monopod/monopod.urdf";

class ModelSection : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratchPath("model_section", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The scene of `text` (written to a file of the scratch folder).
  Scene load(const std::string& text) {
    const fs::path path = dir_ / "scene.yaml";
    std::ofstream(path) << text;
    return loadScene(path.string());
  }
  // The message of the ScenarioError loading `text` throws.
  std::string error(const std::string& text) {
    try {
      load(text);
    } catch (const ScenarioError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return "";
  }
  fs::path dir_;
};

// M(q), the bias forces and the forward dynamics of `a` and `b` (the same coordinates in the same
// order) at random states, and every frame's pose.
void expectSameDynamics(const Model<double>& a, const Model<double>& b, unsigned seed) {
  ASSERT_EQ(a.nv(), b.nv());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  dynamics::Data<double> da(a), db(b);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(a.nv()), v(a.nv()), tau(a.nv());
    for (int k = 0; k < a.nv(); ++k) q[k] = u(rng), v[k] = 3 * u(rng), tau[k] = 20 * u(rng);
    const Eigen::MatrixXd Ma = dynamics::crba(a, da, q), Mb = dynamics::crba(b, db, q);
    EXPECT_LT((Ma - Mb).cwiseAbs().maxCoeff(), 1e-10 * Ma.cwiseAbs().maxCoeff()) << "trial " << trial;
    const Eigen::VectorXd ha = dynamics::nonLinearEffects(a, da, q, v), hb = dynamics::nonLinearEffects(b, db, q, v);
    EXPECT_LT((ha - hb).cwiseAbs().maxCoeff(), 1e-10 * (1 + ha.cwiseAbs().maxCoeff())) << "trial " << trial;
    const Eigen::VectorXd qdd_a = dynamics::aba(a, da, q, v, tau), qdd_b = dynamics::aba(b, db, q, v, tau);
    EXPECT_LT((qdd_a - qdd_b).cwiseAbs().maxCoeff(), 1e-8 * (1 + qdd_a.cwiseAbs().maxCoeff())) << "trial " << trial;
    dynamics::forwardKinematics(a, da, q);
    dynamics::forwardKinematics(b, db, q);
    for (const auto& f : a.frames) {
      const int g = b.frameIndex(f.name);
      ASSERT_GE(g, 0) << f.name;
      const auto& fb = b.frames[g];
      EXPECT_LT((dynamics::pointPosition(da, f.body, f.p_BF) - dynamics::pointPosition(db, fb.body, fb.p_BF)).norm(), 1e-12)
          << f.name;
    }
  }
}

TEST_F(ModelSection, APlanarPartIsThePlanarBaseModel) {
  const Scene s = load("model:\n  parts:\n    - {name: rider, base: planar, urdf: " + kBiped + "}\n");
  const Model<double> alone = dynamics::readUrdfFile(kBiped).build(BaseType::Planar);
  EXPECT_EQ(s.model.base, BaseType::Fixed);
  ASSERT_EQ(s.model.nv(), alone.nv());
  EXPECT_EQ(s.model.coordinate_name[0], "rider_x");
  EXPECT_EQ(s.model.coordinate_name[1], "rider_z");
  EXPECT_EQ(s.model.coordinate_name[2], "rider_theta");
  for (int k = 3; k < alone.nv(); ++k) EXPECT_EQ(s.model.coordinate_name[k], alone.coordinate_name[k]);
  EXPECT_TRUE(s.model.isTranslation(0) && s.model.isTranslation(1) && !s.model.isTranslation(2));
  EXPECT_EQ(s.model_files, std::vector<std::string>{kBiped});
  expectSameDynamics(alone, s.model, 1);
}

TEST_F(ModelSection, AFreePartIsTheEulerBaseModel) {
  const Scene s = load("model:\n  parts:\n    - {name: hopper, base: free, urdf: " + kMonopod + "}\n");
  const Model<double> alone = dynamics::readUrdfFile(kMonopod).build(BaseType::Free);
  const std::vector<std::string> base{"hopper_x", "hopper_y", "hopper_z", "hopper_yaw", "hopper_pitch", "hopper_roll"};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(s.model.coordinate_name[k], base[k]);
  expectSameDynamics(alone, s.model, 2);
}

// A board and a rider, both planar: two models in one, coupled only through contacts.
TEST_F(ModelSection, PartsDoNotCoupleInTheMassMatrix) {
  const Scene s = load(
      "model:\n  parts:\n"
      "    - name: board\n      base: planar\n"
      "      rigid_body: {mass: 2.38, inertia: [0.01, 0.122, 0.12], visuals: [{shape: box, size: [0.8, 0.2, 0.02]}]}\n"
      "    - {name: rider, base: planar, urdf: " + kBiped + "}\n"
      "    - point_mass: {link: ball, mass: 0.5, axes: {ball_x: [1, 0, 0], ball_z: [0, 0, 1]}}\n");
  const Model<double> rider = dynamics::readUrdfFile(kBiped).build(BaseType::Planar);
  const int nr = rider.nv();
  ASSERT_EQ(s.model.nv(), 3 + nr + 2);
  EXPECT_EQ(s.model.coordinate_name[3], "rider_x");
  EXPECT_EQ(s.model.coordinate_name[3 + nr], "ball_x");
  EXPECT_EQ(s.model.visuals.size(), 1 + rider.visuals.size());
  EXPECT_NEAR(s.model.totalMass(), 2.38 + rider.totalMass() + 0.5, 1e-12);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd q(s.model.nv());
  for (int k = 0; k < q.size(); ++k) q[k] = u(rng);
  dynamics::Data<double> d(s.model), dr(rider);
  const Eigen::MatrixXd M = dynamics::crba(s.model, d, q);
  const Eigen::MatrixXd Mr = dynamics::crba(rider, dr, Eigen::VectorXd(q.segment(3, nr)));
  EXPECT_TRUE(M.block(0, 3, 3, nr).isZero(0)) << "board-rider coupling";
  EXPECT_TRUE(M.block(3, 3 + nr, nr, 2).isZero(0)) << "rider-ball coupling";
  EXPECT_LT((M.block(3, 3, nr, nr) - Mr).cwiseAbs().maxCoeff(), 1e-10 * Mr.cwiseAbs().maxCoeff());
  // The board: m, m, I_yy on the diagonal of its block (its centre of mass at its origin).
  EXPECT_NEAR(M(0, 0), 2.38, 1e-12);
  EXPECT_NEAR(M(1, 1), 2.38, 1e-12);
  EXPECT_NEAR(M(2, 2), 0.122, 1e-12);
  EXPECT_NEAR(M(nr + 3, nr + 3), 0.5, 1e-12);
  // Gravity on each part: its weight on its vertical coordinate.
  const Eigen::VectorXd g = dynamics::nonLinearEffects(s.model, d, q, Eigen::VectorXd::Zero(q.size()));
  EXPECT_NEAR(g[1], 2.38 * 9.81, 1e-9);
  EXPECT_NEAR(g[4], rider.totalMass() * 9.81, 1e-9);
  EXPECT_NEAR(g[3 + nr + 1], 0.5 * 9.81, 1e-9);
}

// A fixed part is welded to the world: it has no coordinates but its joints'.
TEST_F(ModelSection, AFixedPartHasOnlyItsJointsCoordinates) {
  const Scene s = load("model:\n  parts:\n    - {name: arm, urdf: " + std::string(SALTUS_SOURCE_DIR) +
                       "/models/pendulum/double_pendulum.urdf}\n    - name: block\n      base: planar\n"
                       "      rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}\n");
  const Model<double> arm = dynamics::readUrdfFile(std::string(SALTUS_SOURCE_DIR) + "/models/pendulum/double_pendulum.urdf").build();
  ASSERT_EQ(s.model.nv(), arm.nv() + 3);
  for (int k = 0; k < arm.nv(); ++k) EXPECT_EQ(s.model.coordinate_name[k], arm.coordinate_name[k]);
  EXPECT_EQ(s.model.coordinate_name[arm.nv()], "block_x");
}

// A part's URDF names its meshes relative to its own folder; in the scene (whose source is the
// scene file, in another folder) they become absolute paths into that folder. A URL
// (package://...) and an absolute path are kept as they are.
TEST_F(ModelSection, APartsRelativeMeshPathsAreResolvedInItsUrdfsFolder) {
  fs::create_directories(dir_ / "robot");
  const std::string inertial =
      "<inertial><mass value=\"1\"/><inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial>";
  auto mesh = [](const std::string& file) { return "<visual><geometry><mesh filename=\"" + file + "\"/></geometry></visual>"; };
  std::ofstream(dir_ / "robot" / "arm.urdf")
      << "<robot name=\"arm\"><link name=\"base\">" << inertial << mesh("meshes/../meshes/base.stl")
      << "</link><link name=\"arm\">" << inertial << mesh("package://arm_description/arm.stl") << mesh("/opt/meshes/hand.stl")
      << "</link><joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child link=\"arm\"/>"
         "<axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"5\"/></joint></robot>";
  const Scene s = load("model:\n  parts:\n    - {name: arm, urdf: robot/arm.urdf}\n");
  std::vector<std::string> meshes;
  for (const dynamics::Visual& v : s.model.visuals)
    if (v.shape == dynamics::Visual::Shape::Mesh) meshes.push_back(v.mesh_file);
  const std::string base = (dir_ / "robot" / "meshes" / "base.stl").lexically_normal().string();
  std::vector<std::string> expected = {base, "package://arm_description/arm.stl", "/opt/meshes/hand.stl"};
  std::sort(meshes.begin(), meshes.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(meshes, expected);
  EXPECT_TRUE(fs::path(base).is_absolute());
}

// A part of one rigid body on an Euler base, and a URDF part welded to the world (its root is not
// named "world"), against the models of them alone.
TEST_F(ModelSection, AFreeRigidBodyAndAWeldedUrdf) {
  const Scene s = load("model:\n  parts:\n    - {name: box, base: free, rigid_body: {mass: 2, com: [0.1, 0, 0], inertia: [0.1, 0.2, 0.25]}}\n");
  dynamics::ModelBuilder b("box");
  b.addLink("box", 2.0, Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0.1, 0.2, 0.25).asDiagonal());
  expectSameDynamics(b.build(BaseType::Free), s.model, 4);
  EXPECT_EQ(s.model.coordinate_name[3], "box_yaw");
  const Scene welded = load("model:\n  parts:\n    - {name: robot, urdf: " + kBiped + "}\n");
  const Model<double> fixed = dynamics::readUrdfFile(kBiped).build(BaseType::Fixed);
  expectSameDynamics(fixed, welded.model, 5);
  EXPECT_EQ(welded.model.nv(), fixed.nv());
}

// The parts' coordinates in `initial:` and `input:`, and contacts on their links (the skateboard).
TEST_F(ModelSection, TheSceneKeysNameThePartsCoordinatesAndLinks) {
  const Scene s = loadScene("skateboard", {{"front_lift", 1.0}});
  EXPECT_DOUBLE_EQ(s.q0[s.model.coordinateIndex("board_z")], 0.0775);
  EXPECT_DOUBLE_EQ(s.q0[s.model.coordinateIndex("back_x")], -0.27);
  EXPECT_DOUBLE_EQ(s.tau[s.model.coordinateIndex("front_z")], 36.5 * 9.81);
  const int board = s.model.frames[s.model.frameIndex("board")].body;
  ASSERT_EQ(s.contacts.size(), 5u);
  EXPECT_EQ(s.contacts[0].body, board);  // rear_wheel, on the board's default link
  EXPECT_EQ(s.contacts[3].plane.body, board);  // back_foot on the deck
  EXPECT_EQ(s.contacts[3].body, s.model.frames[s.model.frameIndex("back")].body);
}

TEST_F(ModelSection, BadPartsAreRefusedWithTheLineAndKey) {
  const std::string board = "    - {name: board, base: planar, rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}}\n";
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"base: planar\nmodel:\n  parts:\n" + board, "scene.yaml:1:7: base: a model of parts gives each part its own base"},
      {"model:\n  parts:\n    - {base: planar, rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}}\n",
       "model.parts[0].name: missing required key 'name'"},
      {"model:\n  parts:\n    - {name: board, rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}}\n",
       "model.parts[0].base: a rigid_body part needs a moving base"},
      {"model:\n  parts:\n    - {name: board, base: free_quaternion, rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}}\n",
       "scene.yaml:3:27: model.parts[0].base: a part's base is a chain of one-coordinate joints"},
      {"model:\n  parts:\n" + board + board, "model.parts[1].name: part 'board' is named twice"},
      {"model:\n  parts:\n    - {name: a, base: planar, urdf: " + kBiped + "}\n    - {name: b, base: planar, urdf: " +
           kBiped + "}\n",
       "model.parts[1].urdf: link 'arm_l' of part 'b' is already in the model"},
      // A point mass's coordinate against a part's base coordinate, either way round.
      {"model:\n  parts:\n" + board + "    - point_mass: {link: m, mass: 1, axes: {board_x: [1, 0, 0]}}\n",
       "model.parts[1].point_mass.axes.board_x: coordinate 'board_x' is used twice"},
      {"model:\n  parts:\n    - point_mass: {link: m, mass: 1, axes: {board_x: [1, 0, 0]}}\n" + board,
       "model.parts[1].rigid_body: joint 'board_x' of part 'board' is already in the model"},
      {"model:\n  parts:\n    - {name: world, base: planar, rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}}\n",
       "model.parts[0].rigid_body.link: 'world' is the name of the fixed frame"},
      {"model:\n  parts:\n    - {name: m, point_mass: {mass: 1, axes: {z: [0, 0, 1]}}}\n",
       "model.parts[0].name: a point mass is named by its link"},
      {"model:\n  parts:\n    - {name: board, base: planar, urdf: x.urdf, rigid_body: {mass: 1, inertia: [1, 1, 1]}}\n",
       "model.parts[0]: expected exactly one of: urdf, point_mass, rigid_body"},
      {"model:\n  parts:\n    - {name: m, base: planar, point_mass: {mass: 1, axes: {z: [0, 0, 1]}}}\n",
       "model.parts[0].base: a point mass moves along its own axes from the world: it takes no base"},
      {"model:\n  parts:\n    - {name: 'a b', base: planar, rigid_body: {mass: 1, inertia: [0.1, 0.1, 0.1]}}\n",
       "model.parts[0].name: a part's name prefixes its base coordinates"},
      {"model:\n  parts:\n    - {name: r, base: planar, urdf: missing.urdf}\n", "model.parts[0].urdf:"},
      {"model:\n  parts: []\n", "model.parts: expected a list of at least one part"},
      {"model:\n  parts:\n" + board + "  rigid_body: {mass: 1, inertia: [1, 1, 1]}\n",
       "model.rigid_body: expected exactly one of: urdf, point_mass, point_masses, rigid_body, parts"},
  };
  for (const Case& c : cases) {
    const std::string message = error(c.text);
    EXPECT_NE(message.find(c.expected), std::string::npos) << "got: " << message << "\nexpected: " << c.expected;
    EXPECT_NE(message.find("scene.yaml:"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace saltus::scene
