// Particles that end a step inside a collider are put back on its surface (issue 10:
// moving colliders). The grid boundary condition (collider.h) acts on node velocities
// only, and a node reads the collider's velocity only once it is inside: a blade at
// 10 m/s leaves grains 1 dx inside and, where it meets the ground, lets some through.
// After advection each point is checked against every collider at the end of the step:
// - inside: moved along the outward normal to phi = 0;
// - swept: the point's motion relative to the collider over the step (from where the
//   collider-fixed frame had the point at the start to where it is now) is sampled every
//   dx / 2; when a sample lies inside, the collider passed over the point (a thin or fast
//   collider), and the point goes back to the last sample outside, on the side it came
//   from;
// and its velocity loses the normal relative velocity towards the collider (sticky: the
// collider's velocity; Coulomb friction on the tangential part as on the grid).
// A second pass over the colliders for the points the first one moved, so a point pushed
// out of one into another (a blade on the ground) is resolved against both; without the
// sweep, since the velocity has changed and x - dt v is no longer where the point started.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/core/types.h"

namespace shellmpm {

struct ProjectionStats {
  std::size_t inside = 0;  ///< points found inside and moved out
  std::size_t swept = 0;   ///< points a collider passed over, moved back
  /// With ProjectionWork: what the projection supplied [J] (sim/integrity/energy_audit.h):
  /// each point's impulse m (v' - v) times a moving collider's velocity there (a static
  /// collider's impulse does no work), plus the potential energy of moving it, -m g . dx.
  double work = 0;
  std::size_t moving = 0;  ///< points a moving collider moved
};

/// What ProjectionStats::work is measured with.
struct ProjectionWork {
  std::function<double(std::size_t i)> mass;  ///< point i's mass [kg]
  Vec3d gravity{0, 0, 0};                     ///< [m/s^2]
};

/// Projects points x (velocities v, advected over dt with x += dt v) out of the colliders
/// (their begin_step set for this step). held: per point, components a pin prescribes
/// (bit a; may be null): such points are left alone. offset [m]: the points' contact
/// surface lies that far out from them (half a shell's contact thickness), so they are put
/// back at phi = offset. work (may be null): measure what the projection supplies.
ProjectionStats project_out_of_colliders(const std::vector<Collider>& colliders, double dx,
                                         double dt, std::vector<Vec3>& x, std::vector<Vec3>& v,
                                         const std::vector<std::uint8_t>* held, bool serial,
                                         double offset = 0, const ProjectionWork* work = nullptr);

}  // namespace shellmpm
