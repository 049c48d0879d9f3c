// A camera that frames an axis-aligned bounding box from a chosen direction.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace surfmap {

struct ViewCameraSpec {
  Eigen::Vector3d view_direction = Eigen::Vector3d(0, 1, 0);  // the way the camera looks
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();              // projected to screen up
  bool perspective = false;
  double fov_deg = 30.0;                                      // perspective only
};

class ViewCamera {
 public:
  // Frames `box` (its bounding sphere, so any rotation fits) in a width x height
  // image with a small margin. `spec.view_direction` must be non-zero; an `up`
  // parallel to it is replaced by another world axis.
  static ViewCamera Frame(const Eigen::AlignedBox3d& box, const ViewCameraSpec& spec, int width, int height);

  // (x, y) in pixels (pixel centres at +0.5, y down) and depth along the view
  // direction in mm (larger = farther).
  Eigen::Vector3d Project(const Eigen::Vector3d& p) const;

  // Unit direction from the eye towards `p` (constant for orthographic views).
  Eigen::Vector3d RayDirection(const Eigen::Vector3d& p) const;

  double scene_radius() const { return radius_; }

 private:
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d eye_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d forward_ = Eigen::Vector3d::UnitY();
  Eigen::Vector3d right_ = Eigen::Vector3d::UnitX();
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  bool perspective_ = false;
  double scale_ = 1.0;  // orthographic: px per mm; perspective: focal length in px
  double radius_ = 1.0;
  double half_width_ = 0.0;
  double half_height_ = 0.0;
};

}  // namespace surfmap
