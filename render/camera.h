// A pinhole camera shared by both render paths: the same basis, field of view and
// pixel convention (pixel (i, j) covers [i, i+1] x [j, j+1], j counted from the top
// row), so the raster and ray traced images line up pixel for pixel.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "sim/core/types.h"

namespace shellmpm {

struct Camera {
  Vec3d eye{0, 1, 3};
  Vec3d target{0, 0, 0};
  Vec3d up_hint{0, 1, 0};
  double fov_deg = 40.0;  ///< vertical field of view
  int width = 960, height = 540;
  std::string name = "auto";

  Vec3d forward() const { return (target - eye).normalized(); }
  Vec3d right() const { return forward().cross(up_hint).normalized(); }
  Vec3d up() const { return right().cross(forward()); }
  double tan_half_fov() const;
  double aspect() const { return static_cast<double>(width) / height; }

  /// Unit direction of the ray through image position (px, py) (pixels, from the top left).
  Vec3d ray_direction(double px, double py) const;
  /// Image position (pixels, from the top left) of world point x, and its depth along the
  /// view direction (> 0 in front of the camera).
  Eigen::Vector3d project(const Vec3d& x) const;
  /// OpenGL view and projection matrices (column-major, right-handed, camera looks down -z)
  /// for depths in [z_near, z_far].
  Eigen::Matrix4f view_matrix() const;
  Eigen::Matrix4f projection_matrix(double z_near, double z_far) const;
};

/// OpenGL view matrix (right-handed, the camera looks down -z) of an eye with the
/// orthonormal basis right r, up u and forward f; Camera::view_matrix and the raster
/// renderer's light view share it.
template <class S>
Eigen::Matrix<S, 4, 4> view_from_basis(const Eigen::Matrix<S, 3, 1>& eye,
                                       const Eigen::Matrix<S, 3, 1>& r,
                                       const Eigen::Matrix<S, 3, 1>& u,
                                       const Eigen::Matrix<S, 3, 1>& f) {
  Eigen::Matrix<S, 4, 4> m = Eigen::Matrix<S, 4, 4>::Identity();
  m.template block<1, 3>(0, 0) = r.transpose();
  m.template block<1, 3>(1, 0) = u.transpose();
  m.template block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -r.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

/// A camera that frames the box [lo, hi]: it looks at the box center from `azimuth_deg`
/// around +Y (0 = from +Z) and `elevation_deg` above the horizon, far enough that the
/// box's bounding sphere fits the narrower field of view with 8% to spare.
Camera auto_frame(const Vec3d& lo, const Vec3d& hi, int width, int height, double fov_deg = 35.0,
                  double azimuth_deg = 30.0, double elevation_deg = 22.0);

}  // namespace shellmpm
