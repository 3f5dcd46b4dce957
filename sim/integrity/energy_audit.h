// The energy audit: a frame may not end with more energy than it started with plus what
// was supplied to it. A blow-up (a step that injects energy, a contact that pushes
// bodies apart faster than anything drove them) shows as energy nobody supplied, even
// where the bodies end the frame slower than they began it, since the injected energy
// can go straight into denting or friction.
//
// Per body (a bulk material, a shell) the mechanical energy is its kinetic energy plus
// what it stores (bulk: sum V0 psi(F); shell: membrane, bending and its contact
// particles' energy) plus its potential energy in gravity, -m g . x; its dissipation is
// what the frame's denting and sliding friction removed. Supplied over the frame, the
// moving colliders' work, each as the impulse the collider applied times its velocity
// there (a static collider does no work):
// - on grid nodes (explicit: the colliders' stage; with the shells' own fields, each
//   body's impulse under the gate instead of the node's);
// - in implicit steps, the constraint impulses of the grid solve and the collider
//   penalty's impulses on shell control points;
// - through the projection of points out of colliders, plus the potential energy it
//   moves them by and, for a shell a moving collider moved, the change of what it
//   stores;
// the kinetic and potential energy of emitted particles; and the moving pins' work, their
// impulse on the components they hold (what the step's forces, the grid, the implicit
// solve and the shell guard would have given them, made up to the pin's motion) times the
// pin's velocity; and the pressure's and point loads' work, their force times the control
// points' displacement.
// Backward Euler, APIC/MLS transfers, the return mappings of sand, snow and contact,
// inelastic contact and damping only remove energy, so
//   excess = (E_end - E_start) + dissipated - supplied
// is at most round-off in a sound frame. A frame fails the audit when the excess passes
// kEnergyTolerance times the frame's energy scale (the bodies' kinetic and stored energy
// at its start, |potential change|, the dissipation and the supply) plus kEnergyFloor
// times the energy of lifting all mass by one cell: a warning by default
// (shot.on_energy_gain), since the paper's contact model can also turn the compression a
// step reads across a contact into work the audit cannot trace to its source.
#pragma once
#include <string>
#include <vector>

namespace shellmpm {

/// Excess allowed, as a fraction of the frame's energy scale.
constexpr double kEnergyTolerance = 0.25;
/// Excess always allowed, as a fraction of M g0 dx (all mass lifted by one cell in
/// standard gravity).
constexpr double kEnergyFloor = 1e-3;
constexpr double kStandardGravity = 9.80665;  ///< g0 [m/s^2]

/// One body's energies at an instant [J].
struct BodyEnergy {
  std::string name;                  ///< the material (bulk) or shell
  bool shell = false;                ///< a shell, else bulk material
  double kinetic = 0;                ///< sum m |v|^2 / 2
  double stored = 0;                 ///< elastic energy (shells: membrane + bending + contact)
  double membrane = 0, bending = 0;  ///< shells: the parts of `stored` [J]
  double potential = 0;              ///< -sum m g . x
  double mass = 0;                   ///< [kg]
  double total() const { return kinetic + stored + potential; }
};

/// What the audit found over one frame (energies in J).
struct EnergyAudit {
  bool judged = false;     ///< false: the first frame measured, or the bodies changed
  std::string reason;      ///< why not judged (empty when judged)
  double start = 0;        ///< bodies' energy at the frame's start
  double end = 0;          ///< and at its end
  double dissipated = 0;   ///< by denting and friction in the frame
  double supplied = 0;     ///< by colliders, projection and emission in the frame
  double excess = 0;       ///< end - start + dissipated - supplied
  double tolerance = 0;    ///< the excess allowed
  std::string object;      ///< the body whose energy plus dissipation rose most
  double object_gain = 0;  ///< by how much [J]
  bool failed() const { return judged && excess > tolerance; }
};

/// Audits a frame: `start` and `end` the bodies (same order, same names), `dissipated`
/// per body over the frame (same order), `supplied` the frame's supply, `floor` the
/// excess always allowed [J].
EnergyAudit audit_energy(const std::vector<BodyEnergy>& start, const std::vector<BodyEnergy>& end,
                         const std::vector<double>& dissipated, double supplied, double floor);

}  // namespace shellmpm
