// Turns sources into particles: a jittered lattice of spacing dx / ppc^(1/3) clipped
// to the shape. Emitting sources move that lattice with the source velocity and
// release lattice points as they leave the shape, so the flow rate is
// rest density * |velocity| * cross-section, independent of the step size.
#pragma once
#include <functional>

#include "sim/collider/shape_sdf.h"
#include "sim/core/types.h"
#include "sim/scene/scene.h"

namespace shellmpm {

class SourceSampler {
 public:
  SourceSampler(const SourceDesc& src, double dx, double fps);

  /// Lattice spacing [m] and the rest volume each particle stands for [m^3].
  double spacing() const { return h_; }
  double particle_volume() const { return h_ * h_ * h_; }
  /// Emission window [s]; fill sources have an empty window.
  double emit_t0() const { return t0_; }
  double emit_t1() const { return t1_; }

  /// Every lattice point inside the shape (fill sources, at the start of the shot).
  void fill(const std::function<void(const Vec3d&)>& out) const;
  /// Lattice points that leave the shape during (t, t + dt], at their position at t + dt.
  void emit(double t, double dt, const std::function<void(const Vec3d&)>& out) const;
  /// Particles fill() would give (for estimates).
  std::size_t count_fill() const;

 private:
  Vec3d point(const Vec3i& ijk, double t) const;
  SourceDesc src_;
  double h_;
  double t0_ = 0, t1_ = -1;
  Aabb bounds_;
};

}  // namespace shellmpm
