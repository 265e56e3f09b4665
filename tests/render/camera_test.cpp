// The camera's projection against the pinhole model written out by hand, and framing.
#include "render/camera.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace {

using saltus::render::Bounds;
using saltus::render::Camera;

// Pinhole projection from first principles: camera axes from the look-at construction, focal
// length in pixels f = (H/2) / tan(fov_y/2), image y downwards, origin at the top-left corner.
Eigen::Vector2d pinholePixel(const Camera& c, const Eigen::Vector3d& p, int W, int H) {
  const Eigen::Vector3d forward = (c.target - c.eye).normalized();
  const Eigen::Vector3d right = forward.cross(c.up).normalized();
  const Eigen::Vector3d up = right.cross(forward);
  const Eigen::Vector3d d = p - c.eye;
  const double f = (H / 2.0) / std::tan(c.fov_y / 2);
  const double depth = d.dot(forward);
  return {W / 2.0 + f * d.dot(right) / depth, H / 2.0 - f * d.dot(up) / depth};
}

TEST(Camera, TargetProjectsToTheImageCentre) {
  Camera c;
  c.eye = {1, -4, 2};
  c.target = {0.2, 0.1, 0.3};
  const Eigen::Vector2d px = c.pixel(c.target, 160, 120);
  EXPECT_NEAR(px.x(), 80, 1e-9);
  EXPECT_NEAR(px.y(), 60, 1e-9);
}

TEST(Camera, PixelMatchesThePinholeModel) {
  Camera c;
  c.eye = {0.7, -3, 1.2};
  c.target = {0, 0.2, 0.3};
  c.fov_y = 0.8;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.4, 0.1, 0.5), Eigen::Vector3d(-0.6, 0.5, -0.2),
                                   Eigen::Vector3d(0.1, -1, 1.1)}) {
    double depth = 0;
    const Eigen::Vector2d px = c.pixel(p, 160, 120, &depth);
    const Eigen::Vector2d expected = pinholePixel(c, p, 160, 120);
    EXPECT_NEAR(px.x(), expected.x(), 1e-9);
    EXPECT_NEAR(px.y(), expected.y(), 1e-9);
    EXPECT_NEAR(depth, (p - c.eye).dot((c.target - c.eye).normalized()), 1e-9);
  }
}

TEST(Camera, WorldUpIsImageUp) {
  Camera c;
  c.eye = {0, -3, 0};
  c.target = {0, 0, 0};
  EXPECT_LT(c.pixel({0, 0, 0.5}, 160, 120).y(), 60);  // above the target: higher in the image (smaller y)
  EXPECT_GT(c.pixel({0.5, 0, 0}, 160, 120).x(), 80);  // +x is to the right when looking along +y
}

TEST(Camera, FitDistancePutsEveryCornerInsideTheMargin) {
  Bounds box;
  box.add({-0.3, -0.1, 0});
  box.add({0.9, 0.2, 1.4});
  const Eigen::Vector3d direction = Eigen::Vector3d(0.35, -1, 0.4).normalized();
  const double fov = 0.6, margin = 0.8;
  const int W = 320, H = 180;
  const double d = saltus::render::fitDistance(box, box.center(), direction, Eigen::Vector3d::UnitZ(), fov,
                                               double(W) / H, margin);
  const Camera c = saltus::render::lookFrom(box.center(), direction, d, fov, 1.0);
  double widest = 0;  // largest |offset| / half-size over corners and image axes
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1) ? box.hi.x() : box.lo.x(), (corner & 2) ? box.hi.y() : box.lo.y(),
                            (corner & 4) ? box.hi.z() : box.lo.z());
    const Eigen::Vector2d px = c.pixel(p, W, H);
    widest = std::max({widest, std::abs(px.x() - W / 2.0) / (W / 2.0), std::abs(px.y() - H / 2.0) / (H / 2.0)});
  }
  EXPECT_LE(widest, margin + 1e-9);
  EXPECT_GT(widest, margin - 1e-6);  // tight: some corner touches the margin
}

}  // namespace
