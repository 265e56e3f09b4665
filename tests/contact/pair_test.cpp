// The pairs of a scene (contact/pair.hpp): its contacts in order, then its joint stops, with the
// surface's plane, tangent basis and friction cone, and each stop's sign.
#include "contact/pair.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace saltus::contact
