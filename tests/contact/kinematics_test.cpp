// Contact kinematics (contact/kinematics.hpp) against independent computations: a point on the
// world ground (gap = height, analytic velocities, a belt's motion subtracted), and a point of one
// moving body on a plane fixed in another (a free-floating base with a swinging arm): the rate of
// the gap by finite differences equals the normal relative velocity, the relative Jacobian times
// q̇ equals the relative velocity of the coincident points, the normal row equals ∂φ/∂q by AD,
// and the generalised force of a reaction is the transpose of the same Jacobian (virtual power).
#include "contact/kinematics.hpp"

#include <gtest/gtest.h>

#include <random>

#include "dynamics/derivatives.hpp"
#include "dynamics/urdf.hpp"

namespace saltus::contact {
namespace {

using dynamics::Data;
using dynamics::Model;

// A box on a free base and an arm on a revolute joint about its y axis.
const char* kTwoBodies = R"(<robot name="two">
  <link name="deck"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.2" izz="0.25" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 -0.2"/><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="swing" type="revolute"><parent link="deck"/><child link="arm"/><origin xyz="0.1 0 0.3" rpy="0 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="10"/></joint>
</robot>)";

struct TwoBodies {
  Model<double> model = dynamics::loadUrdfString(kTwoBodies, dynamics::BaseType::Free);
  ContactPair pair;
  TwoBodies() {
    pair.name = "arm_on_deck";
    pair.body_a = model.bodyIndex("arm");
    pair.point_A = Eigen::Vector3d(0.02, 0.01, -0.4);
    pair.body_b = model.bodyIndex("deck");
    pair.plane_point_B = Eigen::Vector3d(0, 0, 0.05);
    pair.normal_B = Eigen::Vector3d(0.1, -0.2, 1).normalized();
    const Eigen::Vector3d t1 = (Eigen::Vector3d::UnitX() - pair.normal_B.x() * pair.normal_B).normalized();
    pair.tangents_B << t1, pair.normal_B.cross(t1);
    pair.directions_B = pair.tangents_B;
  }
};

Eigen::VectorXd randomVector(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = U(rng);
  return x;
}

TEST(ContactKinematics, PointOnTheWorldGround) {
  // A point mass on a prismatic z axis over the ground: gap = z, v_n = ż, the belt's velocity
  // subtracted from the relative velocity, the normal row e_zᵀ.
  const Model<double> model = dynamics::loadUrdfString(R"(<robot name="p">
    <link name="ball"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  </robot>)", dynamics::BaseType::Free);
  Data<double> data(model);
  ContactPair pair;
  pair.body_a = model.bodyIndex("ball");
  pair.point_A = Eigen::Vector3d(0, 0, -0.01);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nv()), v = Eigen::VectorXd::Zero(model.nv());
  const int z = 2;  // free base: x, y, z, then rotation
  q[z] = 0.3;
  v[0] = 0.4;
  v[z] = -1.5;
  dynamics::forwardKinematics(model, data, q, v);
  EXPECT_NEAR(gap(pair, data, q.data()), 0.29, 1e-14);
  const Eigen::Vector3d belt(0.25, 0, 0);
  EXPECT_NEAR(normalVelocity(pair, data, v.data()), -1.5, 1e-14);
  EXPECT_TRUE(relativeVelocity(pair, data, belt).isApprox(Eigen::Vector3d(0.15, 0, -1.5), 1e-14));
  EXPECT_TRUE(frameVelocity(pair, data, belt).isApprox(Eigen::Vector3d(-1.5, 0.15, 0), 1e-14));  // (n, t1, t2)
  Eigen::Matrix<double, 1, Eigen::Dynamic> row(model.nv());
  normalRow(model, data, pair, row);
  EXPECT_NEAR(row[z], 1.0, 1e-14);
  EXPECT_NEAR(row.norm(), 1.0, 1e-14);
}

TEST(ContactKinematics, JointStop) {
  ContactPair stop;
  stop.kind = PairKind::JointStop;
  stop.coordinate = 1;
  stop.position = 1;
  stop.sign = -1;  // upper
  stop.limit = 0.5;
  const TwoBodies s;
  Data<double> data(s.model);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(s.model.nv(), 0.2), v = Eigen::VectorXd::Constant(s.model.nv(), 3);
  dynamics::forwardKinematics(s.model, data, q, v);
  EXPECT_DOUBLE_EQ(gap(stop, data, q.data()), 0.3);
  EXPECT_DOUBLE_EQ(normalVelocity(stop, data, v.data()), -3.0);
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(s.model.nv());
  addReaction(s.model, data, stop, 2.0, Eigen::Vector3d::Zero().eval(), tau.data());
  EXPECT_DOUBLE_EQ(tau[1], -2.0);
  EXPECT_DOUBLE_EQ(tau.norm(), 2.0);
}

TEST(ContactKinematics, BodyOnBodyRatesAgreeWithFiniteDifferences) {
  const TwoBodies s;
  Data<double> data(s.model), data2(s.model);
  std::mt19937 rng(11);
  const int nv = s.model.nv();
  for (int trial = 0; trial < 5; ++trial) {
    // v = q̇ for every model (dynamics/model.hpp), so the gap's rate along v is its time derivative.
    const Eigen::VectorXd q = 0.3 * randomVector(nv, rng), v = randomVector(nv, rng);
    dynamics::forwardKinematics(s.model, data, q, v);
    const double h = 1e-6;
    const Eigen::VectorXd qp = q + h * v, qm = q - h * v;
    dynamics::forwardKinematics(s.model, data2, qp);
    const double gp = gap(s.pair, data2, qp.data());
    dynamics::forwardKinematics(s.model, data2, qm);
    const double gm = gap(s.pair, data2, qm.data());
    const double rate = (gp - gm) / (2 * h);
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    EXPECT_NEAR(normalVelocity(s.pair, data, v.data()), rate, 1e-7) << "trial " << trial;
    // J q̇ = relative velocity of the coincident points.
    Eigen::Matrix3Xd J(3, nv);
    relativeJacobian(s.model, data, s.pair, J);
    EXPECT_TRUE((J * v).isApprox(relativeVelocity(s.pair, data, zero), 1e-12)) << "trial " << trial;
    // The arm's point and the deck's material point: their difference is the relative velocity.
    const Eigen::Vector3d x = contactPoint(s.pair, data);
    const Eigen::Vector3d x_deck = dynamics::bodyRotation(data, s.pair.body_b).transpose() *
                                   (x - dynamics::bodyPosition(data, s.pair.body_b));
    const Eigen::Vector3d expected = dynamics::pointVelocity(data, s.pair.body_a, s.pair.point_A) -
                                     dynamics::pointVelocity(data, s.pair.body_b, x_deck);
    EXPECT_TRUE(relativeVelocity(s.pair, data, zero).isApprox(expected, 1e-12));
    // In the contact frame: the components along the plane's normal and tangents.
    const PlaneFrame<double> frame = planeFrame(s.pair, data);
    const Eigen::Vector3d in_frame = frameVelocity(s.pair, data, zero);
    EXPECT_NEAR(in_frame[0], frame.normal.dot(expected), 1e-12);
    EXPECT_NEAR(in_frame[0], normalVelocity(s.pair, data, v.data()), 1e-12);
    EXPECT_NEAR(in_frame[1], frame.tangents.col(0).dot(expected), 1e-12);
    EXPECT_NEAR(in_frame[2], frame.tangents.col(1).dot(expected), 1e-12);
    // Virtual power: a reaction's generalised force · v = f · relative velocity.
    const Eigen::Vector3d f_t = frictionDirections(s.pair, data).col(0) * 0.7;
    Eigen::VectorXd tau = Eigen::VectorXd::Zero(nv);
    addReaction(s.model, data, s.pair, 3.0, f_t, tau.data());
    const Eigen::Vector3d f = planeFrame(s.pair, data).normal * 3.0 + f_t;
    EXPECT_NEAR(tau.dot(v), f.dot(relativeVelocity(s.pair, data, zero)), 1e-12);
    // The friction directions lie in the plane.
    EXPECT_NEAR(frictionDirections(s.pair, data).col(1).dot(planeFrame(s.pair, data).normal), 0, 1e-14);
  }
}

// A free contact point (ContactPair::free_axes): the plane's point at plane coordinates s is the
// inverse of planeCoordinates, B's velocity there is its material point's (finite differences of
// its position), the reaction acts on B there (virtual power with relativeVelocityAt), and at s =
// A's projection with A on the plane the free point's reaction and velocity are the fixed point's.
TEST(ContactKinematics, FreePointOnABodysPlane) {
  TwoBodies s;
  s.pair.free_axes = {0, 1};
  Data<double> data(s.model), data2(s.model);
  std::mt19937 rng(13);
  const int nv = s.model.nv();
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = 0.3 * randomVector(nv, rng), v = randomVector(nv, rng);
    const Eigen::Vector2d plane_s = 0.2 * randomVector(2, rng);
    dynamics::forwardKinematics(s.model, data, q, v);
    // planePoint(s) projects back to s and lies on the plane.
    const Eigen::Vector3d x_B = planePoint(s.pair, data, plane_s.data());
    const PlaneFrame<double> frame = planeFrame(s.pair, data);
    EXPECT_NEAR(frame.normal.dot(x_B - frame.point), 0, 1e-14);
    EXPECT_NEAR(frame.tangents.col(0).dot(x_B - frame.point), plane_s[0], 1e-14);
    EXPECT_NEAR(frame.tangents.col(1).dot(x_B - frame.point), plane_s[1], 1e-14);
    // B's material point at s moves with B: its velocity by finite differences along v.
    const double h = 1e-6;
    dynamics::forwardKinematics(s.model, data2, Eigen::VectorXd(q + h * v));
    const Eigen::Vector3d xp = planePoint(s.pair, data2, plane_s.data());
    dynamics::forwardKinematics(s.model, data2, Eigen::VectorXd(q - h * v));
    const Eigen::Vector3d xm = planePoint(s.pair, data2, plane_s.data());
    const Eigen::Vector3d v_A = dynamics::pointVelocity(data, s.pair.body_a, s.pair.point_A);
    EXPECT_LT((relativeVelocityAt(s.pair, data, plane_s.data()) - (v_A - (xp - xm) / (2 * h))).norm(), 1e-8);
    // Its slope along each free axis: relativeVelocityAt is affine in s, so a unit step is exact.
    for (int i = 0; i < 2; ++i) {
      Eigen::Vector2d s1 = plane_s;
      s1[i] += 1.0;
      const Eigen::Vector3d step = relativeVelocityAt(s.pair, data, s1.data()) - relativeVelocityAt(s.pair, data, plane_s.data());
      EXPECT_LT((relativeVelocityAtSlope(s.pair, data, i) - step).norm(), 1e-12);
    }
    // Virtual power: the reaction on A at its point and on B at s.
    const Eigen::Vector3d f_t = frictionDirections(s.pair, data).col(1) * -0.4;
    Eigen::VectorXd tau = Eigen::VectorXd::Zero(nv);
    addReactionAt(s.model, data, s.pair, 2.0, f_t, plane_s.data(), tau.data());
    const Eigen::Vector3d f = frame.normal * 2.0 + f_t;
    EXPECT_NEAR(tau.dot(v), f.dot(relativeVelocityAt(s.pair, data, plane_s.data())), 1e-12);
    // A moved onto the plane (its coordinates in B unchanged by the base): at s = its projection
    // the free point is the fixed one.
    ContactPair on = s.pair;
    const Eigen::Vector3d a_B = dynamics::bodyRotation(data, on.body_b).transpose() *
                                (contactPoint(on, data) - dynamics::bodyPosition(data, on.body_b));
    const Eigen::Vector3d a_on_plane = a_B - on.normal_B * on.normal_B.dot(a_B - on.plane_point_B);
    // the point of A at that material position: A's coordinates of B's point
    const Eigen::Vector3d world = dynamics::pointPosition(data, on.body_b, a_on_plane);
    on.point_A = dynamics::bodyRotation(data, on.body_a).transpose() * (world - dynamics::bodyPosition(data, on.body_a));
    EXPECT_NEAR(gap(on, data, q.data()), 0, 1e-12);
    const Eigen::Vector2d projection = planeCoordinates(on, data);
    Eigen::VectorXd tau_free = Eigen::VectorXd::Zero(nv), tau_fixed = Eigen::VectorXd::Zero(nv);
    addReactionAt(s.model, data, on, 2.0, f_t, projection.data(), tau_free.data());
    addReaction(s.model, data, on, 2.0, f_t, tau_fixed.data());
    EXPECT_LT((tau_free - tau_fixed).norm(), 1e-12);
    EXPECT_LT((relativeVelocityAt(on, data, projection.data()) - relativeVelocity(on, data)).norm(), 1e-12);
  }
}

TEST(ContactKinematics, NormalRowIsTheGradientOfTheGapByAD) {
  using D = dynamics::Dual<Eigen::Dynamic>;
  const TwoBodies s;
  const Model<D> model_d = s.model.cast<D>();
  Data<D> data_d(model_d);
  Data<double> data(s.model);
  std::mt19937 rng(5);
  const int nv = s.model.nv();
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = 0.3 * randomVector(nv, rng);
    Eigen::Matrix<D, Eigen::Dynamic, 1> q_d(nv);
    for (int i = 0; i < nv; ++i) q_d[i] = D(q[i], Eigen::VectorXd::Unit(nv, i));
    dynamics::forwardKinematics(model_d, data_d, q_d);
    const D phi = gap(s.pair, data_d, q_d.data());
    dynamics::forwardKinematics(s.model, data, q);
    EXPECT_NEAR(phi.value(), gap(s.pair, data, q.data()), 1e-14);
    Eigen::Matrix<double, 1, Eigen::Dynamic> row(nv);
    normalRow(s.model, data, s.pair, row);
    // v = q̇ for every model (Euler angles on a free base), so the row is ∂φ/∂q.
    for (int i = 0; i < nv; ++i) EXPECT_NEAR(row[i], phi.derivatives()[i], 1e-12) << "trial " << trial << ", q" << i;
  }
}

}  // namespace
}  // namespace saltus::contact
