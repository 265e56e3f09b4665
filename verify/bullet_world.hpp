// A second engine for scenes: Bullet's btMultiBodyDynamicsWorld (double precision, pkg-config
// bullet-float64) time-stepping a saltus Scene (scene/scene.hpp), for comparisons with the
// Moreau–Stewart–Trinkle stepper (timestepper/stepper.hpp) and for replaying inputs.
//
// What is built from the scene:
//  - the btMultiBody of the scene's Model through BulletMultiBody (bullet_multibody.hpp: tree,
//    principal inertias, joint types, fixed / planar / free base, saltus <-> Bullet state);
//  - gravity: the Model's, applied by the world;
//  - each scene contact point on a world surface: a sphere of radius `contact_radius` centred at
//    the point, a child of its link's compound collider (the link's m_collider; one material per
//    link). A contact on a plane fixed in another body: a sphere collider of its own on the
//    point's link and, on the plane's link, a box whose top face is the plane moved back by the
//    radius and whose size is the plane's extent; a broadphase filter lets the two meet each
//    other only (self-collision on, for one multibody), and both follow their links after every
//    step. Each Surface {n·(x − p) = 0} becomes a
//    btStaticPlaneShape moved back by the radius, n·x = n·p − r, so the sphere–plane distance
//    equals the saltus gap n·(x − p) for every orientation of the body. Only the point where the
//    force acts differs: x − r n instead of x (a moment error r |f_t| for friction forces);
//  - μ and e: each contact sphere carries the contact's friction and restitution, the planes 1
//    and 1, so Bullet's combined values (products) are the contact's (Bullet clamps the combined
//    friction to 10);
//  - friction directions: Bullet's. convertMultiBodyContact overwrites the lateral directions of
//    every multibody contact point with btPlaneSpace1(normal) (so neither a contact-added callback
//    nor direction caching can choose them); for a horizontal surface they are ±y and x. Two
//    directions are used (SOLVER_USE_2_FRICTION_DIRECTIONS), else a scene in the x–z plane would
//    have no friction along x; in a planar scene the y row has a zero Jacobian;
//  - joint-limit stops: one btMultiBodyJointLimitConstraint per limited coordinate (the missing
//    side at ±1e30); Bullet's limits are inelastic;
//  - a surface with a velocity schedule: a kinematic btRigidBody whose reported velocity is the
//    schedule's value at the end of the step, v_surface(t + h) (as in the saltus stepper), while
//    its plane stays in place (the plane is invariant under tangential motion). Bullet's own
//    conveyor mechanism, m_contactMotion1/2 on the manifold point, does not work for btMultiBody
//    contacts in Bullet 3.24: btMultiBodyConstraintSolver::setupMultiBodyContactConstraint takes
//    the desired velocity but never uses it;
//  - the input: generalised forces τ per step (the scene's constant τ unless step(tau) is given).
//
// Settings (BulletWorldOptions). Bullet's defaults lose or distort the bounce (bullet3#1530, and
// measured here with Bullet 3.24); the defaults here are tuned, each choice below:
//  - erp2 = 0: Bullet's default 0.2 turns penetration into a velocity (Baumgarte), which adds
//    energy (apex 0.483 instead of 0.25, measured here). Split impulse, Bullet's energy-neutral
//    alternative, is not implemented for btMultiBody contacts in 3.24 (the branch is commented
//    out in setupMultiBodyContactConstraint), so with erp2 = 0 a penetration stays: a resting
//    contact sits up to |v_impact| h below the surface;
//  - restitution_threshold = 1e-3 m/s: Bullet's default 0.2 m/s treats slower impacts as
//    inelastic, so bounces stop early (Saltus uses 2|g|h);
//  - contact_processing_threshold = 0: only touching or penetrating points are solved (Bullet's
//    default solves every manifold point, i.e. contacts within the breaking threshold before
//    they touch, where restitution acts early);
//  - solver: MLCP with Dantzig (default; see BulletSolver), sequential impulse (projected
//    Gauss–Seidel, `iterations` sweeps) on request; the MLCP solver falls back to sequential
//    impulse when it fails, counted in stats().mlcp_fallbacks;
//  - global_cfm = 1e-12: the zero-Jacobian friction rows above make the MLCP matrix singular and
//    Dantzig's factorisation fails (fallbacks on 68 % of the steps of block_slide and 98 % of
//    pendulum_conveyor at dt 1e-3 with cfm 0); 1e-12 on the diagonal removes every fallback and
//    changes the results by ~1e-11 (a resting contact sinks by cfm·m·g). 1e-6 already lowers the
//    first apex of ball_drop at dt 1e-4 by 6 %;
//  - no damping, no sleeping, no velocity clamp, no impulse clamp, warm starting off.
// BulletWorldOptions::bulletDefaults() gives Bullet's own values for comparison.
//
// approximations() lists in words what the Bullet world cannot represent exactly for the scene.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/pair.hpp"
#include "dynamics/data.hpp"
#include "scene/scene.hpp"
#include "verify/bullet_multibody.hpp"
#include "verify/measured_contact.hpp"

class btBroadphaseInterface;
class btCollisionDispatcher;
class btDefaultCollisionConfiguration;
class btMultiBodyConstraintSolver;
class btMultiBodyMLCPConstraintSolver;
class btMultiBodyDynamicsWorld;
class btMLCPSolverInterface;
class btCollisionShape;
class btRigidBody;
class btMultiBodyLinkCollider;
class btMultiBodyJointLimitConstraint;
class btCollisionObject;
class btPersistentManifold;

namespace saltus::verify {

// Dantzig is the default: it keeps Bullet's friction-to-normal coupling (bounds ±μ p_n through
// the `findex` dependency) and, with global_cfm 1e-12, never fell back on the built-in scenes.
// Bullet's Lemke wrapper falls back on the bounces (3–7 times per ball_drop run) and, where it
// does not, gets friction wrong: on block_slide (μ 0.3, v0 2 m/s, exact stop 0.680 m) the block
// stops after 5.7 mm.
enum class BulletSolver { MlcpDantzig, MlcpLemke, SequentialImpulse };

const char* bulletSolverName(BulletSolver solver);
// "dantzig", "lemke", "si" (or "sequential-impulse"); throws std::invalid_argument otherwise.
BulletSolver parseBulletSolver(const std::string& name);

struct BulletWorldOptions {
  double dt = 1e-3;
  BulletSolver solver = BulletSolver::MlcpDantzig;
  double contact_radius = 1e-3;              // [m] sphere at each contact point
  double erp2 = 0;                           // contact position correction (Bullet default 0.2)
  double restitution_threshold = 1e-3;       // [m/s] (Bullet default 0.2)
  double contact_processing_threshold = 1e-6;  // [m] (Bullet default: all manifold points)
  int iterations = 50;                       // sequential-impulse sweeps (Bullet default 10)
  double global_cfm = 1e-12;                 // constraint force mixing (Bullet default 0)

  // Bullet's own defaults for the settings above (dt and solver kept).
  static BulletWorldOptions bulletDefaults(double dt, BulletSolver solver);
};

// A scene contact after a step: kinematics from saltus, impulses from Bullet's manifold points.
using BulletContactReport = MeasuredContact;

struct BulletWorldStats {
  long steps = 0;
  long mlcp_fallbacks = 0;      // MLCP solves that failed and fell back to sequential impulse
  double max_penetration = 0;   // largest −gap after a step (contacts and limit stops) [m]
};

class BulletWorld {
 public:
  // Throws std::invalid_argument when the scene cannot be built in Bullet (e.g. a limit stop on a
  // coordinate of a native free base).
  BulletWorld(const scene::Scene& scene, BulletWorldOptions options = {});
  ~BulletWorld();
  BulletWorld(const BulletWorld&) = delete;
  BulletWorld& operator=(const BulletWorld&) = delete;

  // Starts from any state and time (the scene's q0, v0 at t = 0 after construction).
  void reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t = 0);
  // One step of size dt with the scene's constant input, or with generalised forces `tau`
  // (model coordinate order) held over this step: a time-varying input is one call per step.
  void step();
  void step(const Eigen::VectorXd& tau);

  double time() const { return t_; }
  const Eigen::VectorXd& q() const { return q_; }
  const Eigen::VectorXd& v() const { return v_; }
  // Kinetic plus gravitational potential energy of (q, v), as TimeStepper::energy().
  double energy();
  const std::vector<BulletContactReport>& contacts() const { return reports_; }  // scene contacts
  const BulletWorldStats& stats() const { return stats_; }
  const BulletWorldOptions& options() const { return options_; }
  const scene::Scene& scene() const { return scene_; }
  // What the Bullet world cannot represent exactly for this scene, in words.
  const std::vector<std::string>& approximations() const { return approximations_; }

 private:
  void placeBelts(double t_next);
  void measure();
  void addBodyPlanePair(int contact, btCollisionShape* sphere);
  void syncPairColliders();

  class PairFilter;  // broadphase filter: a body-plane contact's two colliders meet each other only
  static constexpr int kPairGroup = 1 << 6;  // collision group of the pair colliders

  scene::Scene scene_;
  std::vector<contact::ContactPair> pairs_;  // the contact layer's: scene contacts, then limit stops
  BulletWorldOptions options_;
  dynamics::Data<double> data_;
  double t_ = 0;
  Eigen::VectorXd q_, v_;
  std::vector<BulletContactReport> reports_;
  BulletWorldStats stats_;
  std::vector<std::string> approximations_;

  std::unique_ptr<BulletMultiBody> body_;
  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btMLCPSolverInterface> mlcp_;
  std::unique_ptr<btMultiBodyConstraintSolver> solver_;
  btMultiBodyMLCPConstraintSolver* mlcp_solver_ = nullptr;  // solver_ when it is an MLCP solver
  std::unique_ptr<btMultiBodyDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> surfaces_;             // per scene surface
  std::vector<bool> surface_moves_;                                // kinematic belt
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;  // per link with contacts
  std::vector<int> collider_link_;                                 // Bullet link of each collider (−1 base)
  std::unique_ptr<PairFilter> filter_;  // when a contact is on a body's plane
  std::vector<std::pair<int, int>> contact_child_;                 // per contact: collider, sphere child
  std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>> limits_;
  std::vector<int> limit_coordinate_;
  bool planar_cone_ = false;
};

}  // namespace saltus::verify
