// verify/engine.cpp: Saltus' stepper, Bullet's world and MuJoCo behind one face. All bounce the ball of
// ball_drop with the impulse Newton's restitution gives, m (1 + e) sqrt(2 g h); a force equal to
// the weight holds a free-flying ball at constant velocity; a state that is not finite is a
// SimulationError in all; the engine list parses.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>
#include <stdexcept>

#include <gtest/gtest.h>

#include "scene/scenario.hpp"
#include "verify/engine.hpp"

namespace {

using saltus::verify::EngineKind;
using saltus::verify::EngineOptions;

EngineOptions optionsFor(EngineKind kind, double dt) {
  EngineOptions o;
  o.kind = kind;
  o.saltus.dt = dt;
  o.bullet.dt = dt;
  o.mujoco.dt = dt;
  return o;
}

class EngineFace : public ::testing::TestWithParam<EngineKind> {};

TEST_P(EngineFace, TheBallBouncesWithNewtonsImpulse) {
  const saltus::scene::Scene scene = saltus::scene::loadScene("ball_drop", {{"restitution", 0.5}, {"height", 1.0}});
  // MuJoCo's contact is a spring whose rebound tends to e as dt -> 0 (mujoco_world.hpp): 1e-4 s.
  const double dt = GetParam() == EngineKind::Mujoco ? 1e-4 : 1e-3;
  const auto engine = saltus::verify::makeEngine(scene, optionsFor(GetParam(), dt));
  double impulse = 0, apex = 0;
  while (engine->time() < 0.8 - 1e-9) {  // one bounce: the ball lands at 0.45 s, again at 0.90 s
    engine->step();
    impulse += engine->contact(0).pn;
    if (engine->time() > 0.5) apex = std::max(apex, engine->q()[0]);
  }
  const double m = scene.model.totalMass(), g = 9.81;
  EXPECT_NEAR(impulse, m * 1.5 * std::sqrt(2 * g), 0.03 * m * std::sqrt(2 * g));
  EXPECT_NEAR(apex, 0.25, 0.02);
  EXPECT_EQ(engine->steps(), std::lround(0.8 / dt));
  EXPECT_EQ(engine->failures(), 0);
  EXPECT_GE(engine->contact(0).gap, -1e-3);
}

TEST_P(EngineFace, TheWeightAsAnInputHoldsTheVelocity) {
  const saltus::scene::Scene scene = saltus::scene::loadScene("ball_drop", {{"height", 1.0}});
  const auto engine = saltus::verify::makeEngine(scene, optionsFor(GetParam(), 1e-3));
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(1, 0.5), v0 = Eigen::VectorXd::Constant(1, -0.2);
  engine->reset(q0, v0, 0.0);
  const Eigen::VectorXd weight = Eigen::VectorXd::Constant(1, scene.model.totalMass() * 9.81);
  for (int k = 0; k < 100; ++k) engine->step(weight);
  EXPECT_NEAR(engine->v()[0], -0.2, 1e-9);
  EXPECT_NEAR(engine->q()[0], 0.5 - 0.2 * 0.1, 1e-9);
  EXPECT_NEAR(engine->time(), 0.1, 1e-12);
}

TEST_P(EngineFace, AStateThatIsNotFiniteIsASimulationError) {
  const saltus::scene::Scene scene = saltus::scene::loadScene("ball_drop", {});
  const auto engine = saltus::verify::makeEngine(scene, optionsFor(GetParam(), 1e-3));
  engine->reset(Eigen::VectorXd::Constant(1, 0.5), Eigen::VectorXd::Constant(1, std::nan("")), 0.0);
  EXPECT_THROW(engine->step(), saltus::timestepper::SimulationError);
}

// The contact of `scene` named `name`.
int contactNamed(const saltus::scene::Scene& scene, const std::string& name) {
  for (std::size_t c = 0; c < scene.contacts.size(); ++c)
    if (scene.contacts[c].name == name) return static_cast<int>(c);
  ADD_FAILURE() << "no contact " << name;
  return 0;
}

// A scene of three parts (a planar board, two point masses on it): standing, nothing moves, the
// wheels carry the whole weight and each foot its rider's (statics).
TEST_P(EngineFace, TheSkateboardStandsOnItsWheels) {
  const saltus::scene::Scene scene = saltus::scene::loadScene("skateboard");
  const auto engine = saltus::verify::makeEngine(scene, optionsFor(GetParam(), 1e-3));
  const int rear = contactNamed(scene, "rear_wheel"), front = contactNamed(scene, "front_wheel");
  const int back_foot = contactNamed(scene, "back_foot"), front_foot = contactNamed(scene, "front_foot");
  double wheels = 0, back = 0, forward = 0, window = 0;
  Eigen::VectorXd settled;
  while (engine->time() < 0.5 - 1e-9) {
    engine->step();
    if (engine->time() <= 0.3 + 1e-9) {  // the last 0.2 s: settled
      settled = engine->q();
      continue;
    }
    wheels += engine->contact(rear).pn + engine->contact(front).pn;
    back += engine->contact(back_foot).pn;
    forward += engine->contact(front_foot).pn;
    window += 1e-3;
  }
  const double g = 9.81, rider = 36.5, total = scene.model.totalMass();
  EXPECT_NEAR(total, 2.38 + 2 * rider, 1e-12);
  EXPECT_NEAR(wheels / window, total * g, 0.01 * total * g);
  EXPECT_NEAR(back / window, rider * g, 0.01 * rider * g);
  EXPECT_NEAR(forward / window, rider * g, 0.01 * rider * g);
  // Saltus holds the statics exactly. MuJoCo's contacts are stiff springs: they sink by a fraction
  // of a millimetre under 75 kg, and stay. Bullet's feet creep into the board, about 8 mm/s (its
  // contacts have no position correction here, erp2 = 0: a velocity error of its solver at the
  // mass ratio of 15 between a foot and the board accumulates): 4 mm after 0.5 s, against 8 mm here.
  const double sink = GetParam() == EngineKind::Saltus ? 1e-8 : GetParam() == EngineKind::Mujoco ? 1e-3 : 8e-3;
  EXPECT_LT((engine->q() - scene.q0).cwiseAbs().maxCoeff(), sink) << engine->q().transpose();
  if (GetParam() != EngineKind::Bullet) { EXPECT_LT((engine->q() - settled).cwiseAbs().maxCoeff(), 1e-4) << "creeping"; }
  EXPECT_EQ(engine->failures(), 0);
}

INSTANTIATE_TEST_SUITE_P(AllEngines, EngineFace, ::testing::Values(EngineKind::Saltus, EngineKind::Bullet, EngineKind::Mujoco),
                         [](const auto& info) { return std::string(saltus::verify::engineName(info.param)); });

TEST(EngineList, ParsesNamesAndRefusesOthers) {
  EXPECT_EQ(saltus::verify::parseEngines("saltus"), std::vector<EngineKind>{EngineKind::Saltus});
  EXPECT_EQ(saltus::verify::parseEngines("bullet"), std::vector<EngineKind>{EngineKind::Bullet});
  EXPECT_EQ(saltus::verify::parseEngines("mujoco"), std::vector<EngineKind>{EngineKind::Mujoco});
  EXPECT_EQ(saltus::verify::parseEngines("both"), (std::vector<EngineKind>{EngineKind::Saltus, EngineKind::Bullet}));
  EXPECT_EQ(saltus::verify::parseEngines("all"),
            (std::vector<EngineKind>{EngineKind::Saltus, EngineKind::Bullet, EngineKind::Mujoco}));
  EXPECT_THROW(saltus::verify::parseEngines("ode"), std::invalid_argument);
}

// The front rider's weight carried (front_lift 1): the back foot, behind the rear wheel, tips the
// board about that wheel until the tail strikes the ground. The three engines, one through its
// own multibody (Bullet's btMultiBody, MuJoCo's bodies), agree on when and at what pitch it
// strikes: the tail's tip then at the ground, (−0.407, 0.044) below the board's origin by the
// rear wheel's pivot.
TEST(Skateboard, ThreeEnginesTipItOntoItsTailTogether) {
  const saltus::scene::Scene scene = saltus::scene::loadScene("skateboard", {{"front_lift", 1.0}});
  const int tail = contactNamed(scene, "tail"), front = contactNamed(scene, "front_wheel");
  const int theta = scene.model.coordinateIndex("board_theta");
  ASSERT_GE(theta, 0);
  // The pitch at which the tail's tip touches the ground, pivoting about the rear wheel's contact
  // point (−0.222, −0.0775) on the ground: the tip is at r = (−0.185, 0.1215) from it.
  const auto& k = scene.parameters;
  const double rx = k.at("tail_x") + k.at("wheel_x"), rz = k.at("tail_z") + k.at("clearance");
  // R(θ) (x, z) = (x cos θ + z sin θ, −x sin θ + z cos θ): height −rx sin θ + rz cos θ = 0.
  const double strike_pitch = std::atan2(rz, rx);  // −rx sin θ = −rz cos θ → tan θ = rz / rx
  const double expected = strike_pitch > 0 ? strike_pitch - M_PI : strike_pitch;  // the negative root (nose up)
  std::vector<double> times;
  for (EngineKind kind : {EngineKind::Saltus, EngineKind::Bullet, EngineKind::Mujoco}) {
    const auto engine = saltus::verify::makeEngine(scene, optionsFor(kind, 1e-3));
    double strike = -1, pitch = 0, lift = 0;
    while (engine->time() < 1.0 - 1e-9) {
      engine->step();
      if (strike < 0 && engine->contact(tail).pn > 1e-6) strike = engine->time(), pitch = engine->q()[theta];
      lift = std::max(lift, engine->contact(front).gap);
    }
    SCOPED_TRACE(saltus::verify::engineName(kind));
    ASSERT_GT(strike, 0) << "the tail never struck";
    EXPECT_NEAR(pitch, expected, 0.02);
    EXPECT_GT(lift, 0.1) << "the front wheel should rise with the nose";
    times.push_back(strike);
  }
  EXPECT_NEAR(times[1], times[0], 0.02) << "Bullet against Saltus";
  EXPECT_NEAR(times[2], times[0], 0.02) << "MuJoCo against Saltus";
}

}  // namespace
