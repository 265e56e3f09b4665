// A third engine for scenes: MuJoCo 2.2.2 (Debian's libmujoco-dev), the simulator most robotics
// researchers use, time-stepping the same saltus Scene (scene/scene.hpp) as Saltus' stepper and
// Bullet (bullet_world.hpp), for comparisons and replays.
//
// What is built from the scene (an MJCF model written in memory, mjcf() returns it):
//  - one MuJoCo body per saltus body, nested as the tree, at X_T(i) (the joint frame at q = 0) in
//    its parent, with the body's mass, centre of mass and full inertia about it (a massless
//    saltus body gets 1e-9 kg and 1e-12 kg m²: MuJoCo needs mass on every moving body);
//  - joints: a revolute body a hinge, a prismatic one a slide, about the saltus axis; a planar
//    base (x, z, θ) the slides along x and z and the hinge about y, in that order (MuJoCo composes
//    a body's joints in order, which gives saltus' p = (x, 0, z), R = Ry(θ)). Each joint is named
//    after its saltus coordinate, so that qpos, qvel and the applied forces map by name;
//  - each scene contact point on a world surface: a sphere of radius `contact_radius` at the point
//    on its body, and each surface a plane moved back by the radius (n·x = n·p − r), so that the
//    sphere–plane distance is the saltus gap at every orientation (as in bullet_world.hpp). A
//    plane fixed in a body is the top face of a box on that body, moved back by the radius, as
//    large as the plane's extent. Only the explicit <pair> of each contact collides (every geom
//    has contype = conaffinity = 0);
//  - friction: condim 3 with the contact's μ in both tangential directions and a pyramidal cone
//    (MuJoCo's default; the closest to saltus' polyhedral cone), condim 1 for a frictionless one;
//  - restitution: MuJoCo has none. A contact is a damped spring in MuJoCo's reference
//    acceleration a_ref = −b v − k r, per unit of effective mass, given directly as
//    solref = (−k, −b) (MuJoCo's documentation, "Solver parameters"). A linear spring of natural
//    frequency ω and damping ratio ζ rebounds with e = exp(−π ζ / √(1 − ζ²)), so
//    ζ = −ln e / √(π² + ln² e) (ζ = 1, critically damped, for e = 0), k = ω², b = 2 ζ ω, with
//    ω = 1 / (`timeconst_steps` · dt): MuJoCo's least time constant, 2 steps, for a stable
//    discrete spring at any ζ (the positive solref (τ, ζ) form has ω = 1 / (τ ζ), unstable for a
//    small ζ). The impedance is d = `impedance` at every depth (solimp d d), near rigid. The
//    rebound is that of a spring in contact for about 2π steps, not Newton's law at an instant;
//  - joint-limit stops: the joint's range with the same spring (its restitution through ζ);
//  - gravity: the Model's; the input: generalised forces τ as qfrc_applied, held over the step;
//  - integrator Euler (semi-implicit), Newton solver, `iterations` and `tolerance` as given.
// Not built (std::invalid_argument at construction): a free base (saltus' is Z–Y′–X″ Euler
// angles, MuJoCo's free joint a quaternion: to come with a quaternion base) and a surface with a
// velocity schedule (MuJoCo has no moving-plane contact).
//
// Gaps and velocities are saltus' contact layer's at MuJoCo's (q, v); impulses are MuJoCo's
// contact forces (mj_contactForce) times dt. MuJoCo's warnings are counted; a position, velocity
// or acceleration that is not finite, after which MuJoCo resets the state, is a
// timestepper::SimulationError.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/pair.hpp"
#include "dynamics/data.hpp"
#include "scene/scene.hpp"
#include "verify/measured_contact.hpp"

struct mjModel_;
struct mjData_;

namespace saltus::verify {

struct MujocoWorldOptions {
  double dt = 1e-3;
  double contact_radius = 1e-3;  // [m] sphere at each contact point
  double timeconst_steps = 2;    // contact spring: ω = 1 / (timeconst_steps dt) (MuJoCo's least time constant is 2 steps)
  double impedance = 0.99;       // solimp: constraint impedance at every depth (MuJoCo's default 0.9 … 0.95)
  int iterations = 100;          // Newton solver iterations (MuJoCo's default 100)
  double tolerance = 1e-10;      // solver tolerance (MuJoCo's default 1e-8)
};

// A scene contact after a step: kinematics from saltus, impulses from MuJoCo's contact force.
using MujocoContactReport = MeasuredContact;

struct MujocoWorldStats {
  long steps = 0;
  long warnings = 0;           // MuJoCo's warnings raised (solver, contacts, bad numbers)
  double max_penetration = 0;  // largest −gap after a step (contacts and limit stops) [m]
};

// The damping ratio of a spring–damper contact that rebounds with coefficient e ∈ [0, 1].
double dampingRatioForRestitution(double e);

class MujocoWorld {
 public:
  // Throws std::invalid_argument when the scene cannot be built in MuJoCo (see above), naming
  // the scene and what; std::runtime_error with MuJoCo's message when its compiler refuses.
  MujocoWorld(const scene::Scene& scene, MujocoWorldOptions options = {});
  ~MujocoWorld();
  MujocoWorld(const MujocoWorld&) = delete;
  MujocoWorld& operator=(const MujocoWorld&) = delete;

  // Starts from any state and time (the scene's q0, v0 at t = 0 after construction).
  void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t = 0);
  // One step with the scene's constant input, or with the generalised force tau (model
  // coordinate order) held over the step.
  void step();
  void step(const Eigen::VectorXd& tau);

  double time() const { return t_; }
  const Eigen::VectorXd& q() const { return q_; }
  const Eigen::VectorXd& v() const { return v_; }
  double energy();  // kinetic plus gravitational potential energy of (q, v), as TimeStepper::energy()
  const std::vector<MujocoContactReport>& contacts() const { return reports_; }  // scene contacts
  const MujocoWorldStats& stats() const { return stats_; }
  const std::vector<std::string>& approximations() const { return approximations_; }
  const std::string& mjcf() const { return mjcf_; }  // the model MuJoCo compiled

 private:
  void measure();
  void readState();

  const scene::Scene& scene_;
  std::vector<contact::ContactPair> pairs_;
  MujocoWorldOptions options_;
  dynamics::Data<double> data_;
  std::string mjcf_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  std::vector<int> qpos_address_, dof_address_;  // per saltus position coordinate (qpos), velocity coordinate (qvel)
  std::vector<int> pair_geom_;                   // per scene contact: its sphere geom
  Eigen::VectorXd q_, v_;
  double t_ = 0;
  std::vector<MujocoContactReport> reports_;
  MujocoWorldStats stats_;
  std::vector<std::string> approximations_;
};

}  // namespace saltus::verify
