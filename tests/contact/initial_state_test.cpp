// contact/initial_state.hpp: an initial state inside a surface or beyond a stop is found with its
// depth in the gap's unit (m, rad), deepest first; within the tolerance, or beyond a body plane's
// edge, it is not. (The time-stepper's refusal: tests/timestepper/stepper_test.cpp.)
#include "contact/initial_state.hpp"

#include <algorithm>

#include <gtest/gtest.h>

#include "saltus/build_paths.hpp"
#include "scene/scenario.hpp"

namespace saltus::contact {
namespace {

TEST(InitialState, APointBelowItsSurfaceIsFoundWithItsDepthInMetres) {
  scene::Scene s = scene::loadScene("ball_drop", {{"height", -0.25}});
  const auto found = penetrations(s, s.q0, kInitialPenetrationTolerance);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].name, "ball");
  EXPECT_DOUBLE_EQ(found[0].depth, 0.25);  // the ball's height is its gap
  EXPECT_EQ(found[0].unit, "m");
  EXPECT_EQ(found[0].against, "inside surface 'ground'");
  // within the tolerance: accepted (a state resting on the surface up to round-off)
  s.q0[0] = -0.5 * kInitialPenetrationTolerance;
  EXPECT_TRUE(penetrations(s, s.q0, kInitialPenetrationTolerance).empty());
}

TEST(InitialState, StopsAreMeasuredInTheirCoordinatesUnitDeepestFirst) {
  scene::Scene s = scene::loadScene(std::string(SALTUS_SOURCE_DIR) + "/tests/data/scenes/limits.yaml");
  // rev in [-1, 2] rad, pris in [-0.1, 0.3] m (the scene's URDF)
  const auto& names = s.model.coordinate_name;
  const int rev = static_cast<int>(std::find(names.begin(), names.end(), "rev") - names.begin());
  const int pris = static_cast<int>(std::find(names.begin(), names.end(), "pris") - names.begin());
  ASSERT_LT(rev, s.model.nq());
  ASSERT_LT(pris, s.model.nq());
  s.q0[rev] = 2.5;
  s.q0[pris] = -0.9;
  const auto found = penetrations(s, s.q0, kInitialPenetrationTolerance);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].name, "pris_lower");
  EXPECT_NEAR(found[0].depth, 0.8, 1e-12);
  EXPECT_EQ(found[0].unit, "m");
  EXPECT_EQ(found[1].name, "rev_upper");
  EXPECT_NEAR(found[1].depth, 0.5, 1e-12);
  EXPECT_EQ(found[1].unit, "rad");
}

TEST(InitialState, BeyondABodyPlanesEdgeIsNotAPenetration) {
  scene::Scene s = scene::loadScene("block_on_cart");
  ASSERT_TRUE(penetrations(s, s.q0, kInitialPenetrationTolerance).empty());
  // every coordinate of the block pushed down by 5 cm: under the deck (found) ...
  scene::Scene down = s;
  const int z = static_cast<int>(std::find(s.model.coordinate_name.begin(), s.model.coordinate_name.end(), "block_z") -
                                 s.model.coordinate_name.begin());
  ASSERT_LT(z, s.model.nq()) << "block_on_cart has no coordinate block_z";
  down.q0[z] -= 0.05;
  EXPECT_FALSE(penetrations(down, down.q0, kInitialPenetrationTolerance).empty());
  // ... and as low but 100 m along the deck, beyond its edge: touches nothing
  const int x = z - 1;
  ASSERT_EQ(s.model.coordinate_name[x], "block_x");
  down.q0[x] += 100;
  EXPECT_TRUE(penetrations(down, down.q0, kInitialPenetrationTolerance).empty());
}

}  // namespace
}  // namespace saltus::contact
