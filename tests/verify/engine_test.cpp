// verify/engine.cpp: Saltus' stepper, Bullet's world and MuJoCo behind one face. All bounce the ball of
// ball_drop with the impulse Newton's restitution gives, m (1 + e) sqrt(2 g h); a force equal to
// the weight holds a free-flying ball at constant velocity; a state that is not finite is a
// SimulationError in all; the engine list parses.
#include <cmath>
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

}  // namespace
