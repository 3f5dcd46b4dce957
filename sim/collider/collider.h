// Colliders act on grid velocities after the grid update: a node inside a collider
// gets the collider's velocity (sticky), loses its normal relative velocity (slip) or
// loses it only when approaching (separate); Coulomb friction acts on the tangential
// relative velocity (Stomakhin et al. 2013, sec. 8).
#pragma once
#include "sim/collider/shape_sdf.h"
#include "sim/core/types.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// A rigid transform x_world = R x_local + t.
struct RigidPose {
  Mat3d R = Mat3d::Identity();
  Vec3d t = Vec3d::Zero();
  Vec3d apply(const Vec3d& x) const { return R * x + t; }
  Vec3d apply_inverse(const Vec3d& x) const { return R.transpose() * (x - t); }
};

/// Pose at time t from keyframes: linear translation, slerped rotation, held outside.
RigidPose keyframe_pose(const std::vector<Keyframe>& keys, double t);

class Collider {
 public:
  explicit Collider(const ColliderDesc& desc);

  /// Prepares the motion over [t, t + dt]; nodes are resolved against the pose at t + dt.
  void begin_step(double t, double dt);
  /// Signed distance at world x for the pose at the end of the step.
  double phi(const Vec3d& x) const { return shape_phi(desc_.shape, end_.apply_inverse(x)); }
  /// Signed distance at world x for the pose at the start of the step.
  double phi_start(const Vec3d& x) const { return shape_phi(desc_.shape, start_.apply_inverse(x)); }
  /// Outward unit normal at world x for the pose at the end of the step.
  Vec3d normal(const Vec3d& x) const {
    return end_.R * shape_normal(desc_.shape, end_.apply_inverse(x));
  }
  /// Where the collider point now at world x was at the start of the step.
  Vec3d start_of(const Vec3d& x) const { return start_.apply(end_.apply_inverse(x)); }
  /// Where the collider point at world x at the start of the step is at its end.
  Vec3d end_of(const Vec3d& x) const { return end_.apply(start_.apply_inverse(x)); }
  /// Collider velocity at world x over the step [m/s].
  Vec3d velocity(const Vec3d& x) const;
  /// World-space bounds at the end of the step.
  const Aabb& bounds() const { return bounds_; }
  /// Applies the boundary condition to a node velocity at world x; true if in contact.
  bool apply(const Vec3d& x, Vec3& v) const;
  /// The boundary condition on a velocity v at world x in contact, n the outward unit
  /// normal there: sticky takes the collider's velocity; slip and separate (when
  /// approaching) drop the relative normal velocity, with Coulomb friction on the rest.
  Vec3 resolve(const Vec3d& x, const Vec3d& n, const Vec3& v) const;
  bool animated() const { return desc_.keyframes.size() > 1; }
  /// Largest speed of the collider's points at time t [m/s] (for the CFL bound); planes
  /// count their reference point only.
  double max_speed(double t) const;
  const ColliderDesc& desc() const { return desc_; }

 private:
  ColliderDesc desc_;
  Aabb local_bounds_, bounds_;
  RigidPose start_, end_;
  double dt_ = 0;
};

}  // namespace shellmpm
