// Pre-roll: settles shells to static equilibrium under gravity, pins and loads before
// the shot starts, without advancing time. Shells do not touch each other here.
#pragma once
#include <memory>
#include <vector>

#include "sim/scene/scene.h"
#include "sim/shell/shell_object.h"

namespace shellmpm {

/// p.method Static minimises the energy of each shell in double precision
/// (ShellObject::settle; returns the largest iteration count); Dynamic runs damped
/// dynamic relaxation with kinetic damping at step dt (returns the number of steps).
/// The residual criterion of both: max |unpinned force| < p.tolerance x the reference
/// force (the largest control-point weight or point load; 1 N without either).
/// Velocities are zero afterwards. Throws SimulationError when it does not settle.
int settle_shells(std::vector<std::unique_ptr<ShellObject>>& shells, const Vec3d& gravity,
                  double time, double dt, const PrerollSettings& p, bool serial);

}  // namespace shellmpm
