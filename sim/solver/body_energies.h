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

/// Why the scene's frames cannot be audited (an input the audit does not measure:
/// pressure, point loads), or empty.
std::string energy_unjudged_reason(const Scene& scene);

}  // namespace shellmpm
