#include "verify/engine.hpp"

#include <algorithm>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace saltus::verify {

const char* engineName(EngineKind kind) {
  switch (kind) {
    case EngineKind::Saltus: return "saltus";
    case EngineKind::Bullet: return "bullet";
    case EngineKind::Mujoco: return "mujoco";
  }
  return "?";
}

std::vector<EngineKind> parseEngines(const std::string& name) {
  if (name == "both") return {EngineKind::Saltus, EngineKind::Bullet};
  if (name == "all") return {EngineKind::Saltus, EngineKind::Bullet, EngineKind::Mujoco};
  std::vector<EngineKind> engines;  // one name, or a comma-separated list of them
  for (std::size_t start = 0;;) {
    const std::size_t comma = name.find(',', start);
    const std::string one = name.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    EngineKind kind;
    if (one == "saltus") kind = EngineKind::Saltus;
    else if (one == "bullet") kind = EngineKind::Bullet;
    else if (one == "mujoco") kind = EngineKind::Mujoco;
    else
      throw std::invalid_argument("unknown engine '" + one + "' (expected saltus, bullet, mujoco, a comma-separated list of them, both or all)");
    if (std::find(engines.begin(), engines.end(), kind) == engines.end()) engines.push_back(kind);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return engines;
}

namespace {

class SaltusEngine final : public Engine {
 public:
  SaltusEngine(const scene::Scene& scene, const timestepper::StepperOptions& options) : stepper_(scene, options) {}
  void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) override { stepper_.reset(q, v, t); }
  void step() override { stepper_.step(); }
  void step(const Eigen::VectorXd& tau) override {
    stepper_.setInput(tau);
    stepper_.step();
  }
  const Eigen::VectorXd& q() const override { return stepper_.q(); }
  const Eigen::VectorXd& v() const override { return stepper_.v(); }
  double time() const override { return stepper_.time(); }
  double energy() override { return stepper_.energy(); }
  long steps() const override { return stepper_.stats().steps; }
  long failures() const override { return stepper_.stats().lcp_failures; }
  double maxPenetration() const override { return stepper_.stats().max_penetration; }
  EngineContact contact(int c) const override {
    const timestepper::ContactReport& r = stepper_.contacts()[static_cast<std::size_t>(c)];
    return {r.gap, r.vn, r.pn, std::hypot(r.pt1, r.pt2)};
  }
  std::vector<std::string> approximations() const override { return {}; }

 private:
  timestepper::TimeStepper stepper_;
};

class BulletEngine final : public Engine {
 public:
  BulletEngine(const scene::Scene& scene, const BulletWorldOptions& options) : world_(scene, options) {}
  void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) override { world_.reset(q, v, t); }
  void step() override {
    world_.step();
    checkFinite();
  }
  void step(const Eigen::VectorXd& tau) override {
    world_.step(tau);
    checkFinite();
  }
  const Eigen::VectorXd& q() const override { return world_.q(); }
  const Eigen::VectorXd& v() const override { return world_.v(); }
  double time() const override { return world_.time(); }
  double energy() override { return world_.energy(); }
  long steps() const override { return world_.stats().steps; }
  long failures() const override { return world_.stats().mlcp_fallbacks; }
  double maxPenetration() const override { return world_.stats().max_penetration; }
  EngineContact contact(int c) const override {
    const BulletContactReport& r = world_.contacts()[static_cast<std::size_t>(c)];
    return {r.gap, r.vn, r.pn, std::hypot(r.pt1, r.pt2)};
  }
  std::vector<std::string> approximations() const override { return world_.approximations(); }

 private:
  // Bullet reports no failure of its own: a state that is no longer finite is one.
  void checkFinite() const {
    if (world_.q().allFinite() && world_.v().allFinite()) return;
    std::ostringstream s;
    s << "Bullet: the state is not finite at t = " << world_.time() << " s";
    throw timestepper::SimulationError(s.str(), world_.time(), {}, std::nan(""));
  }
  BulletWorld world_;
};

class MujocoEngine final : public Engine {
 public:
  MujocoEngine(const scene::Scene& scene, const MujocoWorldOptions& options) : world_(scene, options) {}
  void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) override { world_.reset(q, v, t); }
  void step() override { world_.step(); }  // throws SimulationError on a bad acceleration
  void step(const Eigen::VectorXd& tau) override { world_.step(tau); }
  const Eigen::VectorXd& q() const override { return world_.q(); }
  const Eigen::VectorXd& v() const override { return world_.v(); }
  double time() const override { return world_.time(); }
  double energy() override { return world_.energy(); }
  long steps() const override { return world_.stats().steps; }
  long failures() const override { return world_.stats().warnings; }
  double maxPenetration() const override { return world_.stats().max_penetration; }
  EngineContact contact(int c) const override {
    const MujocoContactReport& r = world_.contacts()[static_cast<std::size_t>(c)];
    return {r.gap, r.vn, r.pn, std::hypot(r.pt1, r.pt2)};
  }
  std::vector<std::string> approximations() const override { return world_.approximations(); }

 private:
  MujocoWorld world_;
};

}  // namespace

std::unique_ptr<Engine> makeEngine(const scene::Scene& scene, const EngineOptions& options) {
  switch (options.kind) {
    case EngineKind::Saltus: return std::make_unique<SaltusEngine>(scene, options.saltus);
    case EngineKind::Bullet: return std::make_unique<BulletEngine>(scene, options.bullet);
    case EngineKind::Mujoco: return std::make_unique<MujocoEngine>(scene, options.mujoco);
  }
  throw std::invalid_argument("unknown engine kind");
}

}  // namespace saltus::verify
