// A pinhole camera: where it looks from, the OpenGL view and projection matrices it gives, the
// pixel a world point lands on, and framing (the distance that fits a box into the image).
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace saltus::render {

struct Camera {
  Eigen::Vector3d eye{0, -3, 1};       // p_WE: camera centre
  Eigen::Vector3d target{0, 0, 0};     // point on the optical axis
  Eigen::Vector3d up{0, 0, 1};         // world direction shown upwards
  double fov_y = 0.6;                  // vertical field of view [rad]
  double near = 0.05, far = 100;       // clipping distances [m]

  // World -> camera (OpenGL eye coordinates: x right, y up, looking along −z).
  Eigen::Matrix4d view() const;
  // Camera -> clip coordinates (gluPerspective) for width/height = aspect.
  Eigen::Matrix4d projection(double aspect) const;
  // The pixel (x right, y down, pixel centres at half-integers: pixel (i, j) spans [i, i+1) ×
  // [j, j+1)) a world point lands on in a width × height image, and its depth in front of the
  // camera [m] (negative behind it).
  Eigen::Vector2d pixel(const Eigen::Vector3d& p_W, int width, int height, double* depth = nullptr) const;
};

// An axis-aligned box; empty until a point is added.
struct Bounds {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  bool empty() const { return !(lo.array() <= hi.array()).all(); }
  void add(const Eigen::Vector3d& p) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
  void add(const Bounds& b) { if (!b.empty()) { add(b.lo); add(b.hi); } }
  void addSphere(const Eigen::Vector3d& c, double r) { add(c - Eigen::Vector3d::Constant(r)); add(c + Eigen::Vector3d::Constant(r)); }
  Eigen::Vector3d center() const { return 0.5 * (lo + hi); }
  Eigen::Vector3d size() const { return hi - lo; }
};

// The distance from `center` along `direction` (towards the camera) at which every corner of
// `box` fits inside the image with `margin` (0.8: the box fills 80 % of the narrower side).
double fitDistance(const Bounds& box, const Eigen::Vector3d& center, const Eigen::Vector3d& direction,
                   const Eigen::Vector3d& up, double fov_y, double aspect, double margin);

// A camera at `center` + distance · direction looking at `center`, with near/far planes that
// hold a scene of radius `radius` around the target.
Camera lookFrom(const Eigen::Vector3d& center, const Eigen::Vector3d& direction, double distance, double fov_y,
                double radius);

}  // namespace saltus::render
