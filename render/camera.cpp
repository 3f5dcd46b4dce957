#include "render/camera.h"

#include <algorithm>
#include <cmath>

namespace shellmpm {

double Camera::tan_half_fov() const {
  return std::tan(0.5 * fov_deg * M_PI / 180.0);
}

Vec3d Camera::ray_direction(double px, double py) const {
  const double t = tan_half_fov();
  const double x = (2.0 * px / width - 1.0) * t * aspect();
  const double y = (1.0 - 2.0 * py / height) * t;
  return (forward() + x * right() + y * up()).normalized();
}

Eigen::Vector3d Camera::project(const Vec3d& x) const {
  const Vec3d d = x - eye;
  const double z = d.dot(forward());
  const double t = tan_half_fov();
  const double sx = d.dot(right()) / (z * t * aspect());
  const double sy = d.dot(up()) / (z * t);
  return {(sx + 1.0) * 0.5 * width, (1.0 - sy) * 0.5 * height, z};
}

Eigen::Matrix4f Camera::view_matrix() const {
  return view_from_basis<double>(eye, right(), up(), forward()).cast<float>();
}

Eigen::Matrix4f Camera::projection_matrix(double n, double f) const {
  const double t = tan_half_fov();
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 1.0 / (t * aspect());
  p(1, 1) = 1.0 / t;
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2.0 * f * n / (f - n);
  p(3, 2) = -1.0;
  return p.cast<float>();
}

Camera auto_frame(const Vec3d& lo, const Vec3d& hi, int width, int height, double fov_deg,
                  double azimuth_deg, double elevation_deg) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fov_deg = fov_deg;
  c.target = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
  const double half_v = 0.5 * fov_deg * M_PI / 180.0;
  const double half_h = std::atan(std::tan(half_v) * c.aspect());
  const double half = std::min(half_v, half_h);
  const double dist = 1.08 * radius / std::sin(half);
  const double az = azimuth_deg * M_PI / 180.0, el = elevation_deg * M_PI / 180.0;
  const Vec3d dir(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
  c.eye = c.target + dist * dir;
  c.up_hint = Vec3d(0, 1, 0);
  return c;
}

}  // namespace shellmpm
