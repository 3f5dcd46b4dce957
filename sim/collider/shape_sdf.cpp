#include "sim/collider/shape_sdf.h"

#include <algorithm>
#include <cmath>

#include "sim/core/check.h"

namespace shellmpm {
namespace {

double box_phi(const Vec3d& lo, const Vec3d& hi, const Vec3d& p) {
  const Vec3d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
  const Vec3d q = (p - c).cwiseAbs() - h;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return outside + inside;
}

double cylinder_phi(const ShapeDesc& s, const Vec3d& p) {
  const Vec3d d = p - s.center;
  const double along = d.dot(s.axis);
  const double radial = (d - along * s.axis).norm();
  const double qr = radial - s.radius, qa = std::abs(along) - 0.5 * s.height;
  const double outside = std::hypot(std::max(qr, 0.0), std::max(qa, 0.0));
  return outside + std::min(std::max(qr, qa), 0.0);
}

}  // namespace

double shape_phi(const ShapeDesc& s, const Vec3d& p) {
  switch (s.kind) {
    case ShapeDesc::Kind::Plane:
      return (p - s.point).dot(s.normal);
    case ShapeDesc::Kind::Box:
      return box_phi(s.min, s.max, p);
    case ShapeDesc::Kind::Sphere:
      return (p - s.center).norm() - s.radius;
    case ShapeDesc::Kind::Cylinder:
      return cylinder_phi(s, p);
    case ShapeDesc::Kind::Mesh:
      SHELLMPM_CHECK(s.sdf != nullptr, << "mesh shape without a level set: " << s.mesh_path);
      return s.sdf->sample(p);
  }
  return 0.0;
}

Vec3d shape_normal(const ShapeDesc& s, const Vec3d& p) {
  Vec3d g;
  switch (s.kind) {
    case ShapeDesc::Kind::Plane:
      return s.normal;
    case ShapeDesc::Kind::Sphere:
      g = p - s.center;
      break;
    case ShapeDesc::Kind::Mesh:
      g = s.sdf->gradient(p);
      break;
    default: {
      const double h = 1e-5 * std::max(1.0, p.norm());
      for (int a = 0; a < 3; ++a) {
        Vec3d e = Vec3d::Zero();
        e[a] = h;
        g[a] = shape_phi(s, p + e) - shape_phi(s, p - e);
      }
    }
  }
  const double n = g.norm();
  return n > 0 ? Vec3d(g / n) : Vec3d(0, 1, 0);
}

Aabb shape_bounds(const ShapeDesc& s) {
  Aabb b;
  switch (s.kind) {
    case ShapeDesc::Kind::Plane:
      b.infinite = true;
      break;
    case ShapeDesc::Kind::Box:
      b.lo = s.min;
      b.hi = s.max;
      break;
    case ShapeDesc::Kind::Sphere:
      b.lo = s.center.array() - s.radius;
      b.hi = s.center.array() + s.radius;
      break;
    case ShapeDesc::Kind::Cylinder: {
      const double r = s.radius + 0.5 * s.height;
      b.lo = s.center.array() - r;
      b.hi = s.center.array() + r;
      break;
    }
    case ShapeDesc::Kind::Mesh:
      SHELLMPM_CHECK(s.sdf != nullptr, << s.mesh_path);
      b.lo = s.sdf->origin;
      b.hi = s.sdf->origin + s.sdf->spacing * (s.sdf->dims.cast<double>().array() - 1).matrix();
      break;
  }
  return b;
}

}  // namespace shellmpm
