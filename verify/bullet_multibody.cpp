// Bullet's btMultiBody as a forward-dynamics oracle for saltus models.
//
// Bullet's conventions (btMultiBody.h, btMultiBodyLink.h):
//  - each link frame has its origin at the link's centre of mass and the link's inertia is
//    diagonal in it ("local inertia");
//  - rotParentToThis maps coordinates in the parent link frame to coordinates in this link frame
//    at q = 0; a revolute joint turns it into quat(axis, −q) · rotParentToThis;
//  - parentComToThisPivotOffset (e) is in the parent frame, thisPivotToThisComOffset (d) in this
//    frame; the vector from the parent's com to this com, in this frame, is d + R e (+ q axis for
//    a prismatic joint); the joint axis is in this frame;
//  - the base is at its com too; getBaseOmega / getBaseVel are world-frame angular velocity and
//    com velocity; the ABA output is (ω̇ world, com acceleration world, joint q̈).
//
// saltus (dynamics/model.hpp, joint.hpp): body i's frame is its joint frame; X_tree[i] = (E_T,
// r_T) with E_T parent coordinates -> joint coordinates and r_T the joint origin in parent
// coordinates; revolute: body coordinates x_i = R(a, q)ᵀ E_T x_p; prismatic: the origin moves by
// a q (body coordinates).
//
// So, with P_i the principal axes of body i (columns, body coordinates; det +1) and c_i its com
// (body coordinates), Bullet link i's coordinates are P_iᵀ (x_body − c_i) and
//   rotParentToThis = P_iᵀ E_T P_p,   axis = P_iᵀ a,
//   e = P_pᵀ (r_T − c_p),             d = P_iᵀ (0 − (−c_i)) = P_iᵀ c_i
// (the pivot is the saltus joint origin = body origin). A revolute joint then gives
// P_iᵀ R(a, q)ᵀ E_T P_p = R(P_iᵀ a, q)ᵀ P_iᵀ E_T P_p = quat(axis, −q) · rotParentToThis, which is
// exactly Bullet's update; a prismatic joint moves the com by q axis in this frame, also Bullet's.
// For the world (fixed base) P = 1, c = 0. A multi-coordinate base joint (planar; free with
// FreeBase::VirtualLinks) is expanded into its chain of one-coordinate joints (x, z, θ; x, y, z,
// yaw, pitch, roll) through massless links with P = 1, c = 0 at the body origin.
#include "verify/bullet_multibody.hpp"

#include "dynamics/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <LinearMath/btAlignedObjectArray.h>

#ifndef BT_USE_DOUBLE_PRECISION
#error "the Bullet cross-check must be built against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif
static_assert(sizeof(btScalar) == sizeof(double), "Bullet must be the double-precision build");

namespace saltus::verify {

namespace {

using dynamics::BaseType;
using dynamics::JointType;

btVector3 toBt(const Eigen::Vector3d& x) { return btVector3(x.x(), x.y(), x.z()); }
Eigen::Vector3d toEigen(const btVector3& x) { return Eigen::Vector3d(x.x(), x.y(), x.z()); }

// The quaternion q with quatRotate(q, x) = R x.
btQuaternion toBtQuat(const Eigen::Matrix3d& R) {
  // Eigen's quaternion from a rotation matrix is accurate to rounding; Bullet stores (x, y, z, w).
  const Eigen::Quaterniond e(R);
  return btQuaternion(e.x(), e.y(), e.z(), e.w());
}

Eigen::Matrix3d rotX(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }
Eigen::Matrix3d rotY(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }
Eigen::Matrix3d rotZ(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

// The free base's Euler angles η = (ψ, θ, φ), R = Rz(ψ) Ry(θ) Rx(φ): ω_world = E(η) η̇ with the
// columns of E the world directions of the three joint axes (yaw axis z, pitch axis Rz y, roll
// axis Rz Ry x).
Eigen::Matrix3d eulerRateMatrix(const Eigen::Vector3d& eta) {
  Eigen::Matrix3d E;
  const Eigen::Matrix3d Rz = rotZ(eta[0]);
  E.col(0) = Eigen::Vector3d::UnitZ();
  E.col(1) = Rz * Eigen::Vector3d::UnitY();
  E.col(2) = Rz * rotY(eta[1]) * Eigen::Vector3d::UnitX();
  return E;
}

// Ė(η, η̇) η̇: each axis column turns with the angular velocity of the frames before it.
Eigen::Vector3d eulerRateBias(const Eigen::Vector3d& eta, const Eigen::Vector3d& etad) {
  const Eigen::Matrix3d E = eulerRateMatrix(eta);
  const Eigen::Vector3d w_yaw = etad[0] * E.col(0);
  const Eigen::Vector3d w_yaw_pitch = w_yaw + etad[1] * E.col(1);
  return etad[1] * w_yaw.cross(E.col(1)) + etad[2] * w_yaw_pitch.cross(E.col(2));
}

}  // namespace

// The free base's rotation R (root body in world) and world angular velocity ω from (q, v): Euler
// angles and their rates (ω = E(η) η̇), or a quaternion and ω_B (ω = R ω_B).
Eigen::Matrix3d BulletMultiBody::baseRotation(const Eigen::VectorXd& q) const {
  if (quaternion_) return dynamics::quaternionToRotation(q.segment<4>(3).normalized());
  return rotZ(q[3]) * rotY(q[4]) * rotX(q[5]);
}
Eigen::Vector3d BulletMultiBody::baseOmegaWorld(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
  if (quaternion_) return baseRotation(q) * v.segment<3>(3);
  return eulerRateMatrix(q.segment<3>(3)) * v.segment<3>(3);
}

BulletMultiBody::BulletMultiBody(const dynamics::Model<double>& model, FreeBase free_base)
    : model_(model) {
  const int nb = model_.nbodies();
  quaternion_ = model_.base == BaseType::FreeQuaternion;
  if (quaternion_ && free_base == FreeBase::VirtualLinks)
    throw std::invalid_argument("BulletMultiBody: a quaternion base has no chain of one-coordinate joints; "
                                "it is Bullet's floating base (FreeBase::Native)");
  native_free_ = (model_.base == BaseType::Free && free_base == FreeBase::Native) || quaternion_;
  if (native_free_ && (nb < 1 || (model_.joint_type[0] != JointType::Free && model_.joint_type[0] != JointType::FreeQuaternion)))
    throw std::invalid_argument("BulletMultiBody: a free base must be body 0's free joint");

  // Centres of mass and principal frames.
  P_.assign(nb, Eigen::Matrix3d::Identity());
  c_.assign(nb, Eigen::Vector3d::Zero());
  m_.assign(nb, 0.0);
  std::vector<Eigen::Vector3d> moments(nb, Eigen::Vector3d::Zero());
  for (int i = 0; i < nb; ++i) {
    const auto& I = model_.inertia[i];
    m_[i] = I.m;
    if (!(I.m > 0)) {
      if (I.h.norm() > 0 || I.I.norm() > 0)
        throw std::invalid_argument("BulletMultiBody: body '" + model_.body_name[i] +
                                    "' has no mass but a first or second moment");
      continue;  // massless body: frame at the body origin
    }
    c_[i] = I.h / I.m;
    const Eigen::Matrix3d cx = dynamics::skew(c_[i]);
    Eigen::Matrix3d Ic = I.I + I.m * cx * cx;  // Ī = Ic − m c×c× (RBDA 2.63)
    Ic = 0.5 * (Ic + Ic.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(Ic);
    if (eig.info() != Eigen::Success)
      throw std::invalid_argument("BulletMultiBody: eigen-decomposition failed for body '" + model_.body_name[i] + "'");
    P_[i] = eig.eigenvectors();
    if (P_[i].determinant() < 0) P_[i].col(2) = -P_[i].col(2);
    moments[i] = eig.eigenvalues().cwiseMax(0.0);
  }

  // Bullet links: one per one-coordinate joint; a multi-coordinate base joint (planar, or free
  // with FreeBase::VirtualLinks) becomes its chain of one-coordinate joints through massless
  // links at the body origin, the last of which carries the body.
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  last_link_of_body_.assign(nb, -1);
  for (int i = native_free_ ? 1 : 0; i < nb; ++i) {
    const int k = model_.first_coordinate[i];
    const JointType t = model_.joint_type[i];
    if (t == JointType::Revolute || t == JointType::Prismatic) {
      links_.push_back({i, k, t == JointType::Revolute, model_.axis[i]});
    } else {
      if (model_.parent[i] >= 0 || !model_.X_tree[i].E.isIdentity(0) || !model_.X_tree[i].r.isZero(0))
        throw std::invalid_argument("BulletMultiBody: a multi-coordinate joint must join the world to body 0");
      if (t == JointType::Free) {
        const Eigen::Vector3d axes[6] = {ex, ey, ez, ez, ey, ex};
        for (int c = 0; c < 6; ++c) links_.push_back({i, k + c, c >= 3, axes[c]});
      } else {  // Planar: x, z, θ about y
        links_.push_back({i, k, false, ex});
        links_.push_back({i, k + 1, false, ez});
        links_.push_back({i, k + 2, true, ey});
      }
    }
    last_link_of_body_[i] = static_cast<int>(links_.size()) - 1;
  }

  const int n_links = static_cast<int>(links_.size());
  if (native_free_)
    mb_.reset(new btMultiBody(n_links, m_[0], toBt(moments[0]), false, false));
  else
    mb_.reset(new btMultiBody(n_links, 1.0, btVector3(1, 1, 1), true, false));

  for (int k = 0; k < n_links; ++k) {
    const LinkSpec& ls = links_[k];
    const int i = ls.body;
    const bool carries_body = last_link_of_body_[i] == k;
    // The frame of this link: body i's principal frame if it carries the body, else the body
    // origin with world axes (a virtual link of a base joint, whose X_tree is the identity).
    const Eigen::Matrix3d Pi = carries_body ? P_[i] : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d ci = carries_body ? c_[i] : Eigen::Vector3d::Zero();
    const double mi = carries_body ? m_[i] : 0.0;
    const Eigen::Vector3d Ii = carries_body ? moments[i] : Eigen::Vector3d::Zero();
    int bt_parent;
    Eigen::Matrix3d Pp = Eigen::Matrix3d::Identity(), ET = Eigen::Matrix3d::Identity();
    Eigen::Vector3d cp = Eigen::Vector3d::Zero(), rT = Eigen::Vector3d::Zero();
    if (k > 0 && links_[k - 1].body == i) {
      bt_parent = k - 1;  // previous link of the same base joint: frame at the body origin
    } else {
      const int p = model_.parent[i];
      bt_parent = p >= 0 ? last_link_of_body_[p] : -1;
      if (p >= 0) Pp = P_[p], cp = c_[p];
      ET = model_.X_tree[i].E;
      rT = model_.X_tree[i].r;
    }
    const Eigen::Matrix3d rot0 = Pi.transpose() * ET * Pp;
    const Eigen::Vector3d axis = Pi.transpose() * ls.axis;
    const Eigen::Vector3d e = Pp.transpose() * (rT - cp);
    const Eigen::Vector3d d = Pi.transpose() * ci;
    if (ls.revolute)
      mb_->setupRevolute(k, mi, toBt(Ii), bt_parent, toBtQuat(rot0), toBt(axis), toBt(e), toBt(d), true);
    else
      mb_->setupPrismatic(k, mi, toBt(Ii), bt_parent, toBtQuat(rot0), toBt(axis), toBt(e), toBt(d), true);
    mb_->getLink(k).m_jointDamping = 0;
    mb_->getLink(k).m_jointFriction = 0;
  }
  mb_->finalizeMultiDof();
  mb_->setLinearDamping(0);
  mb_->setAngularDamping(0);
  mb_->setUseGyroTerm(true);
  mb_->setMaxCoordinateVelocity(1e30);
  mb_->setMaxAppliedImpulse(1e30);
  mb_->setCanSleep(false);
  mb_->setBasePos(btVector3(0, 0, 0));
  mb_->setWorldToBaseRot(btQuaternion(0, 0, 0, 1));
  mb_->setBaseVel(btVector3(0, 0, 0));
  mb_->setBaseOmega(btVector3(0, 0, 0));
}

BulletMultiBody::~BulletMultiBody() = default;

int BulletMultiBody::numLinks() const { return mb_->getNumLinks(); }

void BulletMultiBody::setState(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  const int n = model_.nv(), nq = model_.nq();
  if (q.size() != nq || v.size() != n)
    throw std::invalid_argument("BulletMultiBody: q and v must have " + std::to_string(nq) + " and " +
                                std::to_string(n) + " entries");
  for (int k = 0; k < static_cast<int>(links_.size()); ++k) {
    const int j = links_[k].coordinate;
    mb_->setJointPos(k, q[model_.positionOf(j)]);
    mb_->setJointVel(k, v[j]);
  }
  if (!native_free_) return;

  // Free base: pose and twist of the root body (saltus body 0, coordinates 0..5).
  const int r = 0;
  const Eigen::Vector3d p = q.head<3>(), pd = v.head<3>();
  const Eigen::Matrix3d R = baseRotation(q);  // root body in world
  const Eigen::Vector3d w = baseOmegaWorld(q, v);
  const Eigen::Vector3d c_world = R * c_[r];  // com relative to the root origin, world axes
  mb_->setBasePos(toBt(p + c_world));
  mb_->setWorldToBaseRot(toBtQuat((R * P_[r]).transpose()));
  mb_->setBaseOmega(toBt(w));
  mb_->setBaseVel(toBt(pd + w.cross(c_world)));
}

void BulletMultiBody::getState(Eigen::VectorXd& q, Eigen::VectorXd& v, const Eigen::VectorXd* q_hint) const {
  const int n = model_.nv(), nq = model_.nq();
  q.resize(nq);
  v.resize(n);
  for (int k = 0; k < static_cast<int>(links_.size()); ++k) {
    const int j = links_[k].coordinate;
    q[model_.positionOf(j)] = mb_->getJointPos(k);
    v[j] = mb_->getJointVel(k);
  }
  if (!native_free_) return;
  const int r = 0;
  // worldToBaseRot = (R P)ᵀ, so R = worldToBaseRotᵀ Pᵀ.
  const btQuaternion qb = mb_->getWorldToBaseRot();
  const Eigen::Matrix3d RP_T = Eigen::Quaterniond(qb.w(), qb.x(), qb.y(), qb.z()).toRotationMatrix();
  const Eigen::Matrix3d R = RP_T.transpose() * P_[r].transpose();
  if (quaternion_) {  // the sign of the hint's quaternion, so that a trajectory's quaternion is continuous
    dynamics::QuaternionWxyz Q = dynamics::rotationToQuaternion(R);
    if (q_hint && q_hint->size() == nq && Q.dot(q_hint->segment<4>(3)) < 0) Q = -Q;
    const Eigen::Vector3d c_world = R * c_[r];
    const Eigen::Vector3d w = toEigen(mb_->getBaseOmega());
    q.head<3>() = toEigen(mb_->getBasePos()) - c_world;
    q.segment<4>(3) = Q;
    v.head<3>() = toEigen(mb_->getBaseVel()) - w.cross(c_world);
    v.segment<3>(3) = R.transpose() * w;
    return;
  }
  // R = Rz(ψ) Ry(θ) Rx(φ): R(2,0) = −sin θ, R(1,0)/R(0,0) = tan ψ, R(2,1)/R(2,2) = tan φ.
  Eigen::Vector3d eta(std::atan2(R(1, 0), R(0, 0)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
                      std::atan2(R(2, 1), R(2, 2)));
  if (q_hint && q_hint->size() == n)
    for (int a : {0, 2}) {
      const double ref = (*q_hint)[3 + a];
      eta[a] += 2 * std::numbers::pi * std::round((ref - eta[a]) / (2 * std::numbers::pi));
    }
  const Eigen::Vector3d c_world = R * c_[r];
  const Eigen::Vector3d w = toEigen(mb_->getBaseOmega());
  q.head<3>() = toEigen(mb_->getBasePos()) - c_world;
  q.segment<3>(3) = eta;
  v.head<3>() = toEigen(mb_->getBaseVel()) - w.cross(c_world);
  v.segment<3>(3) = eulerRateMatrix(eta).lu().solve(w);
}

void BulletMultiBody::setGeneralisedForces(const Eigen::VectorXd& q, const Eigen::VectorXd& tau) {
  applyForces(q, tau, false);
}

void BulletMultiBody::applyForces(const Eigen::VectorXd& q, const Eigen::VectorXd& tau, bool gravity) {
  const int n = model_.nv(), nq = model_.nq();
  if (q.size() != nq || tau.size() != n)
    throw std::invalid_argument("BulletMultiBody: q and tau must have " + std::to_string(nq) + " and " +
                                std::to_string(n) + " entries");
  mb_->clearForcesAndTorques();
  mb_->clearConstraintForces();
  const Eigen::Vector3d g = model_.gravity;
  for (int k = 0; k < static_cast<int>(links_.size()); ++k) {
    const int j = links_[k].coordinate, i = links_[k].body;
    mb_->addJointTorque(k, tau[j]);
    if (gravity && last_link_of_body_[i] == k && m_[i] > 0) mb_->addLinkForce(k, toBt(m_[i] * g));  // world force at the com
  }
  if (!native_free_) return;
  const int r = 0;
  const Eigen::Matrix3d R = baseRotation(q);
  const Eigen::Vector3d c_world = R * c_[r];
  // Generalised forces of the base: by virtual power, τ_xyz·ṗ + τ_η·η̇ = f·ṗ + n_O·ω, so the
  // force is f = τ_xyz and the moment about the root origin is n_O = E⁻ᵀ τ_η (Euler angles) or
  // R τ_ω (a quaternion base, whose τ_ω is dual to ω_B); Bullet applies base forces at the com, so
  // the torque about the com is n_O − (R c) × f.
  const Eigen::Vector3d f = tau.head<3>();
  const Eigen::Vector3d n_O = quaternion_ ? Eigen::Vector3d(R * tau.segment<3>(3))
                                          : Eigen::Vector3d(eulerRateMatrix(q.segment<3>(3)).transpose().lu().solve(
                                                Eigen::Vector3d(tau.segment<3>(3))));
  mb_->addBaseForce(toBt(f + (gravity ? Eigen::Vector3d(m_[r] * g) : Eigen::Vector3d::Zero())));
  mb_->addBaseTorque(toBt(n_O - c_world.cross(f)));
}

int BulletMultiBody::linkOfCoordinate(int coordinate) const {
  for (int k = 0; k < static_cast<int>(links_.size()); ++k)
    if (links_[k].coordinate == coordinate) return k;
  return -1;
}

Eigen::Vector3d BulletMultiBody::bodyPointInLinkFrame(int body, const Eigen::Vector3d& p_B) const {
  return P_.at(body).transpose() * (p_B - c_.at(body));
}

Eigen::VectorXd BulletMultiBody::forwardDynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                                 const Eigen::VectorXd& tau) {
  setState(q, v);
  applyForces(q, tau, true);
  btAlignedObjectArray<btScalar> scratch_r;
  btAlignedObjectArray<btVector3> scratch_v;
  btAlignedObjectArray<btMatrix3x3> scratch_m;
  // dt = 0: accelerations only, velocities untouched. The output (6 base entries: ω̇ in world,
  // com acceleration in world; then one q̈ per joint dof) is stored by Bullet in scratch_r from
  // index getNumDofs() on (btMultiBody.cpp: "output" = &scratch_r[m_dofCount]).
  mb_->computeAccelerationsArticulatedBodyAlgorithmMultiDof(0, scratch_r, scratch_v, scratch_m, false, false, false);
  const int ndof = mb_->getNumDofs();
  if (scratch_r.size() < 2 * ndof + 6) throw std::logic_error("BulletMultiBody: unexpected Bullet scratch layout");
  const btScalar* out = &scratch_r[ndof];

  const int n = model_.nv();
  if (q.size() != model_.nq() || v.size() != n || tau.size() != n)
    throw std::invalid_argument("BulletMultiBody::forwardDynamics: q, v, tau of the wrong sizes");
  Eigen::VectorXd qdd(n);
  for (int k = 0; k < static_cast<int>(links_.size()); ++k) qdd[links_[k].coordinate] = out[6 + k];
  if (native_free_) {
    const int r = 0;
    const Eigen::Matrix3d R = baseRotation(q);
    const Eigen::Vector3d w = baseOmegaWorld(q, v);
    const Eigen::Vector3d c_world = R * c_[r];
    const Eigen::Vector3d wd(out[0], out[1], out[2]);
    const Eigen::Vector3d a_com(out[3], out[4], out[5]);
    // Root origin O = com − R c: p̈ = a_com − ω̇ × Rc − ω × (ω × Rc).
    qdd.head<3>() = a_com - wd.cross(c_world) - w.cross(w.cross(c_world));
    if (quaternion_) {
      qdd.segment<3>(3) = R.transpose() * wd;  // ω_B = Rᵀ ω: ω̇_B = Rᵀ ω̇ (the ω × ω term vanishes)
    } else {
      const Eigen::Vector3d eta = q.segment<3>(3), etad = v.segment<3>(3);
      qdd.segment<3>(3) = eulerRateMatrix(eta).lu().solve(wd - eulerRateBias(eta, etad));  // ω̇ = E η̈ + Ė η̇
    }
  }
  return qdd;
}

Eigen::Vector3d BulletMultiBody::comPosition(int body) const {
  if (body < 0 || body >= model_.nbodies()) throw std::out_of_range("BulletMultiBody::comPosition: no such body");
  if (native_free_ && body == 0) return toEigen(mb_->getBasePos());
  return toEigen(mb_->localPosToWorld(last_link_of_body_[body], btVector3(0, 0, 0)));
}

}  // namespace saltus::verify
