#include "sim/collider/collider.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace shellmpm {
namespace {

Eigen::Quaterniond euler_xyz_deg(const Vec3d& deg) {
  const Vec3d r = deg * (M_PI / 180.0);
  return Eigen::AngleAxisd(r.z(), Vec3d::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3d::UnitY()) *
         Eigen::AngleAxisd(r.x(), Vec3d::UnitX());
}

}  // namespace

RigidPose keyframe_pose(const std::vector<Keyframe>& keys, double t) {
  RigidPose p;
  if (keys.empty()) return p;
  if (keys.size() == 1 || t <= keys.front().time) {
    p.R = euler_xyz_deg(keys.front().rotate_deg).toRotationMatrix();
    p.t = keys.front().translate;
    return p;
  }
  if (t >= keys.back().time) {
    p.R = euler_xyz_deg(keys.back().rotate_deg).toRotationMatrix();
    p.t = keys.back().translate;
    return p;
  }
  const auto it = std::upper_bound(keys.begin(), keys.end(), t,
                                   [](double a, const Keyframe& k) { return a < k.time; });
  const Keyframe& k1 = *it;
  const Keyframe& k0 = *(it - 1);
  const double s = (t - k0.time) / (k1.time - k0.time);
  p.t = (1 - s) * k0.translate + s * k1.translate;
  p.R = euler_xyz_deg(k0.rotate_deg).slerp(s, euler_xyz_deg(k1.rotate_deg)).toRotationMatrix();
  return p;
}

Collider::Collider(const ColliderDesc& desc) : desc_(desc) {
  local_bounds_ = shape_bounds(desc_.shape);
  begin_step(0.0, 0.0);
}

void Collider::begin_step(double t, double dt) {
  start_ = keyframe_pose(desc_.keyframes, t);
  end_ = keyframe_pose(desc_.keyframes, t + dt);
  dt_ = dt;
  bounds_ = local_bounds_;
  if (!bounds_.infinite) {
    Vec3d lo = Vec3d::Constant(1e300), hi = Vec3d::Constant(-1e300);
    for (int c = 0; c < 8; ++c) {
      const Vec3d corner((c & 4) ? local_bounds_.hi.x() : local_bounds_.lo.x(),
                         (c & 2) ? local_bounds_.hi.y() : local_bounds_.lo.y(),
                         (c & 1) ? local_bounds_.hi.z() : local_bounds_.lo.z());
      const Vec3d w = end_.apply(corner);
      lo = lo.cwiseMin(w);
      hi = hi.cwiseMax(w);
    }
    bounds_.lo = lo;
    bounds_.hi = hi;
  }
}

Vec3d Collider::velocity(const Vec3d& x) const {
  if (!animated() || dt_ <= 0) return Vec3d::Zero();
  // The collider point now at x was at start_(end_^-1 x) when the step began.
  return (x - start_.apply(end_.apply_inverse(x))) / dt_;
}

double Collider::max_speed(double t) const {
  if (!animated()) return 0.0;
  const double h = 1e-4;
  const RigidPose a = keyframe_pose(desc_.keyframes, t), b = keyframe_pose(desc_.keyframes, t + h);
  // Rigid velocity is affine in position, so its largest norm over a box is at a corner.
  double vmax = 0;
  auto at = [&](const Vec3d& xl) { vmax = std::max(vmax, (b.apply(xl) - a.apply(xl)).norm() / h); };
  if (local_bounds_.infinite) {
    at(desc_.shape.point);
  } else {
    for (int c = 0; c < 8; ++c)
      at(Vec3d((c & 4) ? local_bounds_.hi.x() : local_bounds_.lo.x(),
               (c & 2) ? local_bounds_.hi.y() : local_bounds_.lo.y(),
               (c & 1) ? local_bounds_.hi.z() : local_bounds_.lo.z()));
  }
  return vmax;
}

bool Collider::apply(const Vec3d& x, Vec3& v) const {
  const Vec3d xl = end_.apply_inverse(x);
  if (shape_phi(desc_.shape, xl) > 0) return false;
  v = resolve(x, end_.R * shape_normal(desc_.shape, xl), v);
  return true;
}

Vec3 Collider::resolve(const Vec3d& x, const Vec3d& n, const Vec3& v) const {
  const Vec3d vc = velocity(x);
  if (desc_.boundary == BoundaryKind::Sticky) return vc.cast<Real>();
  const Vec3d vr = v.cast<double>() - vc;
  const double vn = vr.dot(n);
  if (desc_.boundary == BoundaryKind::Separate && vn >= 0) return v;
  Vec3d vt = vr - vn * n;
  if (vn < 0 && desc_.friction > 0) {
    const double tn = vt.norm();
    const double drop = -desc_.friction * vn;
    vt = tn <= drop ? Vec3d::Zero() : Vec3d(vt * (1 - drop / tn));
  }
  return (vc + vt).cast<Real>();
}

}  // namespace shellmpm
