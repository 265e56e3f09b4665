// Bullet time-stepping world for a saltus Scene; the mapping and the settings are described in
// bullet_world.hpp.
//
// One step (btDiscreteDynamicsWorld::stepSimulation with one fixed sub-step of dt; Bullet 3.24's
// btMultiBodyDynamicsWorld): collision detection at the current positions (sphere–plane
// manifolds), the free articulated-body step v* = v + h M⁻¹(τ − C v − g), the contact and limit
// rows solved for impulses at velocity level (MLCP or sequential impulse; restitution target
// −e v_n for approach speeds above the threshold), then q⁺ = q + h v⁺ (semi-implicit Euler): the
// structure of the saltus stepper with θ = 1, but with Bullet's contact generation, its friction
// rows (two directions from btPlaneSpace1 of the normal) and without post-stabilisation.
#include "verify/bullet_world.hpp"

#include "dynamics/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodyMLCPConstraintSolver.h>
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btLemkeSolver.h>

#include "contact/kinematics.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::verify {

namespace {

btVector3 toBt(const Eigen::Vector3d& x) { return btVector3(x.x(), x.y(), x.z()); }
Eigen::Vector3d toEigen(const btVector3& x) { return Eigen::Vector3d(x.x(), x.y(), x.z()); }

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

constexpr double kNoLimit = 1e30;

}  // namespace

const char* bulletSolverName(BulletSolver solver) {
  switch (solver) {
    case BulletSolver::MlcpDantzig: return "dantzig";
    case BulletSolver::MlcpLemke: return "lemke";
    case BulletSolver::SequentialImpulse: return "si";
  }
  return "?";
}

BulletSolver parseBulletSolver(const std::string& name) {
  if (name == "dantzig" || name == "mlcp-dantzig") return BulletSolver::MlcpDantzig;
  if (name == "lemke" || name == "mlcp-lemke") return BulletSolver::MlcpLemke;
  if (name == "si" || name == "sequential-impulse") return BulletSolver::SequentialImpulse;
  throw std::invalid_argument("expected a Bullet solver: dantzig, lemke or si (sequential impulse), got '" + name + "'");
}

BulletWorldOptions BulletWorldOptions::bulletDefaults(double dt, BulletSolver solver) {
  BulletWorldOptions o;
  o.dt = dt;
  o.solver = solver;
  const btContactSolverInfo info;
  o.erp2 = info.m_erp2;
  o.restitution_threshold = info.m_restitutionVelocityThreshold;
  o.contact_processing_threshold = BT_LARGE_FLOAT;
  o.iterations = info.m_numIterations;
  o.global_cfm = info.m_globalCfm;
  return o;
}

// Lets a pair collider meet its partner alone (the sphere its box, the box its sphere); leaves
// the rest to the collision groups. A pair collider carries its contact's index as its user
// index (btCollisionObject's default, −1, marks every other object). Also holds the scratch
// arrays of placing the pair colliders after a step (no allocation per step).
class BulletWorld::PairFilter final : public btOverlapFilterCallback {
 public:
  bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
    const int pa = pairOf(a), pb = pairOf(b);
    if (pa >= 0 || pb >= 0) return pa == pb;
    return (a->m_collisionFilterGroup & b->m_collisionFilterMask) != 0 &&
           (b->m_collisionFilterGroup & a->m_collisionFilterMask) != 0;
  }
  static int pairOf(const btCollisionObject* object) { return object->getUserIndex(); }
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;

 private:
  static int pairOf(const btBroadphaseProxy* proxy) {
    return pairOf(static_cast<const btCollisionObject*>(proxy->m_clientObject));
  }
};

BulletWorld::BulletWorld(const scene::Scene& scene, BulletWorldOptions options)
    : scene_(scene), pairs_(contact::contactPairs(scene)), options_(options), data_(scene.model) {
  if (!(options_.dt > 0) || !std::isfinite(options_.dt)) throw std::invalid_argument("BulletWorld: dt must be positive");
  if (!(options_.contact_radius > 0)) throw std::invalid_argument("BulletWorld: contact_radius must be positive");
  const dynamics::Model<double>& model = scene_.model;
  const int n = model.nv();
  body_ = std::make_unique<BulletMultiBody>(model);
  btMultiBody* mb = body_->multiBody();

  config_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  switch (options_.solver) {
    case BulletSolver::MlcpDantzig:
      mlcp_ = std::make_unique<btDantzigSolver>();
      break;
    case BulletSolver::MlcpLemke:
      mlcp_ = std::make_unique<btLemkeSolver>();
      break;
    case BulletSolver::SequentialImpulse:
      break;
  }
  if (mlcp_) {
    auto mlcp_solver = std::make_unique<btMultiBodyMLCPConstraintSolver>(mlcp_.get());
    mlcp_solver_ = mlcp_solver.get();
    solver_ = std::move(mlcp_solver);
  } else
    solver_ = std::make_unique<btMultiBodyConstraintSolver>();
  world_ = std::make_unique<btMultiBodyDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(), config_.get());
  world_->setGravity(toBt(model.gravity));
  // Islands stay split (Bullet's default): with setSplitIslands(false), Bullet 3.24's
  // btMultiBodyInplaceSolverIslandCallback::processIsland(−1) passes the number of typed
  // constraints as the number of multibody constraints, so joint limits would be dropped. The
  // contact colliders are the links' own (m_collider), which puts the whole multibody in one island.

  btContactSolverInfo& info = world_->getSolverInfo();
  info.m_erp2 = options_.erp2;
  info.m_erp = options_.erp2;
  info.m_restitutionVelocityThreshold = options_.restitution_threshold;
  info.m_numIterations = options_.iterations;
  info.m_globalCfm = options_.global_cfm;
  info.m_splitImpulse = false;  // not implemented for btMultiBody contacts in 3.24 anyway
  info.m_linearSlop = 0;
  info.m_leastSquaresResidualThreshold = 0;
  // Two friction directions (see the header: Bullet picks them, the first is ±y for a horizontal
  // surface, so one direction would leave x frictionless).
  info.m_solverMode = SOLVER_USE_2_FRICTION_DIRECTIONS;

  world_->addMultiBody(mb);
  mb->setCanSleep(false);
  mb->setHasSelfCollision(false);

  // Surfaces: planes moved back by the sphere radius.
  const double r = options_.contact_radius;
  surface_moves_.assign(scene_.surfaces.size(), false);
  for (std::size_t s = 0; s < scene_.surfaces.size(); ++s) {
    const scene::Surface& surface = scene_.surfaces[s];
    const double offset = surface.normal.dot(surface.point) - r;
    shapes_.push_back(std::make_unique<btStaticPlaneShape>(toBt(surface.normal), offset));
    btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, shapes_.back().get());
    ci.m_friction = 1;
    ci.m_restitution = 1;
    ci.m_rollingFriction = 0;
    ci.m_spinningFriction = 0;
    surfaces_.push_back(std::make_unique<btRigidBody>(ci));
    btRigidBody* body = surfaces_.back().get();
    for (const auto& step : surface.velocity_schedule)
      if (step.velocity.squaredNorm() > 0) surface_moves_[s] = true;
    if (surface_moves_[s]) {
      body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
      body->setActivationState(DISABLE_DEACTIVATION);
    }
    body->setContactProcessingThreshold(options_.contact_processing_threshold);
    world_->addRigidBody(body);
    if (surface.velocity_schedule.size() > 1)
      approximations_.push_back("surface '" + surface.name +
                                "': the belt speed is the schedule's value at the end of each step (as in saltus); a "
                                "kinematic plane whose velocity Bullet takes from the pose change over the step");
  }

  // Contact spheres: one compound collider per link that has contact points, the link's own
  // m_collider (Bullet keeps its pose at the link frame), one sphere child per point.
  shapes_.push_back(std::make_unique<btSphereShape>(r));
  btCollisionShape* sphere = shapes_.back().get();
  double max_friction = 0;
  const auto colliderOfLink = [&](int link) -> int {
    for (std::size_t i = 0; i < colliders_.size(); ++i)
      if (collider_link_[i] == link && PairFilter::pairOf(colliders_[i].get()) < 0) return static_cast<int>(i);
    auto compound = std::make_unique<btCompoundShape>();
    colliders_.push_back(std::make_unique<btMultiBodyLinkCollider>(mb, link));
    btMultiBodyLinkCollider* col = colliders_.back().get();
    col->setCollisionShape(compound.get());
    shapes_.push_back(std::move(compound));
    col->setRollingFriction(0);
    col->setSpinningFriction(0);
    col->setContactProcessingThreshold(options_.contact_processing_threshold);
    col->setActivationState(DISABLE_DEACTIVATION);
    if (link < 0)
      mb->setBaseCollider(col);
    else
      mb->getLink(link).m_collider = col;
    collider_link_.push_back(link);
    return static_cast<int>(colliders_.size()) - 1;
  };
  for (std::size_t c = 0; c < scene_.contacts.size(); ++c) {
    const scene::Contact& contact = scene_.contacts[c];
    max_friction = std::max(max_friction, contact.friction);
    if (contact.directions == 2) planar_cone_ = true;
    if (contact.surface < 0) {  // on a body's plane: colliders of its own (addBodyPlanePair)
      contact_child_.push_back({-1, -1});
      continue;
    }
    const int link = body_->linkOfBody(contact.body);
    const bool first_on_link =
        std::find(collider_link_.begin(), collider_link_.end(), link) == collider_link_.end();
    const int ci = colliderOfLink(link);
    btMultiBodyLinkCollider* col = colliders_[ci].get();
    auto* compound = static_cast<btCompoundShape*>(col->getCollisionShape());
    btTransform local;
    local.setIdentity();
    local.setOrigin(toBt(body_->bodyPointInLinkFrame(contact.body, contact.p_B)));
    contact_child_.push_back({ci, compound->getNumChildShapes()});
    compound->addChildShape(local, sphere);
    if (first_on_link) {
      col->setFriction(contact.friction);
      col->setRestitution(contact.restitution);
    } else if (col->getFriction() != contact.friction || col->getRestitution() != contact.restitution) {
      approximations_.push_back("contact '" + contact.name + "': friction and restitution of the first contact on its link (" +
                                fmt(col->getFriction()) + ", " + fmt(col->getRestitution()) +
                                ") are used: Bullet has one material per link collider");
    }
  }
  for (auto& col : colliders_)
    world_->addCollisionObject(col.get(), btBroadphaseProxy::DefaultFilter,
                               btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::DefaultFilter);
  if (std::any_of(scene_.contacts.begin(), scene_.contacts.end(), [](const scene::Contact& c) { return c.surface < 0; })) {
    // The pair colliders belong to the one multibody: Bullet only tests its colliders against each
    // other with self-collision on; the filter, installed before they are added (the pair cache
    // keeps the pairs it accepted), lets each pair's sphere meet its box alone.
    mb->setHasSelfCollision(true);
    filter_ = std::make_unique<PairFilter>();
    world_->getPairCache()->setOverlapFilterCallback(filter_.get());
    for (std::size_t c = 0; c < scene_.contacts.size(); ++c)
      if (scene_.contacts[c].surface < 0) addBodyPlanePair(static_cast<int>(c), sphere);
    syncPairColliders();
    approximations_.push_back(
        "a plane on a body is the top face of a box on that body's link, moved back by the sphere radius, with the "
        "plane's extent; a point passing its edge meets the edge rounded by the radius (" + fmt(r) + " m)");
  }
  if (!scene_.contacts.empty())
    approximations_.push_back("contact points are spheres of radius " + fmt(r) +
                              " m centred at the point, against planes moved back by the radius: the gap is exact, "
                              "the force acts " + fmt(r) + " m below the point");
  if (planar_cone_)
    approximations_.push_back("friction: Bullet's two directions from btPlaneSpace1(normal) (a circular cone with "
                              "sequential impulse, a box with the MLCP solvers) instead of the scene's planar cone (k = "
                              "2); rows with a zero Jacobian are regularised by global_cfm " + fmt(options_.global_cfm));
  for (const scene::Contact& contact : scene_.contacts)
    if (contact.directions > 2) {
      approximations_.push_back("friction: Bullet's cone instead of the scene's polyhedral cone with " +
                                std::to_string(contact.directions) + " directions");
      break;
    }
  if (max_friction > 10)
    approximations_.push_back("friction above 10 is clamped to 10 by Bullet (largest here " + fmt(max_friction) + ")");

  // Joint-limit stops, one constraint per limited coordinate.
  std::vector<int> coords;
  for (const scene::LimitStop& stop : scene_.limits)
    if (std::find(coords.begin(), coords.end(), stop.coordinate) == coords.end()) coords.push_back(stop.coordinate);
  for (int k : coords) {
    const int link = body_->linkOfCoordinate(k);
    if (link < 0)
      throw std::invalid_argument("BulletWorld: scene " + scene_.name + ": a limit stop on coordinate '" +
                                  model.coordinate_name[k] + "' of a free base cannot be a Bullet joint limit");
    double lower = -kNoLimit, upper = kNoLimit;
    for (const scene::LimitStop& stop : scene_.limits) {
      if (stop.coordinate != k) continue;
      (stop.upper ? upper : lower) = stop.limit;
      if (stop.restitution > 0)
        approximations_.push_back("limit stop '" + stop.name + "': restitution " + fmt(stop.restitution) +
                                  " ignored (Bullet's joint limits are inelastic)");
    }
    limits_.push_back(std::make_unique<btMultiBodyJointLimitConstraint>(mb, link, lower, upper));
    limits_.back()->setMaxAppliedImpulse(kNoLimit);
    world_->addMultiBodyConstraint(limits_.back().get());
    limit_coordinate_.push_back(k);
  }
  // Bullet solves a joint-limit constraint in the simulation island of its link's collider, or
  // of its parent link's (btMultiBodyJointLimitConstraint::getIslandIdA/B); a limit on a link
  // where neither has a collider is in no island and is never solved, so it is silently ignored
  // (a chain with one collider passed its other stops by radians). Such a link gets a collider
  // that collides with nothing (collision mask 0), which puts it in the multibody's island.
  for (int k : limit_coordinate_) {
    const int link = body_->linkOfCoordinate(k);
    const int parent = mb->getLink(link).m_parent;
    const bool parent_collider = parent < 0 ? mb->getBaseCollider() != nullptr : mb->getLink(parent).m_collider != nullptr;
    if (mb->getLink(link).m_collider || parent_collider) continue;
    const int ci = colliderOfLink(link);
    auto* compound = static_cast<btCompoundShape*>(colliders_[ci]->getCollisionShape());
    btTransform local;
    local.setIdentity();
    compound->addChildShape(local, sphere);
    world_->addCollisionObject(colliders_[ci].get(), btBroadphaseProxy::DefaultFilter, 0);
  }

  reports_.assign(scene_.contacts.size(), BulletContactReport{});
  q_ = scene_.q0.size() == model.nq() ? scene_.q0 : dynamics::neutralConfiguration(model);
  v_ = scene_.v0.size() == n ? scene_.v0 : Eigen::VectorXd::Zero(n);
  reset(q_, v_, 0);
}

BulletWorld::~BulletWorld() {
  if (!world_) return;
  for (auto& c : limits_) world_->removeMultiBodyConstraint(c.get());
  for (auto& c : colliders_) world_->removeCollisionObject(c.get());
  for (auto& s : surfaces_) world_->removeRigidBody(s.get());
  world_->removeMultiBody(body_->multiBody());
  world_.reset();
}

void BulletWorld::reset(const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t) {
  const int n = scene_.model.nv(), nq = scene_.model.nq();
  if (q.size() != nq || v.size() != n)
    throw std::invalid_argument("BulletWorld::reset: q and v must have " + std::to_string(nq) + " and " +
                                std::to_string(n) + " entries");
  q_ = q;
  v_ = v;
  t_ = t;
  body_->setState(q_, v_);
  // Bullet's cached link transforms (used by the contact Jacobians) for the new pose.
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;
  body_->multiBody()->forwardKinematics(world_to_local, local_origin);
  body_->multiBody()->updateCollisionObjectWorldTransforms(world_to_local, local_origin);
  syncPairColliders();
  for (auto& c : colliders_) c->setInterpolationWorldTransform(c->getWorldTransform());
  // Forget the manifolds of the old state (their cached impulses and points).
  for (auto& c : colliders_) {
    world_->getBroadphase()->getOverlappingPairCache()->cleanProxyFromPairs(c->getBroadphaseHandle(), dispatcher_.get());
  }
  for (BulletContactReport& r : reports_) r = BulletContactReport{};
  stats_ = BulletWorldStats{};
  if (mlcp_solver_) mlcp_solver_->setNumFallbacks(0);
  measure();
  stats_.max_penetration = 0;
}

// A belt's plane keeps its pose; its interpolation transform is put h·v_surface(t + h) behind so
// that btRigidBody::saveKinematicState reports the velocity v_surface(t + h) for the step.
void BulletWorld::placeBelts(double t_next) {
  for (std::size_t s = 0; s < surfaces_.size(); ++s) {
    if (!surface_moves_[s]) continue;
    const Eigen::Vector3d vel = scene_.surfaces[s].velocity(t_next);
    btTransform now;
    now.setIdentity();
    btTransform before = now;
    before.setOrigin(toBt(-options_.dt * vel));
    surfaces_[s]->setWorldTransform(now);
    surfaces_[s]->setInterpolationWorldTransform(before);
  }
}

void BulletWorld::step() {
  if (scene_.tau.size() == scene_.model.nv())
    step(scene_.tau);
  else
    step(Eigen::VectorXd::Zero(scene_.model.nv()));
}

void BulletWorld::step(const Eigen::VectorXd& tau) {
  const double h = options_.dt;
  body_->setGeneralisedForces(q_, tau);
  placeBelts(t_ + h);
  world_->stepSimulation(h, 0, h);
  syncPairColliders();
  t_ += h;
  ++stats_.steps;
  const Eigen::VectorXd q_prev = q_;
  body_->getState(q_, v_, &q_prev);
  measure();
  if (mlcp_solver_) stats_.mlcp_fallbacks = mlcp_solver_->getNumFallbacks();
}

// Gaps and velocities from saltus' kinematics of (q, v); impulses from Bullet's manifold points.
void BulletWorld::measure() {
  dynamics::forwardKinematics(scene_.model, data_, q_, v_);
  stats_.max_penetration =
      std::max(stats_.max_penetration, measureContactKinematics(scene_, pairs_, data_, q_.data(), t_, reports_));
  // The stops Bullet enforces (limit_coordinate_): their penetration.
  for (std::size_t l = scene_.contacts.size(); l < pairs_.size(); ++l)
    if (std::find(limit_coordinate_.begin(), limit_coordinate_.end(), pairs_[l].coordinate) != limit_coordinate_.end())
      stats_.max_penetration = std::max(stats_.max_penetration, -contact::gap(pairs_[l], data_, q_.data()));

  const int nm = dispatcher_->getNumManifolds();
  for (int m = 0; m < nm; ++m) {
    btPersistentManifold* manifold = dispatcher_->getManifoldByIndexInternal(m);
    for (std::size_t ci = 0; ci < colliders_.size(); ++ci) {
      const btCollisionObject* col = colliders_[ci].get();
      const bool is_a = manifold->getBody0() == col, is_b = manifold->getBody1() == col;
      if (!is_a && !is_b) continue;
      for (int p = 0; p < manifold->getNumContacts(); ++p) {
        const btManifoldPoint& cp = manifold->getContactPoint(p);
        if (cp.getDistance() > manifold->getContactProcessingThreshold()) continue;
        const int child = is_a ? cp.m_index0 : cp.m_index1;  // the sphere within the link's compound
        for (std::size_t c = 0; c < contact_child_.size(); ++c) {
          if (contact_child_[c].first != static_cast<int>(ci) || contact_child_[c].second != child) continue;
          const contact::PlaneFrame<double> f = contact::planeFrame(pairs_[c], data_);
          BulletContactReport& r = reports_[c];
          r.active = true;
          // The normal impulse acts on A along m_normalWorldOnB and on B against it; the friction
          // rows act on A along the lateral directions.
          const double sign = is_a ? 1.0 : -1.0;
          const Eigen::Vector3d impulse =
              sign * (cp.m_appliedImpulse * toEigen(cp.m_normalWorldOnB) +
                      cp.m_appliedImpulseLateral1 * toEigen(cp.m_lateralFrictionDir1) +
                      cp.m_appliedImpulseLateral2 * toEigen(cp.m_lateralFrictionDir2));
          r.pn += f.normal.dot(impulse);
          r.pt1 += f.tangents.col(0).dot(impulse);
          r.pt2 += f.tangents.col(1).dot(impulse);
        }
      }
    }
  }
}

// A contact on a plane fixed in body B: a collider on A's link holding the contact's sphere, and
// one on B's link holding a box whose top face is the plane moved back by the sphere radius (so
// the sphere–box distance is the gap), as large as the plane's extent. Neither is its link's
// m_collider, which Bullet moves with the link: syncPairColliders places them after every step.
void BulletWorld::addBodyPlanePair(int c, btCollisionShape* sphere) {
  const scene::Contact& contact = scene_.contacts[c];
  const contact::ContactPair& pair = pairs_[c];
  btMultiBody* mb = body_->multiBody();
  const double r = options_.contact_radius;
  const int link_a = body_->linkOfBody(pair.body_a), link_b = body_->linkOfBody(pair.body_b);
  if ((link_a >= 0 && mb->getLink(link_a).m_parent == link_b) || (link_b >= 0 && mb->getLink(link_b).m_parent == link_a))
    throw std::invalid_argument("BulletWorld: scene " + scene_.name + ": contact '" + contact.name +
                                "' joins a link to its parent, which Bullet never collides");
  auto add = [&](int link, std::unique_ptr<btCollisionShape> child, const btTransform& local) {
    auto compound = std::make_unique<btCompoundShape>();
    compound->addChildShape(local, child ? child.get() : sphere);
    colliders_.push_back(std::make_unique<btMultiBodyLinkCollider>(mb, link));
    btMultiBodyLinkCollider* col = colliders_.back().get();
    col->setCollisionShape(compound.get());
    shapes_.push_back(std::move(compound));
    if (child) shapes_.push_back(std::move(child));
    col->setFriction(1);
    col->setRestitution(1);
    col->setRollingFriction(0);
    col->setSpinningFriction(0);
    col->setContactProcessingThreshold(options_.contact_processing_threshold);
    col->setActivationState(DISABLE_DEACTIVATION);
    collider_link_.push_back(link);
    col->setUserIndex(c);  // the filter's mark
    world_->addCollisionObject(col, kPairGroup, kPairGroup);
    return colliders_.back().get();
  };
  btTransform at_point;
  at_point.setIdentity();
  at_point.setOrigin(toBt(body_->bodyPointInLinkFrame(pair.body_a, pair.point_A)));
  btMultiBodyLinkCollider* sphere_col = add(link_a, nullptr, at_point);
  sphere_col->setFriction(contact.friction);  // Bullet combines the two materials by product
  sphere_col->setRestitution(contact.restitution);
  contact_child_[c] = {static_cast<int>(colliders_.size()) - 1, 0};
  // The box in B's body frame: axes (t1, t2, n), top face r below the plane.
  const double half_depth = std::max(10 * r, 0.01);
  Eigen::Matrix3d R_BX;
  R_BX << pair.tangents_B.col(0), pair.tangents_B.col(1), pair.normal_B;
  const Eigen::Vector3d centre_B = pair.plane_point_B - (r + half_depth) * pair.normal_B;
  // bodyPointInLinkFrame places a point; the rotation of the body frame in the link frame is that
  // of two points' difference, so the box's axes are mapped the same way.
  const Eigen::Vector3d centre_L = body_->bodyPointInLinkFrame(pair.body_b, centre_B);
  Eigen::Matrix3d R_LX;
  for (int k = 0; k < 3; ++k)
    R_LX.col(k) = body_->bodyPointInLinkFrame(pair.body_b, centre_B + R_BX.col(k)) - centre_L;
  btTransform at_box;
  at_box.setOrigin(toBt(centre_L));
  at_box.setBasis(btMatrix3x3(R_LX(0, 0), R_LX(0, 1), R_LX(0, 2), R_LX(1, 0), R_LX(1, 1), R_LX(1, 2), R_LX(2, 0),
                              R_LX(2, 1), R_LX(2, 2)));
  auto box = std::make_unique<btBoxShape>(btVector3(pair.extent[0], pair.extent[1], half_depth));
  add(link_b, std::move(box), at_box);
}

// The pair colliders at their links' poses (Bullet moves only each link's m_collider).
void BulletWorld::syncPairColliders() {
  if (!filter_) return;  // no contact on a body's plane
  btMultiBody* mb = body_->multiBody();
  // updates each link's m_cachedWorldTransform
  mb->forwardKinematics(filter_->world_to_local, filter_->local_origin);
  for (std::size_t i = 0; i < colliders_.size(); ++i) {
    if (PairFilter::pairOf(colliders_[i].get()) < 0) continue;
    const int link = collider_link_[i];
    const btTransform X = link < 0 ? mb->getBaseWorldTransform() : mb->getLink(link).m_cachedWorldTransform;
    colliders_[i]->setWorldTransform(X);
    colliders_[i]->setInterpolationWorldTransform(X);
  }
}

double BulletWorld::energy() {
  dynamics::forwardKinematics(scene_.model, data_, q_, v_);
  return dynamics::kineticEnergy(scene_.model, data_) + dynamics::potentialEnergy(scene_.model, data_);
}

}  // namespace saltus::verify
