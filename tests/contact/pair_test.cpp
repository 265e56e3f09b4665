// The pairs of a scene (contact/pair.hpp): its contacts in order, then its joint stops, with the
// surface's plane, tangent basis and friction cone, and each stop's sign.
#include "contact/pair.hpp"

#include <gtest/gtest.h>

#include <random>

#include "contact/kinematics.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/world_translation.hpp"

#include "scene/scenario.hpp"
#include "saltus/build_paths.hpp"

namespace saltus::contact {
namespace {

TEST(ContactPairs, ContactsThenStopsWithTheirPlanesAndSigns) {
  scene::Scene s = scene::loadScene("pendulum_conveyor");
  scene::LimitStop lower{"theta2_lower", 1, false, -0.5, 0.2}, upper{"theta2_upper", 1, true, 2.0, 0};
  s.limits = {lower, upper};
  ASSERT_EQ(s.contacts.size(), 1u);
  const std::vector<ContactPair> pairs = contactPairs(s);
  ASSERT_EQ(pairs.size(), 3u);
  const ContactPair& tip = pairs[0];
  const scene::Contact& c = s.contacts[0];
  const scene::Surface& belt = s.surfaces[c.surface];
  EXPECT_EQ(tip.name, c.name);
  EXPECT_EQ(tip.kind, PairKind::PointOnPlane);
  EXPECT_EQ(tip.body_a, c.body);
  EXPECT_EQ(tip.body_b, -1);
  EXPECT_EQ(tip.surface, c.surface);
  EXPECT_TRUE(tip.normal_B.isApprox(belt.normal));
  EXPECT_TRUE(tip.plane_point_B.isApprox(belt.point));
  EXPECT_EQ(tip.k(), c.friction > 0 ? c.directions : 0);
  EXPECT_DOUBLE_EQ(tip.friction, c.friction);
  // The tangent basis is right-handed with the normal, the cone in the plane.
  EXPECT_TRUE(tip.tangents_B.col(0).cross(tip.tangents_B.col(1)).isApprox(tip.normal_B));
  for (int j = 0; j < tip.k(); ++j) EXPECT_NEAR(tip.directions_B.col(j).dot(tip.normal_B), 0, 1e-15);
  EXPECT_TRUE(pairs[1].isStop());
  EXPECT_EQ(pairs[1].sign, 1.0);
  EXPECT_EQ(pairs[1].limit, -0.5);
  EXPECT_EQ(pairs[1].restitution, 0.2);
  EXPECT_EQ(pairs[2].sign, -1.0);
  EXPECT_EQ(pairs[2].k(), 0);
}

// jacobian_with: moves_with less the world translations that shift the contact point and the
// plane together (dynamics/world_translation.hpp). Shifting such a coordinate leaves the relative
// Jacobian as it was; shifting any world translation leaves the plane's normal as it was and
// changes the Jacobian, the gap and the plane coordinates linearly (second differences of zero). On the cart of the conveyor, the boxes'
// bases, HyQ's base and the skateboard's rider and board, whose feet stand on the deck: a plane
// on another tree, against which the rider's translations move the feet.
TEST(ContactPairs, JacobianWithLeavesOutTheWorldTranslations) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> U(-1, 1);
  int translations = 0, shifted = 0, levers = 0, depending = 0, changed = 0, lever_moved = 0;
  for (const char* name : {"pendulum_conveyor", "box_stack", "hyq_drop", "skateboard_rider"}) {
    const scene::Scene s = scene::loadScene(name);
    const auto& model = s.model;
    dynamics::Data<double> data(model);
    const std::vector<ContactPair> pairs = contactPairs(s);
    Eigen::VectorXd q(model.nq());
    for (int i = 0; i < q.size(); ++i) q[i] = U(rng);
    if (model.nq() != model.nv()) q.segment(3, 4).normalize();  // a quaternion base
    struct Look {
      dynamics::Mat3X<double> J;
      Eigen::Vector3d normal;
      double gap;
      Eigen::Vector2d s;
    };
    auto look = [&](const ContactPair& pair, const Eigen::VectorXd& at) {
      dynamics::forwardKinematics(model, data, at);
      Look l{dynamics::Mat3X<double>(3, model.nv()), planeNormal(pair, data), gap(pair, data, at.data()),
             planeCoordinates(pair, data)};
      relativeJacobian(model, data, pair, l.J);
      return l;
    };
    for (const ContactPair& pair : pairs) {
      ASSERT_EQ(static_cast<int>(pair.jacobian_with.size()), model.nv()) << name << " " << pair.name;
      if (pair.isStop()) {
        for (int k = 0; k < model.nv(); ++k) EXPECT_FALSE(pair.jacobian_with[k]) << name << " " << pair.name;
        continue;
      }
      const Look l0 = look(pair, q);
      for (int k = 0; k < model.nv(); ++k) {
        const std::string what = std::string(name) + " " + pair.name + " " + std::to_string(k);
        EXPECT_TRUE(!pair.jacobian_with[k] || pair.moves_with[k]) << what;
        if (!pair.moves_with[k]) continue;
        if (model.nq() != model.nv() && k >= 3 && k < 6) continue;  // a quaternion's rotation: not by a shift
        const double d = 0.3;
        Eigen::VectorXd q1 = q, q2 = q;
        q1[model.positionOf(k)] += d;
        q2[model.positionOf(k)] += 2 * d;
        const Look l1 = look(pair, q1), l2 = look(pair, q2);
        const double scale = 1 + l0.J.norm();
        if (pair.jacobian_with[k]) {
          ++depending;
          const bool moved = (l1.J - l0.J).norm() > 1e-6 * scale || (l1.normal - l0.normal).norm() > 1e-6;
          changed += moved;
          lever_moved += moved && dynamics::isWorldTranslation(model, k);
        } else {
          ++shifted;
          EXPECT_LT((l1.J - l0.J).norm(), 1e-12 * scale) << what;
        }
        if (!dynamics::isWorldTranslation(model, k)) continue;
        ++translations;
        levers += pair.jacobian_with[k];
        EXPECT_LT((l2.J - 2 * l1.J + l0.J).norm(), 1e-12 * scale) << what;
        EXPECT_LT((l1.normal - l0.normal).norm(), 1e-14) << what;
        EXPECT_NEAR(l2.gap - 2 * l1.gap + l0.gap, 0.0, 1e-12) << what;
        if (pair.body_b >= 0) { EXPECT_LT((l2.s - 2 * l1.s + l0.s).norm(), 1e-12) << what; }
      }
    }
  }
  EXPECT_GT(shifted, 0);
  EXPECT_GT(levers, 0);  // the rider's and the board's translations for the feet on the deck
  EXPECT_GT(translations, levers);
  // Most coordinates jacobian_with names change the Jacobian or the normal here (it may name more
  // than do: the board's angle turns the deck's normal but not the feet's Jacobian in world
  // axes, and a box that only slides up and down has no rotation for a translation to lever).
  EXPECT_GT(changed, depending / 2);
  EXPECT_GT(lever_moved, 0);  // the rider's x moves the feet against the board's rotation axis
}

// reaction_jacobian_with: for a free point (feet free along the deck: the point-mass riders and
// the rider's shank tips), the coordinates J_A(x_A) − J_B(p + Σ t_i s_i) at given plane
// coordinates s and the plane's normal depend on: no world translation, though jacobian_with
// names the riders' and the board's (the Jacobian at A's point levers B's rotation about A's
// point, which a translation of A moves). Shifting a coordinate it leaves out leaves that
// Jacobian and the normal as they were, at random states and random s; the Jacobian at A's
// point does change with the rider's x. For a point at A's point it is jacobian_with.
TEST(ContactPairs, ReactionJacobianWithOfAFreePointLeavesOutEveryWorldTranslation) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  int free_points = 0, left_out = 0, lever_at_A = 0, named = 0, changed = 0;
  for (const char* name : {"skateboard", "skateboard_rider", "hyq_drop", "box_stack"}) {
    const scene::Scene sc = scene::loadScene(name);
    const auto& model = sc.model;
    dynamics::Data<double> data(model);
    for (const ContactPair& pair : contactPairs(sc)) {
      const std::string what = std::string(name) + " " + pair.name;
      ASSERT_EQ(static_cast<int>(pair.reaction_jacobian_with.size()), model.nv()) << what;
      if (!pair.freePoint()) {
        EXPECT_EQ(pair.reaction_jacobian_with, pair.jacobian_with) << what;
        continue;
      }
      ++free_points;
      for (int trial = 0; trial < 3; ++trial) {
        Eigen::VectorXd q(model.nq());
        for (int i = 0; i < q.size(); ++i) q[i] = U(rng);
        const double s[2] = {U(rng), U(rng)};
        struct Look {
          dynamics::Mat3X<double> J_s, J_A;  // at the plane coordinates s, at A's point
          Eigen::Vector3d normal;
        };
        auto look = [&](const Eigen::VectorXd& at) {
          dynamics::forwardKinematics(model, data, at);
          Look l{dynamics::Mat3X<double>::Zero(3, model.nv()), dynamics::Mat3X<double>(3, model.nv()),
                 planeNormal(pair, data)};
          forEachJacobianColumnAt(model, data, pair, s, [&](int k, const Eigen::Vector3d& c) { l.J_s.col(k) += c; });
          relativeJacobian(model, data, pair, l.J_A);
          return l;
        };
        const Look l0 = look(q);
        for (int k = 0; k < model.nv(); ++k) {
          EXPECT_TRUE(!pair.reaction_jacobian_with[k] || pair.jacobian_with[k]) << what << " " << k;
          if (!pair.moves_with[k]) continue;
          Eigen::VectorXd q1 = q;
          q1[model.positionOf(k)] += 0.4;
          const Look l1 = look(q1);
          const double scale = 1 + l0.J_s.norm();
          if (pair.reaction_jacobian_with[k]) {
            ++named;
            changed += (l1.J_s - l0.J_s).norm() > 1e-6 * scale || (l1.normal - l0.normal).norm() > 1e-6;
            continue;
          }
          ++left_out;
          EXPECT_TRUE(dynamics::isWorldTranslation(model, k)) << what << " " << k;
          EXPECT_LT((l1.J_s - l0.J_s).norm(), 1e-12 * scale) << what << " " << k;
          EXPECT_LT((l1.normal - l0.normal).norm(), 1e-14) << what << " " << k;
          lever_at_A += pair.jacobian_with[k] && (l1.J_A - l0.J_A).norm() > 1e-6 * scale;
        }
      }
    }
  }
  EXPECT_EQ(free_points, 4);  // two feet on each deck
  EXPECT_GT(left_out, 0);
  EXPECT_GT(lever_at_A, 0);  // what jacobian_with keeps them for: the Jacobian at A's point
  EXPECT_GT(changed, named / 2);
}

}  // namespace
}  // namespace saltus::contact

namespace saltus::contact {
namespace {

// moves_with against the contact layer's own Jacobian: at random states, a point's relative
// Jacobian is non-zero in exactly the columns it names (a HyQ foot: the base and its own leg's
// three joints, not the other legs; a box on a box: both boxes' coordinates), a stop's in its
// coordinate only.
TEST(ContactPairs, MovesWithTheColumnsOfItsJacobian) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  int points = 0, off_path = 0;
  for (const char* name : {"hyq_drop", "chain_on_stops", "box_stack", "pendulum_conveyor"}) {
    const scene::Scene s = scene::loadScene(name);
    const auto& model = s.model;
    dynamics::Data<double> data(model);
    const std::vector<ContactPair> pairs = contactPairs(s);
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd q(model.nq());
      for (int i = 0; i < q.size(); ++i) q[i] = U(rng);
      if (model.nq() != model.nv()) q.segment(3, 4).normalize();  // a quaternion base
      dynamics::forwardKinematics(model, data, q);
      for (const ContactPair& pair : pairs) {
        ASSERT_EQ(static_cast<int>(pair.moves_with.size()), model.nv()) << name << " " << pair.name;
        Eigen::RowVectorXd row(model.nv());
        normalRow(model, data, pair, row);
        dynamics::Mat3X<double> J(3, model.nv());
        if (!pair.isStop()) relativeJacobian(model, data, pair, J);
        for (int k = 0; k < model.nv(); ++k) {
          const double column = pair.isStop() ? std::abs(row[k]) : J.col(k).norm();
          if (pair.moves_with[k])
            EXPECT_GT(column, 1e-9) << name << " " << pair.name << " column " << k;
          else
            EXPECT_EQ(column, 0.0) << name << " " << pair.name << " column " << k;
          off_path += !pair.moves_with[k];
        }
        points += !pair.isStop();
      }
    }
  }
  EXPECT_GT(points, 0);
  EXPECT_GT(off_path, 0);
}

}  // namespace
}  // namespace saltus::contact
