// Frames of a trajectory: how many, and that consecutive frames differ while the body moves and
// are identical while it rests; impulse markers; bad options.
#include "render/animation.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "render/csv_trajectory.hpp"
#include "tests/support/files.hpp"
#include "tests/support/scenes.hpp"

namespace {

using namespace saltus::render;

// Ball falling from 1 m to rest at 0 by t = 0.5 (an impulse at 0.5), then resting until t = 1.
std::string restingBallCsv() {
  static const saltus::testing::ScratchDir dir("render", "animation");  // removed when the program exits
  const auto path = dir / "resting_ball.csv";
  std::ofstream out(path);
  out << "t,q.z,v.z,contact.ball.rn,contact.ball.pn\n";
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.05 * k;
    out << t << "," << 1 - 4 * t * t << "," << -8 * t << ",0,0\n";
  }
  out << "0.5,0,0,0,4\n";  // after the jump: at rest, impulse 4 N s
  for (int k = 11; k <= 20; ++k) out << 0.05 * k << ",0,0,9.81,0\n";
  return path.string();
}

TEST(Animation, FrameCountFollowsFpsAndSpeed) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.0);
  const CsvTrajectory tr(restingBallCsv(), scene);
  std::ostringstream warnings;
  AnimationOptions options;
  options.fps = 10;
  EXPECT_EQ(Animation(scene, tr, options, warnings).frames(), 11);
  options.speed = 0.5;  // twice as slow: twice the frames
  const Animation slow(scene, tr, options, warnings);
  EXPECT_EQ(slow.frames(), 21);
  EXPECT_NEAR(slow.time(1), 0.05, 1e-12);
  options.fps = 0;
  EXPECT_THROW(Animation(scene, tr, options, warnings), std::invalid_argument);
  options.fps = 30;
  options.speed = -1;
  EXPECT_THROW(Animation(scene, tr, options, warnings), std::invalid_argument);
}

TEST(Animation, FramesChangeWhileMovingAndRepeatAtRest) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.0);
  const CsvTrajectory tr(restingBallCsv(), scene);
  std::ostringstream warnings;
  AnimationOptions options;
  options.fps = 20;
  options.width = 160;
  options.height = 120;
  options.marker_seconds = 0.2;  // the impulse marker is gone by t = 0.7
  const Animation animation(scene, tr, options, warnings);
  ASSERT_EQ(animation.frames(), 21);
  Renderer renderer(animation.geometry(), animation.settings());
  std::vector<std::vector<std::uint8_t>> images;
  for (int k = 0; k < animation.frames(); ++k) {
    renderer.draw(animation.camera(k), animation.content(k));
    images.push_back(renderer.rgb());
  }
  for (int k = 1; k <= 10; ++k) EXPECT_NE(images[k], images[k - 1]) << "frame " << k << " (moving)";
  for (int k = 15; k <= 20; ++k) EXPECT_EQ(images[k], images[k - 1]) << "frame " << k << " (resting)";
  // the impulse marker shows at the impact and is gone later
  EXPECT_EQ(animation.content(10).markers.size(), 1u);
  EXPECT_EQ(animation.content(12).markers.size(), 1u);
  EXPECT_TRUE(animation.content(15).markers.empty());
  // at rest the force arrow points up, weight-sized arrows are drawn
  ASSERT_EQ(animation.content(16).arrows.size(), 1u);
  EXPECT_GT(animation.content(16).arrows[0].vector.z(), 0);
}

TEST(Animation, AutoCameraFramesTheWholeTrajectory) {
  const auto scene = saltus::testing::ballDrop(1.0, 0.0);
  const CsvTrajectory tr(restingBallCsv(), scene);
  std::ostringstream warnings;
  AnimationOptions options;
  options.width = 160;
  options.height = 120;
  options.fps = 10;
  const Animation animation(scene, tr, options, warnings);
  const Camera c0 = animation.camera(0);
  EXPECT_EQ(c0.eye, animation.camera(animation.frames() - 1).eye);  // fixed
  for (int k = 0; k < animation.frames(); ++k) {
    const Eigen::Vector2d px = c0.pixel(animation.content(k).pose.X_WG[0].translation(), 160, 120);
    EXPECT_GT(px.x(), 0);
    EXPECT_LT(px.x(), 160);
    EXPECT_GT(px.y(), 0);
    EXPECT_LT(px.y(), 120);
  }
  options.camera = CameraMode::Follow;
  const Animation follow(scene, tr, options, warnings);
  for (int k : {0, 5, 10}) {  // the body stays at the image centre
    const Eigen::Vector2d px = follow.camera(k).pixel(follow.content(k).pose.X_WG[0].translation(), 160, 120);
    EXPECT_NEAR(px.x(), 80, 2);
    EXPECT_NEAR(px.y(), 60, 2);
  }
}

TEST(Animation, CameraNamesParse) {
  EXPECT_EQ(parseCameraMode("follow"), CameraMode::Follow);
  EXPECT_EQ(parseCameraMode("side"), CameraMode::Side);
  EXPECT_THROW(parseCameraMode("orbit"), std::invalid_argument);
}

}  // namespace
