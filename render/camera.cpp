#include "render/camera.hpp"

#include <algorithm>
#include <cmath>

namespace saltus::render {

namespace {

// Camera axes in world coordinates: right, up, back (OpenGL looks along −back).
Eigen::Matrix3d cameraAxes(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d back = (eye - target).normalized();
  Eigen::Vector3d right = up.cross(back);
  if (right.norm() < 1e-9) right = Eigen::Vector3d::UnitX().cross(back);  // looking along up
  right.normalize();
  Eigen::Matrix3d R;
  R << right, back.cross(right), back;
  return R;
}

}  // namespace

Eigen::Matrix4d Camera::view() const {
  const Eigen::Matrix3d R_WC = cameraAxes(eye, target, up);  // columns: camera axes in world
  Eigen::Matrix4d V = Eigen::Matrix4d::Identity();
  V.topLeftCorner<3, 3>() = R_WC.transpose();
  V.topRightCorner<3, 1>() = -R_WC.transpose() * eye;
  return V;
}

Eigen::Matrix4d Camera::projection(double aspect) const {
  const double f = 1.0 / std::tan(fov_y / 2);
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = f / aspect;
  P(1, 1) = f;
  P(2, 2) = (far + near) / (near - far);
  P(2, 3) = 2 * far * near / (near - far);
  P(3, 2) = -1;
  return P;
}

Eigen::Vector2d Camera::pixel(const Eigen::Vector3d& p_W, int width, int height, double* depth) const {
  const Eigen::Vector4d clip = projection(double(width) / height) * view() * p_W.homogeneous();
  if (depth) *depth = clip.w();
  const double x_ndc = clip.x() / clip.w(), y_ndc = clip.y() / clip.w();
  return {(x_ndc + 1) / 2 * width, (1 - y_ndc) / 2 * height};
}

double fitDistance(const Bounds& box, const Eigen::Vector3d& center, const Eigen::Vector3d& direction,
                   const Eigen::Vector3d& up, double fov_y, double aspect, double margin) {
  const Eigen::Matrix3d R = cameraAxes(center + direction, center, up);
  const double tan_y = std::tan(fov_y / 2) * margin, tan_x = tan_y * aspect;
  double distance = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1) ? box.hi.x() : box.lo.x(), (corner & 2) ? box.hi.y() : box.lo.y(),
                            (corner & 4) ? box.hi.z() : box.lo.z());
    const Eigen::Vector3d c = R.transpose() * (p - center);  // right, up, back
    // in front at depth distance − back: |right| ≤ tan_x (distance − back), same for up
    distance = std::max({distance, std::abs(c.x()) / tan_x + c.z(), std::abs(c.y()) / tan_y + c.z()});
  }
  return distance;
}

Camera lookFrom(const Eigen::Vector3d& center, const Eigen::Vector3d& direction, double distance, double fov_y,
                double radius) {
  Camera camera;
  camera.target = center;
  camera.eye = center + distance * direction.normalized();
  camera.fov_y = fov_y;
  camera.near = std::max(1e-3, 0.02 * distance);
  camera.far = 4 * (distance + radius) + 10 * radius;
  return camera;
}

}  // namespace saltus::render
