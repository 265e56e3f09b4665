// One face for the engines that step a scene: Saltus' Moreau–Stewart–Trinkle time-stepper
// (timestepper/stepper.hpp), Bullet's btMultiBody world (bullet_world.hpp) and MuJoCo
// (mujoco_world.hpp). The benchmarks
// (`saltus bench`: work-precision and stability) and the replays (replay.hpp) drive either
// through it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scene/scene.hpp"
#include "timestepper/stepper.hpp"
#include "verify/bullet_world.hpp"
#include "verify/mujoco_world.hpp"

namespace saltus::verify {

enum class EngineKind { Saltus, Bullet, Mujoco };
const char* engineName(EngineKind kind);  // "saltus", "bullet", "mujoco"
// "saltus", "bullet", "mujoco", "both" (saltus and bullet) or "all" → the list; throws
// std::invalid_argument otherwise.
std::vector<EngineKind> parseEngines(const std::string& name);

// How an engine is set up: the stepper's options (Saltus) or the world's (Bullet, MuJoCo).
struct EngineOptions {
  EngineKind kind = EngineKind::Saltus;
  timestepper::StepperOptions saltus;
  BulletWorldOptions bullet;
  MujocoWorldOptions mujoco;
};

// A contact's state after the last step, both engines alike.
struct EngineContact {
  double gap = 0, vn = 0;  // [m], [m/s]: from Saltus' contact layer at (q, v)
  double pn = 0, pt = 0;   // normal impulse and the length of the tangential one over the step [N s]
};

class Engine {
 public:
  virtual ~Engine() = default;
  virtual void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t = 0) = 0;
  // One step with the scene's inputs, or with the generalised force tau held over the step.
  // Throws timestepper::SimulationError on an LCP failure (Saltus) or a state that is not finite.
  virtual void step() = 0;
  virtual void step(const Eigen::VectorXd& tau) = 0;

  virtual const Eigen::VectorXd& q() const = 0;
  virtual const Eigen::VectorXd& v() const = 0;
  virtual double time() const = 0;
  virtual double energy() = 0;  // kinetic + gravitational potential [J]
  virtual long steps() const = 0;
  virtual long failures() const = 0;  // LCP failures (Saltus) / MLCP fallbacks (Bullet) / warnings (MuJoCo)
  virtual double maxPenetration() const = 0;  // the engine's own count, limit stops included [m]
  // Scene contact c (not a limit stop) after the last step.
  virtual EngineContact contact(int c) const = 0;
  // What the engine approximates of the scene (bullet_world.hpp, mujoco_world.hpp); empty for Saltus.
  virtual std::vector<std::string> approximations() const = 0;
};

// Throws std::invalid_argument for a scene the engine cannot build (bullet_world.hpp, mujoco_world.hpp).
std::unique_ptr<Engine> makeEngine(const scene::Scene& scene, const EngineOptions& options);

}  // namespace saltus::verify
