// An independent forward-dynamics oracle: Bullet's btMultiBody (Featherstone articulated-body
// algorithm, double precision via pkg-config bullet-float64) built from a saltus Model.
//
// Mapping (see bullet_multibody.cpp for the derivations):
//  - every moving saltus body becomes one btMultiBody link whose frame sits at the body's centre
//    of mass with principal axes (Bullet wants a diagonal inertia about the com); the joint pivot
//    is the saltus joint origin, the axis is rotated into the principal frame;
//  - BaseType::Fixed: Bullet's fixed base is the world;
//  - BaseType::FreeQuaternion: Bullet's floating base, its quaternion and ω_B (rotated to and
//    from Bullet's world ω) taken as they are;
//  - BaseType::Free, FreeBase::Native (default): the root body becomes Bullet's floating base;
//    the Euler-coordinate state (x, y, z, yaw, pitch, roll) and its rates are converted to the
//    base pose and twist, base generalised forces to a wrench, and Bullet's base accelerations
//    (ω̇, com acceleration) back to q̈ including the Euler-rate terms;
//  - BaseType::Planar, or FreeBase::VirtualLinks: the base joint is expanded into a chain of
//    one-coordinate prismatic/revolute links, massless but for the last, on a fixed Bullet base
//    (Bullet's ABA copes with massless links whose subtree has mass).
// Forward dynamics is Bullet's computeAccelerationsArticulatedBodyAlgorithmMultiDof with dt = 0:
// the accelerations are read from its output, no time stepping is involved. The state conversions
// (setState / getState, generalised forces) are public so that a time-stepping Bullet world
// (bullet_world.hpp) can drive the same btMultiBody.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "dynamics/model.hpp"

class btMultiBody;

namespace saltus::verify {

enum class FreeBase {
  Native,        // the root body is Bullet's floating base
  VirtualLinks,  // the six virtual joints become massless Bullet links on a fixed base
};

class BulletMultiBody {
 public:
  // Throws std::invalid_argument when the model cannot be represented (e.g. a multi-coordinate
  // joint that is not body 0's joint to the world).
  explicit BulletMultiBody(const dynamics::Model<double>& model, FreeBase free_base = FreeBase::Native);
  ~BulletMultiBody();
  BulletMultiBody(const BulletMultiBody&) = delete;
  BulletMultiBody& operator=(const BulletMultiBody&) = delete;

  // q̈ in saltus coordinates (order and convention of the Model) from Bullet's articulated-body
  // algorithm, with the Model's gravity applied as a force m g at each body's centre of mass.
  Eigen::VectorXd forwardDynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                  const Eigen::VectorXd& tau);

  // saltus (q, v) -> Bullet joint and base state (no forces). Throws on a size mismatch.
  void setState(const Eigen::VectorXd& q, const Eigen::VectorXd& v);
  // Bullet state -> saltus (q, v). For a native free base the Euler angles (ψ, θ, φ) come from the
  // base rotation with θ ∈ [−π/2, π/2]; yaw and roll are unwrapped to the branch nearest
  // `q_hint`'s (when given), so a body that keeps turning has continuous coordinates.
  void getState(Eigen::VectorXd& q, Eigen::VectorXd& v, const Eigen::VectorXd* q_hint = nullptr) const;
  // Clears Bullet's applied forces and adds the generalised forces τ (joint torques / forces; for a
  // native free base the equivalent wrench at the com, see setState). Gravity is not added (a
  // btMultiBodyDynamicsWorld applies its own). Needs the base pose of the current state.
  void setGeneralisedForces(const Eigen::VectorXd& q, const Eigen::VectorXd& tau);

  btMultiBody* multiBody() { return mb_.get(); }
  const dynamics::Model<double>& model() const { return model_; }
  // Number of Bullet links (bodies other than Bullet's base).
  int numLinks() const;
  // The Bullet link that carries saltus body i (−1: Bullet's base, for a native free base).
  int linkOfBody(int body) const { return last_link_of_body_.at(body); }
  // The Bullet link whose joint is saltus coordinate k (−1 for a native free base's coordinates).
  int linkOfCoordinate(int coordinate) const;
  // A point given in saltus body coordinates, in the Bullet link frame of that body:
  // P_iᵀ (p_B − c_i) (the link frame sits at the com with principal axes).
  Eigen::Vector3d bodyPointInLinkFrame(int body, const Eigen::Vector3d& p_B) const;
  bool nativeFloatingBase() const { return native_free_; }

  // World position of the centre of mass of saltus body i after the last forwardDynamics call, as
  // Bullet sees it (for kinematic cross-checks of the mapping).
  Eigen::Vector3d comPosition(int body) const;

 private:
  void applyForces(const Eigen::VectorXd& q, const Eigen::VectorXd& tau, bool gravity);

  struct LinkSpec {
    int body;        // saltus body the link belongs to (the last link of a body carries it)
    int coordinate;  // saltus coordinate of its joint
    bool revolute;
    Eigen::Vector3d axis;  // in the saltus body (joint) frame
  };

  dynamics::Model<double> model_;
  bool native_free_ = false;
  bool quaternion_ = false;  // BaseType::FreeQuaternion (always native)
  Eigen::Matrix3d baseRotation(const Eigen::VectorXd& q) const;
  Eigen::Vector3d baseOmegaWorld(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  std::vector<LinkSpec> links_;        // Bullet link k
  std::vector<int> last_link_of_body_;  // per saltus body: its (last) Bullet link; −1 for Bullet's base
  std::vector<Eigen::Matrix3d> P_;  // principal axes of each body, in body coordinates
  std::vector<Eigen::Vector3d> c_;  // centre of mass of each body, body coordinates
  std::vector<double> m_;
  std::unique_ptr<btMultiBody> mb_;
};

}  // namespace saltus::verify
