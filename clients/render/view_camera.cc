#include "clients/render/view_camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace surfmap {

ViewCamera ViewCamera::Frame(const Eigen::AlignedBox3d& box, const ViewCameraSpec& spec, int width, int height) {
  ViewCamera cam;
  cam.center_ = box.isEmpty() ? Eigen::Vector3d::Zero().eval() : Eigen::Vector3d(box.center());
  cam.radius_ = box.isEmpty() ? 1.0 : std::max(0.5 * box.diagonal().norm(), 1e-9);
  cam.forward_ = spec.view_direction.normalized();
  Eigen::Vector3d up = spec.up;
  if (up.norm() < 1e-12 || std::abs(up.normalized().dot(cam.forward_)) > 0.999) {
    // Fall back to the world axis least aligned with the view direction.
    Eigen::Index axis;
    cam.forward_.cwiseAbs().minCoeff(&axis);
    up = Eigen::Vector3d::Unit(axis);
  }
  cam.right_ = cam.forward_.cross(up).normalized();
  cam.up_ = cam.right_.cross(cam.forward_);
  cam.perspective_ = spec.perspective;
  cam.half_width_ = 0.5 * width;
  cam.half_height_ = 0.5 * height;
  const double half_extent_px = 0.45 * std::min(width, height);  // 10% margin overall
  if (spec.perspective) {
    const double half_fov = 0.5 * spec.fov_deg * std::numbers::pi / 180.0;
    const double distance = cam.radius_ / std::sin(half_fov);
    cam.eye_ = cam.center_ - distance * cam.forward_;
    cam.scale_ = half_extent_px / std::tan(half_fov);
  } else {
    cam.eye_ = cam.center_ - 2.0 * cam.radius_ * cam.forward_;
    cam.scale_ = half_extent_px / cam.radius_;
  }
  return cam;
}

Eigen::Vector3d ViewCamera::Project(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d d = p - eye_;
  const double depth = d.dot(forward_);
  double x = d.dot(right_);
  double y = d.dot(up_);
  if (perspective_) {
    const double z = std::max(depth, 1e-9);
    x = scale_ * x / z;
    y = scale_ * y / z;
  } else {
    x *= scale_;
    y *= scale_;
  }
  return {half_width_ + x, half_height_ - y, depth};
}

Eigen::Vector3d ViewCamera::RayDirection(const Eigen::Vector3d& p) const {
  if (!perspective_) return forward_;
  const Eigen::Vector3d d = p - eye_;
  const double n = d.norm();
  return n > 0 ? Eigen::Vector3d(d / n) : forward_;
}

}  // namespace surfmap
