// The renderer draws a body where the camera projection says it is: the centroid of the
// non-background pixels of a sphere against its projected centre, computed independently.
#include "render/renderer.hpp"

#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/support/pixels.hpp"
#include "tests/support/scenes.hpp"

namespace {

using namespace saltus::render;
using saltus::testing::Centroid;
using saltus::testing::nonBackground;

constexpr int kW = 160, kH = 120;

// Projection written out by hand (look-at axes, focal length (H/2)/tan(fov/2), y down).
Eigen::Vector2d projectByHand(const Camera& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d f = (c.target - c.eye).normalized(), r = f.cross(c.up).normalized(), u = r.cross(f);
  const Eigen::Vector3d d = p - c.eye;
  const double focal = (kH / 2.0) / std::tan(c.fov_y / 2);
  return {kW / 2.0 + focal * d.dot(r) / d.dot(f), kH / 2.0 - focal * d.dot(u) / d.dot(f)};
}

TEST(Renderer, SphereAppearsAtItsProjectedCentre) {
  const auto scene = saltus::testing::particle3d(Eigen::Vector2d::Zero(), 0, 4);  // point mass on x, y, z
  std::ostringstream warnings;
  const SceneGeometry geometry(scene, warnings);
  RenderSettings settings;
  settings.width = kW;
  settings.height = kH;
  settings.surfaces = false;
  Renderer renderer(geometry, settings);
  Camera camera;
  camera.eye = {0.3, -1.5, 0.6};
  camera.target = {0, 0, 0.2};
  camera.fov_y = 0.7;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, 0.1, 0.45), Eigen::Vector3d(-0.25, -0.2, 0.0),
                                   Eigen::Vector3d(0.0, 0.0, 0.2)}) {
    FrameContent frame;
    frame.pose = geometry.pose(p);
    renderer.draw(camera, frame);
    const Centroid c = nonBackground(renderer.rgb(), kW, kH, settings.background);
    const Eigen::Vector2d expected = projectByHand(camera, p);
    // a sphere of radius r at distance d covers about π (f r / d)² pixels
    const double radius_px = (kH / 2.0) / std::tan(camera.fov_y / 2) * geometry.shapes()[0].scale.x() / (p - camera.eye).norm();
    EXPECT_NEAR(c.pixels, M_PI * radius_px * radius_px, 0.25 * M_PI * radius_px * radius_px) << p.transpose();
    EXPECT_NEAR(c.at.x(), expected.x(), 1.0) << p.transpose();
    EXPECT_NEAR(c.at.y(), expected.y(), 1.0) << p.transpose();
  }
}

TEST(Renderer, ArrowIsDrawnAlongTheForce) {
  const auto scene = saltus::testing::particle3d(Eigen::Vector2d::Zero(), 0, 4);
  std::ostringstream warnings;
  const SceneGeometry geometry(scene, warnings);
  RenderSettings settings;
  settings.width = kW;
  settings.height = kH;
  settings.surfaces = false;
  settings.arrow_radius = 0.01;
  Renderer renderer(geometry, settings);
  Camera camera;
  camera.eye = {0, -2, 0};
  camera.target = {0, 0, 0};
  FrameContent frame;
  frame.pose = geometry.pose(Eigen::Vector3d(-0.5, 0, 0));  // the sphere out of the way, left
  frame.arrows.push_back({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 0.4)});  // upwards from the centre
  renderer.draw(camera, frame);
  auto green = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d px = projectByHand(camera, p);
    const std::uint8_t* c = &renderer.rgb()[(static_cast<std::size_t>(px.y()) * kW + static_cast<int>(px.x())) * 3];
    return c[1] > c[0] + 40 && c[1] > c[2] + 40;
  };
  EXPECT_TRUE(green({0, 0, 0.1}));
  EXPECT_TRUE(green({0, 0, 0.3}));
  EXPECT_FALSE(green({0, 0, -0.1}));  // nothing below the tail
  EXPECT_FALSE(green({0.2, 0, 0.2}));
}

TEST(Renderer, GroundAndShadowAreDrawnUnderTheBody) {
  const auto scene = saltus::testing::ballDrop(0.3, 0.5);
  std::ostringstream warnings;
  const SceneGeometry geometry(scene, warnings);
  RenderSettings settings;
  settings.width = kW;
  settings.height = kH;
  settings.light_direction = Eigen::Vector3d::UnitZ();  // shadow straight below
  Renderer renderer(geometry, settings);
  Camera camera;
  camera.eye = {0, -2, 1.2};
  camera.target = {0, 0, 0.15};
  FrameContent frame;
  frame.pose = geometry.pose(Eigen::VectorXd::Constant(1, 0.3));
  renderer.draw(camera, frame);
  auto brightness = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d px = projectByHand(camera, p);
    const std::uint8_t* c = &renderer.rgb()[(static_cast<std::size_t>(px.y()) * kW + static_cast<int>(px.x())) * 3];
    return int(c[0]) + c[1] + c[2];
  };
  // the shadow below the ball is darker than the ground beside it
  EXPECT_LT(brightness({0, 0, 0}) + 60, std::max(brightness({0.15, 0, 0}), brightness({0.15 + 0.125, 0, 0})));
  // ground covers the bottom of the image, not the background colour
  const std::uint8_t* bottom = &renderer.rgb()[(static_cast<std::size_t>(kH - 1) * kW + kW / 2) * 3];
  EXPECT_GT(std::abs(int(bottom[2]) - int(std::lround(255 * settings.background[2]))), 8);
}

}  // namespace
