// Scenario files (scene/scenario.hpp): the built-in scenes against forward kinematics and
// their parameters, --set overrides, defaults, joint-limit stops (bad input: scenario_errors_test.cpp).
#include "scene/scenario.hpp"

#include <gtest/gtest.h>
#include <unistd.h>
#include <filesystem>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numbers>

#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "saltus/build_paths.hpp"
#include "tests/support/errors.hpp"

namespace saltus::scene {
namespace {

const std::string kSceneDir = std::string(SALTUS_SOURCE_DIR) + "/models/scenes/";
const std::string kDataDir = std::string(SALTUS_SOURCE_DIR) + "/tests/data/scenes/";
constexpr double kPi = std::numbers::pi;

// The ScenarioError message of f, or a test failure.
std::string errorOf(const std::function<void()>& f) { return testing::expectedMessageOf<ScenarioError>(f); }

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// World position of contact i at configuration q, and its gap to its surface.
Eigen::Vector3d contactPosition(const Scene& s, int i, const Eigen::VectorXd& q) {
  dynamics::Data<double> data(s.model);
  dynamics::forwardKinematics(s.model, data, q);
  return dynamics::pointPosition(data, s.contacts[i].body, Eigen::Vector3d(s.contacts[i].p_B));
}
double gap(const Scene& s, int i, const Eigen::VectorXd& q) {
  const Surface& surface = s.surfaces[s.contacts[i].surface];  // the plane's signed distance, by hand
  return surface.normal.dot(contactPosition(s, i, q) - surface.point);
}
// World position of a frame (URDF link) at q.
Eigen::Vector3d framePosition(const Scene& s, const std::string& frame, const Eigen::VectorXd& q) {
  const int f = s.model.frameIndex(frame);
  EXPECT_GE(f, 0) << frame;
  dynamics::Data<double> data(s.model);
  dynamics::forwardKinematics(s.model, data, q);
  return dynamics::pointPosition(data, s.model.frames[f].body, Eigen::Vector3d(s.model.frames[f].p_BF));
}

// ---------------------------------------------------------------------------------------------
// Built-in scenes

TEST(Scenario, BuiltinNames) {
  EXPECT_EQ(builtinSceneNames(),
            (std::vector<std::string>{"ball_drop", "block_on_cart", "block_on_slab", "block_slide", "box_on_corners", "box_stack",
                                      "chain_on_stops", "fast_spin", "hyq_drop", "newtons_cradle", "painleve_rod",
                                      "pendulum_conveyor", "rocking_block", "skateboard", "skateboard_rider"}));
}

TEST(Scenario, EveryBuiltinLoadsWithItsCoordinatesAndContacts) {
  const std::map<std::string, std::pair<int, int>> expected = {
      {"ball_drop", {1, 1}},         {"block_slide", {2, 1}},   {"pendulum_conveyor", {2, 1}},
      {"painleve_rod", {3, 1}},      {"block_on_cart", {3, 1}}, {"block_on_slab", {2, 2}},
      {"rocking_block", {3, 2}},     {"newtons_cradle", {3, 2}}, {"box_on_corners", {6, 4}},
      {"chain_on_stops", {10, 0}},    {"fast_spin", {6, 0}},     {"hyq_drop", {18, 4}},
      {"box_stack", {3, 3}},         {"skateboard", {7, 5}},    {"skateboard_rider", {12, 5}}};
  for (const std::string& name : builtinSceneNames()) {
    SCOPED_TRACE(name);
    const Scene s = loadScene(name);
    ASSERT_TRUE(expected.count(name));
    EXPECT_EQ(s.name, name);
    EXPECT_EQ(s.source, "builtin:" + name);
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(s.model.nv(), expected.at(name).first);
    EXPECT_EQ(static_cast<int>(s.contacts.size()), expected.at(name).second);
    EXPECT_EQ(s.q0.size(), s.model.nq());
    EXPECT_EQ(s.model.nq(), s.model.nv() + (name == "fast_spin" || name == "box_on_corners" || name == "hyq_drop"));  // quaternion bases
    EXPECT_EQ(s.v0.size(), s.model.nv());
    EXPECT_EQ(s.tau.size(), s.model.nv());
    EXPECT_EQ(s.tau.isZero(), name != "block_on_cart");  // the cart is pulled
    // two stops per limited joint
    EXPECT_EQ(s.limits.size(), name == "chain_on_stops" ? 18u : name == "hyq_drop" ? 24u : name == "skateboard_rider" ? 12u : 0u);
    EXPECT_GT(s.duration, 0);
    EXPECT_FALSE(s.model.visuals.empty());
    for (const Surface& surf : s.surfaces) EXPECT_NEAR(surf.normal.norm(), 1.0, 1e-15);
  }
}

// Point masses on their own axes, and a contact on a plane fixed in another body.
TEST(Scenario, BlockOnCartTouchesAPlaneOnTheCart) {
  const Scene s = loadScene("block_on_cart", {{"deck", 0.7}});
  ASSERT_EQ(s.model.nv(), 3);
  EXPECT_EQ(s.model.coordinate_name, (std::vector<std::string>{"cart_x", "block_x", "block_z"}));
  EXPECT_DOUBLE_EQ(s.model.totalMass(), 5.0);
  EXPECT_DOUBLE_EQ(s.tau[0], 30.0);
  ASSERT_EQ(s.contacts.size(), 1u);
  const Contact& c = s.contacts[0];
  EXPECT_EQ(c.surface, -1);
  EXPECT_EQ(c.plane.link, "cart");
  EXPECT_EQ(c.plane.body, s.model.frames[s.model.frameIndex("cart")].body);
  EXPECT_EQ(c.body, s.model.frames[s.model.frameIndex("block")].body);
  EXPECT_NE(c.plane.body, c.body);
  EXPECT_EQ(c.plane.extent, Eigen::Vector2d(0.7, 0.2));
  EXPECT_EQ(c.plane.normal, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(c.plane.tangents.col(0), Eigen::Vector3d::UnitX());  // the link's x projected onto the plane
  EXPECT_EQ(c.directions, 2);
}

// `free_point: true`: the contact point on the plane is free along both of its axes in space,
// along t1 alone in a planar scene (t2 is the normal to the plane of motion); without it, none.
TEST(Scenario, AFreeContactPointIsFreeAlongThePlanesAxesOfMotion) {
  EXPECT_TRUE(loadScene("block_on_cart").contacts[0].free_axes.empty());
  EXPECT_EQ(loadScene(kDataDir + "free_point_spatial.yaml").contacts[0].free_axes, (std::vector<int>{0, 1}));
  const Scene board = loadScene("skateboard");
  int feet = 0;
  for (const Contact& c : board.contacts)
    if (c.surface < 0) {
      ++feet;
      EXPECT_EQ(c.free_axes, (std::vector<int>{0})) << c.name;
      EXPECT_EQ(c.plane.tangents.col(1).cwiseAbs(), Eigen::Vector3d::UnitY()) << c.name;
    } else {
      EXPECT_TRUE(c.free_axes.empty()) << c.name;
    }
  EXPECT_EQ(feet, 2);
}

// The full-body Ollie's scene: the board and the biped as two parts, the biped's feet on the deck
// at the stance the parameters give (the hip over their middle, straight legs), free along it.
TEST(Scenario, SkateboardRiderStandsOnTheDeck) {
  for (const auto& [back, front] : {std::pair{-0.27, 0.2}, std::pair{-0.2, 0.25}}) {
    const Scene s = loadScene("skateboard_rider", {{"back_foot", back}, {"front_foot", front}});
    // the board and the biped: 73 kg times its segments' mass fractions (torso, two arms, thighs
    // and shanks; they sum to 0.9726)
    EXPECT_NEAR(s.model.totalMass(), 2.38 + 73.0 * (0.504 + 2 * (0.0494 + 0.1416 + 0.0433)), 1e-9);
    dynamics::Data<double> data(s.model);
    dynamics::forwardKinematics(s.model, data, s.q0);
    const Eigen::Vector3d deck_top(0, 0, 0.0775);  // board at rest on its wheels
    for (const auto& [foot, x] : {std::pair{"foot_r", back}, std::pair{"foot_l", front}}) {
      const dynamics::Frame& f = s.model.frames[s.model.frameIndex(foot)];
      const Eigen::Vector3d p = dynamics::pointPosition(data, f.body, f.p_BF);
      EXPECT_NEAR(p.x(), x, 1e-12) << foot;
      EXPECT_NEAR(p.z(), deck_top.z(), 1e-12) << foot;
    }
    int feet = 0;
    for (const Contact& c : s.contacts)
      if (c.surface < 0) {
        ++feet;
        EXPECT_EQ(c.free_axes, (std::vector<int>{0})) << c.name;
        EXPECT_EQ(c.plane.link, "board") << c.name;
        EXPECT_EQ(c.friction, 1.6) << c.name;
      }
    EXPECT_EQ(feet, 2);
  }
}

TEST(Scenario, BlockOnSlabStartsAtItsDropHeight) {
  const Scene s = loadScene("block_on_slab", {{"height", 0.4}, {"slab_height", 0.2}});
  ASSERT_EQ(s.model.nv(), 2);
  EXPECT_DOUBLE_EQ(s.q0[0], 0.2);              // slab_z
  EXPECT_DOUBLE_EQ(s.q0[1], 0.2 + 0.1 + 0.4);  // block_z: on top of the slab plus the drop
  EXPECT_EQ(s.contacts[0].surface, 0);
  EXPECT_EQ(s.contacts[1].surface, -1);
  EXPECT_EQ(s.contacts[1].plane.point, Eigen::Vector3d(0, 0, 0.1));
  EXPECT_DOUBLE_EQ(s.contacts[1].restitution, 0.5);
}

TEST(Scenario, LoadByPathKeepsThePathAsSource) {
  const Scene s = loadScene(kSceneDir + "ball_drop.yaml");
  EXPECT_EQ(s.source, kSceneDir + "ball_drop.yaml");
  EXPECT_EQ(s.name, "ball_drop");
}

TEST(Scenario, BallDrop) {
  const Scene s = loadScene("ball_drop");
  ASSERT_EQ(s.model.nv(), 1);
  EXPECT_EQ(s.model.coordinate_name[0], "z");
  EXPECT_DOUBLE_EQ(s.model.totalMass(), 1.0);
  EXPECT_EQ(s.model.gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_DOUBLE_EQ(gap(s, 0, s.q0), 1.0);
  EXPECT_TRUE(s.v0.isZero());
  EXPECT_DOUBLE_EQ(s.contacts[0].restitution, 0.5);
  EXPECT_EQ(s.contacts[0].friction, 0.0);
  EXPECT_EQ(s.contacts[0].directions, 0);
  EXPECT_EQ(s.parameters, (std::map<std::string, double>{{"height", 1.0}, {"restitution", 0.5}}));
  // Moving the coordinate moves the contact point along z one for one.
  EXPECT_DOUBLE_EQ(gap(s, 0, Eigen::VectorXd::Constant(1, 0.25)), 0.25);
}

TEST(Scenario, OverridesChangeTheValues) {
  const Scene s = loadScene("ball_drop", {{"height", 2.0}, {"restitution", 0.8}});
  EXPECT_DOUBLE_EQ(gap(s, 0, s.q0), 2.0);
  EXPECT_DOUBLE_EQ(s.contacts[0].restitution, 0.8);
  EXPECT_DOUBLE_EQ(s.parameters.at("height"), 2.0);
  EXPECT_DOUBLE_EQ(s.parameters.at("restitution"), 0.8);
  // Through the parser, as from the command line.
  const Scene t = loadScene("ball_drop", parseOverrides({"height=3.5"}));
  EXPECT_DOUBLE_EQ(gap(t, 0, t.q0), 3.5);
}

TEST(Scenario, OverrideOutsideTheValidRangeIsCaughtWhereTheParameterIsUsed) {
  const std::string what = errorOf([] { loadScene("ball_drop", {{"restitution", 1.5}}); });
  EXPECT_TRUE(contains(what, "ball_drop.yaml:")) << what;
  EXPECT_TRUE(contains(what, "contacts[0].restitution")) << what;
  EXPECT_TRUE(contains(what, "[0, 1]")) << what;
}

// A number a double cannot hold is refused as written (1e-400 would be read as 0, then reported
// as "mass must be positive, got 0"); an expression that is not finite names the parameters it
// used and which came from --set.
TEST(ScenarioErrors, NumbersAreQuotedAsWritten) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("saltus_scenario_numbers_" + std::to_string(::getpid()) + ".yaml");
  auto errorWith = [&](const std::string& mass, const std::map<std::string, double>& overrides = {}) {
    std::ofstream(file) << "parameters: {m: 1}\nmodel:\n  point_mass:\n    mass: " << mass << "\n";
    return errorOf([&] { loadScene(file.string(), overrides); });
  };
  std::string what = errorWith("1e-400");
  EXPECT_TRUE(contains(what, ".yaml:4:11: model.point_mass.mass: '1e-400' is out of the range of a double (it would be read as 0)")) << what;
  what = errorWith("-1e400");
  EXPECT_TRUE(contains(what, "'-1e400' is out of the range of a double (it would be read as infinite)")) << what;
  what = errorWith("sqrt(m - 2)");
  EXPECT_TRUE(contains(what, "expression 'sqrt(m - 2)' evaluates to -nan with m = 1")) << what;
  EXPECT_FALSE(contains(what, "(--set)")) << what;
  what = errorWith("sqrt(m - 2)", {{"m", 1.5}});
  EXPECT_TRUE(contains(what, "with m = 1.5 (--set)")) << what;
  what = errorWith("0.0e5");  // zero written as zero: left to the mass check
  EXPECT_FALSE(contains(what, "out of the range")) << what;
  EXPECT_TRUE(contains(what, "mass")) << what;
  std::filesystem::remove(file);
}

TEST(Scenario, UnknownOverrideListsTheParameters) {
  const std::string what = errorOf([] { loadScene("ball_drop", {{"heigth", 2.0}}); });
  // The message points at the scene's `parameters:` map.
  std::ifstream in(kSceneDir + "ball_drop.yaml");
  std::string line;
  int n = 0, params_line = -1;
  while (std::getline(in, line) && params_line < 0)
    if (++n, line.rfind("parameters:", 0) == 0) params_line = n;
  ASSERT_GT(params_line, 0);
  EXPECT_TRUE(contains(what, kSceneDir + "ball_drop.yaml:" + std::to_string(params_line) + ":")) << what;
  EXPECT_TRUE(contains(what, "parameters: ")) << what;
  EXPECT_TRUE(contains(what, "heigth")) << what;
  EXPECT_TRUE(contains(what, "height, restitution")) << what;
  EXPECT_TRUE(contains(what, "did you mean 'height'")) << what;
}

TEST(Scenario, BlockSlide) {
  const double incline = 0.3, g = 9.81;
  const Scene s = loadScene("block_slide", {{"incline", incline}});
  ASSERT_EQ(s.model.nv(), 2);
  EXPECT_EQ(s.model.coordinate_name, (std::vector<std::string>{"s", "n"}));
  EXPECT_NEAR((s.model.gravity - Eigen::Vector3d(g * std::sin(incline), 0, -g * std::cos(incline))).norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(gap(s, 0, s.q0), 0.0);
  EXPECT_EQ(s.v0, Eigen::Vector2d(2.0, 0.0));
  EXPECT_DOUBLE_EQ(s.contacts[0].friction, 0.3);
  EXPECT_EQ(s.contacts[0].directions, 2);
  EXPECT_DOUBLE_EQ(s.model.totalMass(), 1.0);
  // s moves along the slope, n off it.
  EXPECT_DOUBLE_EQ(gap(s, 0, Eigen::Vector2d(1.0, 0.0)), 0.0);
  EXPECT_DOUBLE_EQ(gap(s, 0, Eigen::Vector2d(0.0, 0.5)), 0.5);
  // Level by default.
  const Scene level = loadScene("block_slide");
  EXPECT_EQ(level.model.gravity, Eigen::Vector3d(0, 0, -9.81));
}

TEST(Scenario, PendulumConveyorTipRestsOnTheBelt) {
  const Scene s = loadScene("pendulum_conveyor");
  ASSERT_EQ(s.model.nv(), 2);
  EXPECT_EQ(s.model.base, dynamics::BaseType::Fixed);
  EXPECT_EQ(s.q0, Eigen::Vector2d(0, kPi / 4));
  EXPECT_TRUE(s.v0.isZero());
  const Contact& c = s.contacts[0];
  EXPECT_EQ(c.link, "tip");
  EXPECT_EQ(c.restitution, 0.0);
  EXPECT_DOUBLE_EQ(c.friction, 2.0);
  EXPECT_EQ(c.directions, 2);
  // Forward kinematics: the tip is at (−0.5 sin θ2, 0, −0.5 − 0.5 cos θ2), on the belt.
  const Eigen::Vector3d tip = framePosition(s, "tip", s.q0);
  EXPECT_NEAR((tip - Eigen::Vector3d(-0.5 * std::sin(kPi / 4), 0, -0.5 - 0.5 * std::cos(kPi / 4))).norm(), 0, 1e-12);
  EXPECT_NEAR((contactPosition(s, 0, s.q0) - tip).norm(), 0, 1e-15);
  EXPECT_NEAR(gap(s, 0, s.q0), 0.0, 1e-12);
  EXPECT_EQ(s.surfaces[0].normal, Eigen::Vector3d::UnitZ());
}

TEST(Scenario, PendulumConveyorBeltSchedule) {
  const Scene s = loadScene("pendulum_conveyor");
  const Surface& belt = s.surfaces[s.contacts[0].surface];
  EXPECT_EQ(belt.velocity(0.0), Eigen::Vector3d::Zero());
  EXPECT_EQ(belt.velocity(0.0999), Eigen::Vector3d::Zero());
  EXPECT_EQ(belt.velocity(0.1), Eigen::Vector3d(0.5, 0, 0));
  EXPECT_EQ(belt.velocity(10.0), Eigen::Vector3d(0.5, 0, 0));
  // The belt drags the tip toward the point below the elbow (the paradoxical direction).
  const Eigen::Vector3d tip = framePosition(s, "tip", s.q0), elbow = framePosition(s, "link2", s.q0);
  EXPECT_GT(belt.velocity(1.0).x() * (elbow.x() - tip.x()), 0);

  const Scene t = loadScene("pendulum_conveyor", {{"belt_speed", 1.5}, {"belt_step_time", 0.25}});
  const Surface& b2 = t.surfaces[0];
  EXPECT_EQ(b2.velocity(0.2), Eigen::Vector3d::Zero());
  EXPECT_EQ(b2.velocity(0.25), Eigen::Vector3d(1.5, 0, 0));
}

TEST(Scenario, PendulumConveyorBeltFollowsTheInitialAngles) {
  const Scene s = loadScene("pendulum_conveyor", {{"theta1_0", 0.2}, {"theta2_0", 0.6}});
  EXPECT_EQ(s.q0, Eigen::Vector2d(0.2, 0.6));
  EXPECT_NEAR(gap(s, 0, s.q0), 0.0, 1e-12);
}

TEST(Scenario, PainleveRod) {
  const Scene s = loadScene("painleve_rod");
  ASSERT_EQ(s.model.nv(), 3);
  EXPECT_EQ(s.model.base, dynamics::BaseType::Planar);
  EXPECT_EQ(s.model.coordinate_name, (std::vector<std::string>{"base_x", "base_z", "base_theta"}));
  const double angle = std::atan(2.0), l = 0.5, m = 1.0, mu = 2.0;
  EXPECT_NEAR(s.q0[2], angle, 1e-15);
  EXPECT_NEAR(s.q0[1], l * std::sin(angle), 1e-15);
  EXPECT_EQ(s.v0, Eigen::Vector3d(1.0, 0, 0));
  EXPECT_NEAR(gap(s, 0, s.q0), 0.0, 1e-15);
  // The contact end is ahead of the centre along +x (it leads) and below it.
  const Eigen::Vector3d end = contactPosition(s, 0, s.q0);
  EXPECT_NEAR(end.x(), l * std::cos(angle), 1e-15);
  EXPECT_EQ(s.contacts[0].p_B, Eigen::Vector3d(l, 0, 0));
  EXPECT_EQ(s.contacts[0].directions, 2);
  EXPECT_DOUBLE_EQ(s.contacts[0].friction, mu);
  // Uniform rod (body 0, on the planar base joint): I about the centre = m (2l)²/12 = m l²/3
  // across the rod, small along it.
  const dynamics::RigidInertia<double>& I = s.model.inertia[0];
  EXPECT_DOUBLE_EQ(I.m, m);
  EXPECT_TRUE(I.h.isZero());
  EXPECT_NEAR(I.I(1, 1), m * l * l / 3, 1e-15);
  EXPECT_NEAR(I.I(2, 2), m * l * l / 3, 1e-15);
  EXPECT_GT(I.I(0, 0), 0);
  EXPECT_LT(I.I(0, 0), 1e-3 * I.I(1, 1));
  // Painlevé: friction above (1 + 3cos²θ)/(3 sinθ cosθ) = 4/3 at tan θ = 2.
  const double c = std::cos(angle), sn = std::sin(angle);
  EXPECT_NEAR((1 + 3 * c * c) / (3 * sn * c), 4.0 / 3.0, 1e-12);
  EXPECT_GT(mu, (1 + 3 * c * c) / (3 * sn * c));
}

TEST(Scenario, PainleveRodExpressionsFollowOverrides) {
  const Scene s = loadScene("painleve_rod", {{"half_length", 1.0}, {"angle", 0.7}, {"mass", 2.0}});
  EXPECT_NEAR(gap(s, 0, s.q0), 0.0, 1e-15);
  EXPECT_EQ(s.contacts[0].p_B, Eigen::Vector3d(1.0, 0, 0));
  EXPECT_NEAR(s.model.inertia[0].I(1, 1), 2.0 * 4.0 / 12.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.q0[2], 0.7);
}

// ---------------------------------------------------------------------------------------------
// Overrides, defaults, limits, the scenes directory

TEST(Scenario, ParseOverrides) {
  const auto o = parseOverrides({"height=2", " angle = pi/4 ", "speed=-1.5e-1", "height=3"});
  EXPECT_EQ(o.size(), 3u);
  EXPECT_DOUBLE_EQ(o.at("height"), 3.0);  // the later assignment wins
  EXPECT_DOUBLE_EQ(o.at("angle"), kPi / 4);
  EXPECT_DOUBLE_EQ(o.at("speed"), -0.15);
  for (const std::string bad : {"height", "=2", "he ight=2", "height=abc", "height=", "height=1/0", "a=b=2"}) {
    SCOPED_TRACE(bad);
    const std::string what = errorOf([&] { parseOverrides({"x=1", bad}); });
    EXPECT_TRUE(contains(what, "'" + bad + "'")) << what;
  }
}

TEST(Scenario, Defaults) {
  const Scene s = loadScene(kDataDir + "defaults.yaml");
  EXPECT_EQ(s.name, "defaults");
  EXPECT_EQ(s.description, "");
  EXPECT_EQ(s.model.gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.duration, 1.0);
  EXPECT_TRUE(s.parameters.empty());
  ASSERT_EQ(s.surfaces.size(), 1u);
  EXPECT_EQ(s.surfaces[0].point, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.surfaces[0].normal, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(s.surfaces[0].velocity(5.0), Eigen::Vector3d::Zero());
  ASSERT_EQ(s.contacts.size(), 1u);
  EXPECT_EQ(s.contacts[0].name, "mass");
  EXPECT_EQ(s.contacts[0].p_B, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.contacts[0].restitution, 0.0);
  EXPECT_EQ(s.contacts[0].directions, 2);  // point mass moving in x–z only: planar
  EXPECT_TRUE(s.q0.isZero() && s.v0.isZero() && s.tau.isZero());
  EXPECT_DOUBLE_EQ(s.model.totalMass(), 2.0);
}

TEST(Scenario, FreeRigidBody) {
  const Scene s = loadScene(kDataDir + "free_rigid_body.yaml");
  ASSERT_EQ(s.model.nv(), 6);
  EXPECT_DOUBLE_EQ(s.parameters.at("b"), 0.2);
  EXPECT_DOUBLE_EQ(s.q0[2], 0.2);
  ASSERT_EQ(s.contacts.size(), 2u);
  EXPECT_EQ(s.contacts[0].directions, 4);  // spatial cone
  EXPECT_EQ(s.contacts[1].directions, 0);  // frictionless
  EXPECT_NEAR(gap(s, 0, s.q0), 0.0, 1e-15);
  EXPECT_NEAR(gap(s, 1, s.q0), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.duration, 2.0);
  // The centre of mass is kept: h = m c.
  EXPECT_NEAR((s.model.inertia[0].h - Eigen::Vector3d(0, 0, 0.03)).norm(), 0, 1e-15);
  // Overriding a parameter changes the ones computed from it.
  const Scene t = loadScene(kDataDir + "free_rigid_body.yaml", {{"a", 0.3}});
  EXPECT_DOUBLE_EQ(t.parameters.at("b"), 0.6);
  EXPECT_NEAR(gap(t, 0, t.q0), 0.0, 1e-15);
}

// A quaternion base: the orientation from yaw, pitch and roll (at pitch π/2, where the Euler base
// is singular), or as a quaternion; velocities in body axes.
TEST(Scenario, QuaternionBaseInitialState) {
  const Scene s = loadScene(kDataDir + "quaternion_free_body.yaml");
  ASSERT_EQ(s.model.base, dynamics::BaseType::FreeQuaternion);
  ASSERT_EQ(s.q0.size(), 7);
  EXPECT_DOUBLE_EQ(s.q0[2], 1.5);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitX())).toRotationMatrix();
  const Eigen::Vector4d Q = s.q0.segment<4>(3);
  EXPECT_NEAR(Q.norm(), 1.0, 1e-15);
  EXPECT_LT((Eigen::Quaterniond(Q[0], Q[1], Q[2], Q[3]).toRotationMatrix() - R).norm(), 1e-14);
  EXPECT_DOUBLE_EQ(s.v0[0], 1.0);
  EXPECT_DOUBLE_EQ(s.v0[5], 2.0);  // base_wz
  // No orientation given: the identity.
  const Scene spin = loadScene("fast_spin");
  EXPECT_EQ(spin.q0.segment<4>(3), Eigen::Vector4d(1, 0, 0, 0));
  EXPECT_EQ(spin.model.position_name[3], "base_qw");
}
TEST(Scenario, JointLimitStopsAndInput) {
  const Scene s = loadScene(kDataDir + "limits.yaml");
  ASSERT_EQ(s.limits.size(), 4u);
  const int rev = s.model.coordinateIndex("rev"), pris = s.model.coordinateIndex("pris");
  struct Expected {
    std::string name;
    int coordinate;
    bool upper;
    double limit;
  };
  const std::vector<Expected> expected = {
      {"rev_lower", rev, false, -1.0}, {"rev_upper", rev, true, 2.0},
      {"pris_lower", pris, false, -0.1}, {"pris_upper", pris, true, 0.3}};
  for (const Expected& e : expected) {
    const auto it = std::find_if(s.limits.begin(), s.limits.end(), [&](const LimitStop& l) { return l.name == e.name; });
    ASSERT_NE(it, s.limits.end()) << e.name;
    EXPECT_EQ(it->coordinate, e.coordinate) << e.name;
    EXPECT_EQ(it->upper, e.upper) << e.name;
    EXPECT_DOUBLE_EQ(it->limit, e.limit) << e.name;
    EXPECT_DOUBLE_EQ(it->restitution, 0.2) << e.name;
  }
  // The constant input, by coordinate; the others stay zero.
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(s.model.nv());
  tau[rev] = 0.5;
  tau[pris] = -2;
  EXPECT_EQ(s.tau, tau);

  // A list: stops for the named coordinates only, restitution 0 by default.
  const Scene t = loadScene(kDataDir + "limits_list.yaml");
  ASSERT_EQ(t.limits.size(), 2u);
  EXPECT_EQ(t.limits[0].name, "pris_lower");
  EXPECT_EQ(t.limits[1].name, "pris_upper");
  EXPECT_EQ(t.limits[0].coordinate, pris);
  EXPECT_EQ(t.limits[1].restitution, 0.0);
}

TEST(Scenario, ScenesDirectoryFromTheEnvironment) {
  ASSERT_EQ(setenv("SALTUS_SCENES_DIR", kDataDir.c_str(), 1), 0);
  const std::vector<std::string> names = builtinSceneNames();
  const std::string what = errorOf([] { loadScene("ball_drop"); });
  const Scene s = loadScene("limits");
  unsetenv("SALTUS_SCENES_DIR");
  EXPECT_NE(std::find(names.begin(), names.end(), "limits"), names.end());
  EXPECT_EQ(std::find(names.begin(), names.end(), "ball_drop"), names.end());
  EXPECT_TRUE(contains(what, "unknown built-in scene 'ball_drop'")) << what;
  EXPECT_EQ(s.source, "builtin:limits");
  EXPECT_EQ(s.limits.size(), 4u);
}

TEST(Scenario, UnknownBuiltinListsTheBuiltins) {
  const std::string what = errorOf([] { loadScene("ball_dorp"); });
  EXPECT_TRUE(contains(what, "unknown built-in scene 'ball_dorp'")) << what;
  EXPECT_TRUE(contains(what, "did you mean 'ball_drop'")) << what;
  EXPECT_TRUE(contains(what, "ball_drop, block_on_cart, block_on_slab, block_slide, box_on_corners, box_stack, chain_on_stops, fast_spin, hyq_drop, newtons_cradle, painleve_rod, pendulum_conveyor, rocking_block")) << what;
}

TEST(Scenario, MissingFile) {
  const std::string what = errorOf([] { loadScene(kDataDir + "no_such_file.yaml"); });
  EXPECT_TRUE(contains(what, kDataDir + "no_such_file.yaml: cannot open")) << what;
}

}  // namespace
}  // namespace saltus::scene
