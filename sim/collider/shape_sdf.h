// Signed distance (negative inside) of the analytic and sampled shapes that sources
// and colliders use, in the shape's own frame.
#pragma once
#include "sim/core/types.h"
#include "sim/scene/scene.h"

namespace shellmpm {

struct Aabb {
  Vec3d lo{0, 0, 0}, hi{0, 0, 0};
  bool infinite = false;  ///< planes
  bool overlaps(const Aabb& o) const {
    if (infinite || o.infinite) return true;
    for (int a = 0; a < 3; ++a)
      if (hi[a] < o.lo[a] || o.hi[a] < lo[a]) return false;
    return true;
  }
};

/// Signed distance from p to the shape surface [m]; negative inside.
double shape_phi(const ShapeDesc& s, const Vec3d& p);
/// Outward unit normal at p (gradient of phi).
Vec3d shape_normal(const ShapeDesc& s, const Vec3d& p);
/// Bounding box of the shape's interior (planes are infinite).
Aabb shape_bounds(const ShapeDesc& s);

}  // namespace shellmpm
