// What is drawn for a model: visuals where the model has them, capsules and spheres where it
// has none, posed by forward kinematics; belt travel.
#include "render/geometry.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <gtest/gtest.h>

#include "scene/scenario.hpp"
#include "tests/support/scenes.hpp"

namespace {

using saltus::render::SceneGeometry;

TEST(SceneGeometry, PointMassWithoutVisualsIsASphereAtItsPosition) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.5);
  std::ostringstream warnings;
  const SceneGeometry g(scene, warnings);
  ASSERT_EQ(g.shapes().size(), 1u);
  const auto pose = g.pose(Eigen::VectorXd::Constant(1, 0.7));
  EXPECT_TRUE(pose.X_WG[0].translation().isApprox(Eigen::Vector3d(0, 0, 0.7)));
  const auto box = g.bounds(pose);
  const double r = g.shapes()[0].scale.x();
  EXPECT_NEAR(box.hi.z(), 0.7 + r, 1e-6);
  EXPECT_NEAR(box.lo.z(), 0.7 - r, 1e-6);
  EXPECT_TRUE(warnings.str().empty());
}

TEST(SceneGeometry, PendulumVisualsFollowTheLinks) {
  const auto scene = saltus::scene::loadScene("pendulum_conveyor");
  std::ostringstream warnings;
  const SceneGeometry g(scene, warnings);
  ASSERT_EQ(g.shapes().size(), 4u);  // the pivot, two cylinders and the tip sphere (double_pendulum.urdf)
  // θ1 = π/2 about y
  Eigen::VectorXd q(2);
  q << M_PI / 2, 0;
  const auto pose = g.pose(q);
  // the tip is 1 m from the pivot along the rotated −z axis
  const Eigen::Vector3d tip = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()) * Eigen::Vector3d(0, 0, -1);
  EXPECT_TRUE(pose.p_contact[0].isApprox(tip, 1e-12));
  EXPECT_TRUE(pose.X_WG[0].translation().isZero());                 // pivot
  EXPECT_TRUE(pose.X_WG[3].translation().isApprox(tip, 1e-12));      // tip sphere
  EXPECT_TRUE(pose.X_WG[1].translation().isApprox(tip / 4, 1e-12));  // link 1 cylinder centre
}

TEST(SceneGeometry, LinksWithoutVisualsGetCapsulesToTheirChildren) {
  saltus::dynamics::ModelBuilder b("chain");
  b.addLink("world");
  b.addLink("a", 1.0, Eigen::Vector3d(0, 0, -0.2), Eigen::Matrix3d::Identity() * 0.01);
  b.addLink("b", 1.0, Eigen::Vector3d(0, 0, -0.3), Eigen::Matrix3d::Identity() * 0.01);
  saltus::dynamics::JointSpec j1;
  j1.name = "j1";
  j1.parent = "world";
  j1.child = "a";
  j1.axis = Eigen::Vector3d::UnitY();
  b.addJoint(j1);
  saltus::dynamics::JointSpec j2;
  j2.name = "j2";
  j2.parent = "a";
  j2.child = "b";
  j2.axis = Eigen::Vector3d::UnitY();
  j2.p_PJ = Eigen::Vector3d(0, 0, -0.4);
  b.addJoint(j2);
  saltus::scene::Scene scene;
  scene.model = b.build(saltus::dynamics::BaseType::Fixed);
  std::ostringstream warnings;
  const SceneGeometry g(scene, warnings);
  ASSERT_EQ(g.shapes().size(), 3u);  // a: joint -> child joint (0.4 m); b: joint -> com (0.3 m); the pivot
  const auto pose = g.pose(Eigen::VectorXd::Zero(2));
  const auto box = g.bounds(pose);
  const double r = g.meshes()[g.shapes()[0].mesh].hi.x();  // capsule radius
  EXPECT_NEAR(box.lo.z(), -0.7 - r, 1e-6);
  EXPECT_NEAR(box.hi.z(), 2 * r, 1e-6);  // the pivot sphere, radius twice the capsules'
}

TEST(SceneGeometry, UnreadableMeshIsACapsuleReportedOnce) {
  auto scene = saltus::testing::ballDrop(1.0, 0.5);
  saltus::dynamics::Visual v;
  v.body = 0;
  v.link = "mass";
  v.shape = saltus::dynamics::Visual::Shape::Mesh;
  v.mesh_file = "/nonexistent/ball.stl";
  v.p_BG = Eigen::Vector3d(0, 0, 0.1);
  scene.model.visuals = {v, v};
  std::ostringstream warnings;
  const SceneGeometry g(scene, warnings);
  EXPECT_EQ(g.shapes().size(), 2u);
  const std::string w = warnings.str();
  EXPECT_NE(w.find("cannot load mesh '/nonexistent/ball.stl' of link 'mass'"), std::string::npos) << w;
  EXPECT_EQ(w.find("cannot load", w.find("cannot load") + 1), std::string::npos) << w;  // once
}

TEST(SceneGeometry, BeltTravelIntegratesTheVelocitySchedule) {
  saltus::scene::Surface belt;
  belt.velocity_schedule = {{0.1, Eigen::Vector3d(0.5, 0, 0)}, {0.3, Eigen::Vector3d(-1, 0, 0)}};
  const Eigen::Vector3d d = saltus::render::beltDirection(belt);
  EXPECT_TRUE(d.isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_DOUBLE_EQ(saltus::render::surfaceTravel(belt, d, 0.05), 0);
  EXPECT_NEAR(saltus::render::surfaceTravel(belt, d, 0.2), 0.05, 1e-12);
  EXPECT_NEAR(saltus::render::surfaceTravel(belt, d, 0.5), 0.1 - 0.2, 1e-12);
  saltus::scene::Surface ground;
  EXPECT_EQ(saltus::render::beltDirection(ground).norm(), 0);
}

}  // namespace

namespace {

TEST(SceneGeometry, MeshFileLoadsThroughAssimp) {
  const auto path = std::filesystem::temp_directory_path() / ("saltus_geometry_" + std::to_string(::getpid()) + ".obj");
  std::ofstream(path) << "v 0 0 0\nv 2 0 0\nv 0 1 0\nv 0 0 3\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";  // a tetrahedron
  saltus::render::Mesh mesh;
  std::string why;
  ASSERT_TRUE(saltus::render::loadMeshFile(path.string(), mesh, &why)) << why;
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_TRUE(mesh.lo.isZero());
  EXPECT_TRUE(mesh.hi.isApprox(Eigen::Vector3d(2, 1, 3)));
  std::filesystem::remove(path);
  EXPECT_FALSE(saltus::render::loadMeshFile("/nonexistent/x.stl", mesh, &why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
