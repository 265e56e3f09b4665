// Contact kinematics of a pair (contact/pair.hpp), templated on the scalar like dynamics/ so the
// collocation's local functions differentiate them by AD: the gap φ, the contact frame in world
// coordinates, the relative velocity of the contact point (including a world surface's
// prescribed motion) and the relative Jacobian J = J_A − J_B, with which the reaction enters the
// equations of motion as Jᵀ f (RBDA §11.2; paper §II.C and eq. 6).
//
// For a point on a plane fixed in body B the contact point is x = the point of A; its relative
// velocity is that of A's point minus that of B's material point at x (and minus the surface's
// velocity for a world plane), and J maps q̇ to it. For a joint stop the "frame" is the coordinate
// itself: gap sign·(q_i − limit), normal velocity sign·q̇_i, normal row sign·e_iᵀ.
// The material velocity of a world plane (a belt's schedule) is the consumer's to give: the
// time-stepper reads it at a time, the collocation at a mesh element.
//
// Every function needs dynamics::forwardKinematics at q (and at (q, v) for velocities) in `data`.
#pragma once

#include "contact/pair.hpp"
#include "dynamics/jacobian.hpp"
#include "dynamics/kinematics.hpp"

namespace saltus::contact {

template <class S> using Vec3 = dynamics::Vec3<S>;
template <class S> using Tangents = Eigen::Matrix<S, 3, 2>;

// The plane of a point-on-plane pair in world coordinates.
template <class S>
struct PlaneFrame {
  Vec3<S> point;        // a point of the plane
  Vec3<S> normal;       // unit normal
  Tangents<S> tangents;  // (t1, t2), t2 = n × t1
};

template <class S>
PlaneFrame<S> planeFrame(const ContactPair& pair, const dynamics::Data<S>& data) {
  PlaneFrame<S> f;
  if (pair.body_b < 0) {  // a world plane: as given
    f.point = pair.plane_point_B.cast<S>();
    f.normal = pair.normal_B.cast<S>();
    f.tangents = pair.tangents_B.cast<S>();
    return f;
  }
  const dynamics::Mat3<S> R = dynamics::bodyRotation(data, pair.body_b);
  f.point = dynamics::pointPosition(data, pair.body_b, Vec3<S>(pair.plane_point_B.cast<S>()));
  f.normal = R * pair.normal_B.cast<S>();
  f.tangents = R * pair.tangents_B.cast<S>();
  return f;
}

// The plane's unit normal in world coordinates (planeFrame's, without the rest).
template <class S>
Vec3<S> planeNormal(const ContactPair& pair, const dynamics::Data<S>& data) {
  if (pair.body_b < 0) return pair.normal_B.cast<S>();
  return dynamics::bodyRotation(data, pair.body_b) * pair.normal_B.cast<S>();
}

// World position of the contact point (the point of A); a stop has none (zero).
template <class S>
Vec3<S> contactPoint(const ContactPair& pair, const dynamics::Data<S>& data) {
  if (pair.isStop()) return Vec3<S>::Zero();
  return dynamics::pointPosition(data, pair.body_a, Vec3<S>(pair.point_A.cast<S>()));
}

// The gap φ(q): n·(x − plane point) for a point on a plane, sign·(q_i − limit) for a stop.
template <class S>
S gap(const ContactPair& pair, const dynamics::Data<S>& data, const S* q) {
  if (pair.isStop()) return S(pair.sign) * (q[pair.position] - S(pair.limit));
  const Vec3<S> x = contactPoint(pair, data);
  if (pair.body_b < 0) return pair.normal_B.cast<S>().dot(x - pair.plane_point_B.cast<S>());
  const PlaneFrame<S> f = planeFrame(pair, data);
  return f.normal.dot(x - f.point);
}

// B's material point at the contact point, in B's coordinates (the contact point itself for the world).
template <class S>
Vec3<S> pointOnB(const ContactPair& pair, const dynamics::Data<S>& data) {
  const Vec3<S> x = contactPoint(pair, data);
  if (pair.body_b < 0) return x;
  return dynamics::bodyRotation(data, pair.body_b).transpose() * (x - dynamics::bodyPosition(data, pair.body_b));
}

// The contact point's coordinates in a body's plane, s_i = t_i·(x − p) along the plane's tangents
// in B's coordinates: what its extent bounds. For a plane fixed in a body only.
template <class S>
Eigen::Matrix<S, 2, 1> planeCoordinates(const ContactPair& pair, const dynamics::Data<S>& data) {
  return pair.tangents_B.cast<S>().transpose() * (pointOnB(pair, data) - pair.plane_point_B.cast<S>());
}

// A free contact point (ContactPair::free_axes): the point of B's plane at plane coordinates s,
// s[i] along the tangent free_axes[i] (0 along the others), in B's coordinates, p + Σ_i t_i s[i]:
// planeCoordinates' inverse on the free axes. The optimiser's contact point on B.
template <class S>
Vec3<S> planePointInB(const ContactPair& pair, const S* s) {
  Vec3<S> x = pair.plane_point_B.cast<S>();
  for (int i = 0; i < pair.freeAxes(); ++i) x += pair.tangents_B.col(pair.free_axes[i]).cast<S>() * s[i];
  return x;
}

// The same in world coordinates.
template <class S>
Vec3<S> planePoint(const ContactPair& pair, const dynamics::Data<S>& data, const S* s) {
  return dynamics::pointPosition(data, pair.body_b, planePointInB(pair, s));
}

// Whether the pair's plane is bounded (a plane fixed in a body, with its extent).
inline bool hasExtent(const ContactPair& pair) { return !pair.isStop() && pair.body_b >= 0; }

// Whether the contact point lies over the plane's rectangle (always, for a world plane or a
// stop): |s_i| ≤ extent_i (planeCoordinates). A point beyond it touches nothing.
// The same test for plane coordinates s already computed (planeCoordinates).
inline bool withinExtent(const ContactPair& pair, const Eigen::Vector2d& s) {
  return !hasExtent(pair) || (std::abs(s[0]) <= pair.extent[0] && std::abs(s[1]) <= pair.extent[1]);
}
inline bool withinExtent(const ContactPair& pair, const dynamics::Data<double>& data) {
  return !hasExtent(pair) || withinExtent(pair, Eigen::Vector2d(planeCoordinates(pair, data)));
}

// Relative velocity of the contact point of a point on a plane, in world coordinates, of the
// bodies alone: v_A(x) − v_B(x) (B's material point at x; nothing for the world) = J q̇. Not for a
// stop (see normalVelocity).
template <class S>
Vec3<S> relativeVelocity(const ContactPair& pair, const dynamics::Data<S>& data) {
  if (pair.body_b < 0) return dynamics::pointVelocity(data, pair.body_a, Vec3<S>(pair.point_A.cast<S>()));
  return dynamics::pointVelocity(data, pair.body_a, Vec3<S>(pair.point_A.cast<S>())) -
         dynamics::pointVelocity(data, pair.body_b, pointOnB(pair, data));
}

// The relative velocity of a free contact point: v_A(x) − v_B(p + Σ t_i s_i), B's material point
// at plane coordinates s (planePointInB) rather than at A's point.
template <class S>
Vec3<S> relativeVelocityAt(const ContactPair& pair, const dynamics::Data<S>& data, const S* s) {
  return dynamics::pointVelocity(data, pair.body_a, Vec3<S>(pair.point_A.cast<S>())) -
         dynamics::pointVelocity(data, pair.body_b, planePointInB(pair, s));
}

// ∂/∂s_i of relativeVelocityAt (which is affine in s): B's material point moves along the free
// axis i with B's rotation, −ω_B × t_i in world coordinates (ω_B from forwardVelocities).
template <class S>
Vec3<S> relativeVelocityAtSlope(const ContactPair& pair, const dynamics::Data<S>& data, int i) {
  const Vec3<S> t_B = pair.tangents_B.col(pair.free_axes[i]).cast<S>();
  return -(data.X_world[pair.body_b].E.transpose() * data.v[pair.body_b].w.cross(t_B));
}

// The same less a world plane's material velocity (a belt's; tangent to the plane): the slip.
template <class S>
Vec3<S> relativeVelocity(const ContactPair& pair, const dynamics::Data<S>& data,
                         const std::type_identity_t<Vec3<S>>& surface_velocity) {
  return relativeVelocity(pair, data) - surface_velocity;
}

// The slip velocity (relativeVelocity less the surface's) in the contact frame: its components
// along the normal and the tangents (t1, t2). Not for a stop.
template <class S>
Vec3<S> frameVelocity(const ContactPair& pair, const dynamics::Data<S>& data,
                      const std::type_identity_t<Vec3<S>>& surface_velocity) {
  const Vec3<S> v = relativeVelocity(pair, data, surface_velocity);
  if (pair.body_b < 0)
    return Vec3<S>(pair.normal_B.cast<S>().dot(v), pair.tangents_B.col(0).cast<S>().dot(v),
                   pair.tangents_B.col(1).cast<S>().dot(v));
  const Vec3<S> v_B = dynamics::bodyRotation(data, pair.body_b).transpose() * v;  // in B's coordinates
  return Vec3<S>(pair.normal_B.cast<S>().dot(v_B), pair.tangents_B.col(0).cast<S>().dot(v_B),
                 pair.tangents_B.col(1).cast<S>().dot(v_B));
}

// Normal component of the relative velocity, n·(J q̇) (a surface's own motion is tangent to it,
// so it has none); sign·q̇_i for a stop.
template <class S>
S normalVelocity(const ContactPair& pair, const dynamics::Data<S>& data, const S* v) {
  if (pair.isStop()) return S(pair.sign) * v[pair.coordinate];
  return planeNormal(pair, data).dot(relativeVelocity(pair, data));
}

// Friction direction j of the cone in world coordinates (no allocation: for a time step).
template <class S>
Vec3<S> frictionDirection(const ContactPair& pair, const dynamics::Data<S>& data, int j) {
  if (pair.body_b < 0) return pair.directions_B.col(j).cast<S>();
  return dynamics::bodyRotation(data, pair.body_b) * pair.directions_B.col(j).cast<S>();
}

// The friction directions of the cone in world coordinates (3 × k).
template <class S>
Eigen::Matrix<S, 3, Eigen::Dynamic> frictionDirections(const ContactPair& pair, const dynamics::Data<S>& data) {
  Eigen::Matrix<S, 3, Eigen::Dynamic> d(3, pair.k());
  for (int j = 0; j < pair.k(); ++j) d.col(j) = frictionDirection(pair, data, j);
  return d;
}

// Calls fn(k, c) with the column c of the relative Jacobian J_A(x_A) − J_B(x_B) (world
// coordinates) for every coordinate k on the bodies' paths to the root, as dynamics::pointJacobian
// builds its columns: +(s_k × x_A) on A's path, −(s_k × x_B) on B's, so that a common ancestor's
// two calls cancel when x_A = x_B.
template <class S, class F>
SALTUS_INLINE void forEachJacobianColumn(const dynamics::Model<S>& model, const dynamics::Data<S>& data,
                                         const ContactPair& pair, const Vec3<S>& x_A, const Vec3<S>& x_B, F&& fn) {
  // (a negation, not a product: cheap for AD scalars)
  auto path = [&](int body, bool negate, const Vec3<S>& x) SALTUS_LAMBDA_INLINE {
    for (int j = body; j >= 0; j = model.parent[j])
      for (int k = model.first_coordinate[j]; k < model.first_coordinate[j] + model.num_coordinates[j]; ++k) {
        const dynamics::Motion<S> s = data.X_world[j].applyInverse(data.S_joint[k]);
        if (negate)
          fn(k, Vec3<S>(-(s.v + s.w.cross(x))));
        else
          fn(k, Vec3<S>(s.v + s.w.cross(x)));
      }
  };
  path(pair.body_a, false, x_A);
  path(pair.body_b, true, x_B);
}

// The pair's relative Jacobian at its contact point x (A's point): J_A(x) − J_B(x).
template <class S, class F>
SALTUS_INLINE void forEachJacobianColumn(const dynamics::Model<S>& model, const dynamics::Data<S>& data,
                                         const ContactPair& pair, F&& fn) {
  const Vec3<S> x = contactPoint(pair, data);
  forEachJacobianColumn(model, data, pair, x, x, std::forward<F>(fn));
}

// A free contact point's relative Jacobian J_A(x_A) − J_B(planePoint(s)), the Jacobian of
// relativeVelocityAt: B's material point at plane coordinates s.
template <class S, class F>
SALTUS_INLINE void forEachJacobianColumnAt(const dynamics::Model<S>& model, const dynamics::Data<S>& data,
                                           const ContactPair& pair, const S* s, F&& fn) {
  forEachJacobianColumn(model, data, pair, contactPoint(pair, data), planePoint(pair, data, s), std::forward<F>(fn));
}

// The relative Jacobian J_A(x) − J_B(x) (3 × nv, world coordinates): J q̇ is the relative velocity
// without the surface's motion. Not for a stop (see normalRow).
template <class S>
void relativeJacobian(const dynamics::Model<S>& model, const dynamics::Data<S>& data, const ContactPair& pair,
                      dynamics::MatOut<dynamics::Mat3X<S>> J) {
  J.setZero();
  forEachJacobianColumn(model, data, pair, [&](int k, const Vec3<S>& c) SALTUS_LAMBDA_INLINE { J.col(k) += c; });
}

// The normal row of the pair's constraint (1 × nv): nᵀ J for a point on a plane, sign·e_iᵀ for a stop.
// `row` may be a row of a column-major matrix (an LCP's constraint matrix).
template <class S>
void normalRow(const dynamics::Model<S>& model, const dynamics::Data<S>& data, const ContactPair& pair,
               std::type_identity_t<Eigen::Ref<Eigen::Matrix<S, 1, Eigen::Dynamic>, 0, Eigen::InnerStride<>>> row) {
  row.setZero();
  if (pair.isStop()) {
    row[pair.coordinate] = S(pair.sign);
    return;
  }
  const Vec3<S> n = planeNormal(pair, data);
  forEachJacobianColumn(model, data, pair, [&](int k, const Vec3<S>& c) SALTUS_LAMBDA_INLINE { row[k] += n.dot(c); });
}

// The generalised force of a reaction with normal component r_n and tangential force f_t (world
// coordinates, in the plane; zero for a stop): tau += Jᵀ (n r_n + f_t) for a point on a plane
// (acting on A, its opposite on B), tau_i += sign·r_n for a stop.
template <class S>
void addReaction(const dynamics::Model<S>& model, const dynamics::Data<S>& data, const ContactPair& pair, const S& r_n,
                 const Vec3<S>& f_t, S* tau) {
  if (pair.isStop()) {
    tau[pair.coordinate] += S(pair.sign) * r_n;
    return;
  }
  const Vec3<S> f = planeNormal(pair, data) * r_n + f_t;
  forEachJacobianColumn(model, data, pair, [&](int k, const Vec3<S>& c) SALTUS_LAMBDA_INLINE { tau[k] += c.dot(f); });
}

// The same for a free contact point (ContactPair::free_axes) at plane coordinates s: the force
// acts on A at A's point and its opposite on B at planePoint(s), tau += J_A(x_A)ᵀ f − J_B(x_B)ᵀ f.
template <class S>
void addReactionAt(const dynamics::Model<S>& model, const dynamics::Data<S>& data, const ContactPair& pair,
                   const S& r_n, const Vec3<S>& f_t, const S* s, S* tau) {
  const Vec3<S> f = planeNormal(pair, data) * r_n + f_t;
  forEachJacobianColumnAt(model, data, pair, s, [&](int k, const Vec3<S>& c) SALTUS_LAMBDA_INLINE { tau[k] += c.dot(f); });
}

}  // namespace saltus::contact
