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
// For the world (fixed base) P = 1, c = 0.
#include "verify/bullet_multibody.hpp"

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

BulletMultiBody::BulletMultiBody(const dynamics::Model<double>& model, FreeBase free_base)
    : model_(model) {
  const int n = model_.nv();
  native_free_ = model_.base == BaseType::Free && free_base == FreeBase::Native;
  if (native_free_) {
    if (model_.n_base != 6 || n < 6 || model_.parent[5] != 4)
      throw std::invalid_argument("BulletMultiBody: a free base must be the six-body virtual chain");
    for (int i = 6; i < n; ++i)
      if (model_.parent[i] < 5)
        throw std::invalid_argument("BulletMultiBody: body '" + model_.body_name[i] +
                                    "' hangs from the virtual base chain");
    first_link_body_ = 6;
  }

  // Centres of mass and principal frames.
  P_.assign(n, Eigen::Matrix3d::Identity());
  c_.assign(n, Eigen::Vector3d::Zero());
  m_.assign(n, 0.0);
  std::vector<Eigen::Vector3d> moments(n, Eigen::Vector3d::Zero());
  for (int i = 0; i < n; ++i) {
    const auto& I = model_.inertia[i];
    m_[i] = I.m;
    if (!(I.m > 0)) {
      if (I.h.norm() > 0 || I.I.norm() > 0)
        throw std::invalid_argument("BulletMultiBody: body '" + model_.body_name[i] +
                                    "' has no mass but a first or second moment");
      continue;  // massless (virtual) body: frame at the body origin
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

  const int root = first_link_body_ - 1;  // saltus body of Bullet's base (native free base only)
  const int n_links = n - first_link_body_;
  if (native_free_)
    mb_.reset(new btMultiBody(n_links, m_[root], toBt(moments[root]), false, false));
  else
    mb_.reset(new btMultiBody(n_links, 1.0, btVector3(1, 1, 1), true, false));

  for (int i = first_link_body_; i < n; ++i) {
    const int k = i - first_link_body_;
    const int p = model_.parent[i];
    const int bt_parent = p < first_link_body_ ? -1 : p - first_link_body_;
    const Eigen::Matrix3d Pp = p >= 0 ? P_[p] : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d cp = p >= 0 ? c_[p] : Eigen::Vector3d::Zero();
    const auto& XT = model_.X_tree[i];
    const Eigen::Matrix3d rot0 = P_[i].transpose() * XT.E * Pp;
    const Eigen::Vector3d axis = P_[i].transpose() * model_.axis[i];
    const Eigen::Vector3d e = Pp.transpose() * (XT.r - cp);
    const Eigen::Vector3d d = P_[i].transpose() * c_[i];
    if (model_.joint_type[i] == JointType::Revolute)
      mb_->setupRevolute(k, m_[i], toBt(moments[i]), bt_parent, toBtQuat(rot0), toBt(axis), toBt(e), toBt(d), true);
    else
      mb_->setupPrismatic(k, m_[i], toBt(moments[i]), bt_parent, toBtQuat(rot0), toBt(axis), toBt(e), toBt(d), true);
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

void BulletMultiBody::setState(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& tau) {
  const int n = model_.nv();
  if (q.size() != n || v.size() != n || tau.size() != n)
    throw std::invalid_argument("BulletMultiBody: q, v and tau must have " + std::to_string(n) + " entries");
  mb_->clearForcesAndTorques();
  mb_->clearConstraintForces();
  const Eigen::Vector3d g = model_.gravity;
  for (int i = first_link_body_; i < n; ++i) {
    const int k = i - first_link_body_;
    mb_->setJointPos(k, q[i]);
    mb_->setJointVel(k, v[i]);
    mb_->addJointTorque(k, tau[i]);
    if (m_[i] > 0) mb_->addLinkForce(k, toBt(m_[i] * g));  // world force at the com
  }
  if (!native_free_) return;

  // Free base: pose, twist and wrench of the root body (saltus body 5) from the Euler chain.
  const int r = 5;
  const Eigen::Vector3d p = q.head<3>(), pd = v.head<3>();
  const Eigen::Vector3d eta = q.segment<3>(3), etad = v.segment<3>(3);
  const Eigen::Matrix3d R = rotZ(eta[0]) * rotY(eta[1]) * rotX(eta[2]);  // root body in world
  const Eigen::Matrix3d E = eulerRateMatrix(eta);
  const Eigen::Vector3d w = E * etad;
  const Eigen::Vector3d c_world = R * c_[r];  // com relative to the root origin, world axes
  mb_->setBasePos(toBt(p + c_world));
  mb_->setWorldToBaseRot(toBtQuat((R * P_[r]).transpose()));
  mb_->setBaseOmega(toBt(w));
  mb_->setBaseVel(toBt(pd + w.cross(c_world)));
  // Generalised forces of the base: by virtual power, τ_xyz·ṗ + τ_η·η̇ = f·ṗ + n_O·ω, so the
  // force is f = τ_xyz and the moment about the root origin is n_O = E⁻ᵀ τ_η; Bullet applies
  // base forces at the com, so the torque about the com is n_O − (R c) × f.
  const Eigen::Vector3d f = tau.head<3>();
  const Eigen::Vector3d n_O = E.transpose().lu().solve(Eigen::Vector3d(tau.segment<3>(3)));
  mb_->addBaseForce(toBt(f + m_[r] * g));
  mb_->addBaseTorque(toBt(n_O - c_world.cross(f)));
}

Eigen::VectorXd BulletMultiBody::forwardDynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                                 const Eigen::VectorXd& tau) {
  setState(q, v, tau);
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
  Eigen::VectorXd qdd(n);
  for (int i = first_link_body_; i < n; ++i) qdd[i] = out[6 + (i - first_link_body_)];
  if (native_free_) {
    const int r = 5;
    const Eigen::Vector3d eta = q.segment<3>(3), etad = v.segment<3>(3);
    const Eigen::Matrix3d R = rotZ(eta[0]) * rotY(eta[1]) * rotX(eta[2]);
    const Eigen::Matrix3d E = eulerRateMatrix(eta);
    const Eigen::Vector3d w = E * etad;
    const Eigen::Vector3d c_world = R * c_[r];
    const Eigen::Vector3d wd(out[0], out[1], out[2]);
    const Eigen::Vector3d a_com(out[3], out[4], out[5]);
    // Root origin O = com − R c: p̈ = a_com − ω̇ × Rc − ω × (ω × Rc).
    qdd.head<3>() = a_com - wd.cross(c_world) - w.cross(w.cross(c_world));
    // ω̇ = E η̈ + Ė η̇.
    qdd.segment<3>(3) = E.lu().solve(wd - eulerRateBias(eta, etad));
  }
  return qdd;
}

Eigen::Vector3d BulletMultiBody::comPosition(int body) const {
  if (body < 0 || body >= model_.nv()) throw std::out_of_range("BulletMultiBody::comPosition: no such body");
  if (native_free_ && body == 5) return toEigen(mb_->getBasePos());
  if (body < first_link_body_)
    throw std::out_of_range("BulletMultiBody::comPosition: body '" + model_.body_name[body] +
                            "' is part of Bullet's base");
  return toEigen(mb_->localPosToWorld(body - first_link_body_, btVector3(0, 0, 0)));
}

}  // namespace saltus::verify
