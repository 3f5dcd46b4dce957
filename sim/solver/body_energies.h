// The bodies' energies for the energy audit (sim/integrity/energy_audit.h): one entry per
// bulk material, then one per shell, in scene order.
#pragma once
#include <string>
#include <vector>

#include "sim/integrity/energy_audit.h"
#include "sim/solver/step_context.h"

namespace shellmpm {

/// Kinetic, stored and potential energy of each bulk material and each shell now.
std::vector<BodyEnergy> body_energies(const StepContext& c);

/// What shell i stores now: membrane, bending and its contact particles' energy [J].
double shell_stored_energy(const StepContext& c, std::size_t i);

/// The work of loads f (per control point, constant over the step) on a shell whose
/// control points moved by dt v over it: dt sum f . v [J] (0 when f is empty).
double load_work(const std::vector<Vec3d>& f, const std::vector<Vec3>& v, double dt);

}  // namespace shellmpm
