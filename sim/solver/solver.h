// The step loop. The solver sets up the shared StepContext from the scene and runs the
// stages the scene switches on (sim/solver/stages/registry.h), in order, every substep:
// only the effects a scene calls for run (no bulk material means no transfer stages, no
// collider no collider stage, no plastic material no plasticity stage, no emitting source
// no emission stage). Between steps it chooses dt and runs the integrity monitor.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim/core/simulation_error.h"
#include "sim/integrity/energy_audit.h"
#include "sim/integrity/integrity_monitor.h"
#include "sim/solver/energy_trace.h"
#include "sim/solver/frame_stats.h"
#include "sim/solver/stages/stage.h"
#include "sim/solver/step_context.h"

namespace shellmpm {

/// Called after every substep: substep index in the frame, dt taken, time reached.
using SubstepCallback = std::function<void(int, double, double)>;

/// The time a substep of dt from `time` reaches on the way to t_end: t_end itself when
/// the step was the last one planned (`last`) or ends within kTimeSnap dt of it. A step an
/// implicit stage shortened (a retry at half the step) can otherwise leave a round-off
/// remainder: a following step of 1e-17 s, and with it the multi-field contact's overlap
/// recovery at gap / dt, threw a can on sand apart at 1e11 m/s.
double step_end_time(double time, double dt, double t_end, bool last);
constexpr double kTimeSnap = 1e-6;

class Solver {
 public:
  explicit Solver(const Scene& scene, SolverOptions opt = {});

  /// Names of the stages this scene switches on, in execution order.
  std::vector<std::string> stage_names() const;
  /// Advances to absolute time t_end [s] in CFL-limited substeps; returns the frame's stats.
  FrameStats advance_to(double t_end, const SubstepCallback& cb = {});
  /// Computes the energy, momentum and speed entries of a FrameStats for the current state.
  void measure(FrameStats& s) const;
  /// The step the solver would take now, before splitting the remaining frame time.
  double stable_dt() const;  // NaN when a velocity is not finite (diverged)
  /// The integrity checks for the current state without advancing (frame 1); the frame
  /// reports of advance_to carry the crossings seen while advancing.
  IntegrityReport integrity_snapshot();

  double time() const { return c_.time; }
  void set_time(double t) { c_.time = t; }
  ParticleSet& particles() { return c_.particles; }
  const ParticleSet& particles() const { return c_.particles; }
  const SparseGrid& grid() const { return c_.grid; }
  const std::vector<ConstitutiveModel>& models() const { return c_.models; }
  const std::vector<Real>& densities() const { return c_.densities; }
  const std::vector<SourceSampler>& samplers() const { return c_.samplers; }
  const Scene& scene() const { return c_.scene; }
  /// Colliders in scene order (their pose is that of the last step).
  const std::vector<Collider>& colliders() const { return c_.colliders; }
  std::vector<std::unique_ptr<ShellObject>>& shells() { return c_.shells; }
  const std::vector<std::unique_ptr<ShellObject>>& shells() const { return c_.shells; }
  /// Shells whose control points are MPM particles (contact on), in scene order.
  std::vector<GridShell>& grid_shells() { return c_.grid_shells; }
  const std::vector<GridShell>& grid_shells() const { return c_.grid_shells; }
  /// Whether shell i has contact (its control points live on the grid).
  bool shell_on_grid(std::size_t i) const { return c_.contacts[i] != nullptr; }
  /// Contact particles of shell i (null without contact).
  ShellContact* contact(std::size_t i) { return c_.contacts[i].get(); }
  const ShellContact* contact(std::size_t i) const { return c_.contacts[i].get(); }
  /// Work dissipated by sliding friction between shells so far [J] (checkpointed).
  double friction_work() const { return c_.friction_work; }
  void set_friction_work(double w) { c_.friction_work = w; }
  /// Plastic work dissipated by denting so far [J] (part of the checkpointed state).
  double shell_plastic_work() const { return c_.plastic_work; }
  void set_shell_plastic_work(double w) { c_.plastic_work = w; }
  /// Settles the shells to static equilibrium without advancing time (sim/shell/preroll.h)
  /// and makes the settled shape the contact particles' reference. Returns the iteration
  /// or step count; throws SimulationError when the residual does not fall below the
  /// tolerance.
  int preroll(const PrerollSettings& p);

 private:
  struct Slot {
    std::unique_ptr<Stage> stage;
    double seconds = 0;
  };
  /// stable_dt, and the largest particle, shell point or collider speed [m/s].
  double stable_dt(double* vmax) const;
  /// stable_dt, or a SimulationError when it is not finite (diverged) or below
  /// shot.dt_min with more than dt_min of the frame left (`remaining` [s]).
  double checked_stable_dt(double remaining, double* vmax) const;
  /// Sorts the bulk particles by grid block (once per frame, for memory locality).
  void reorder_particles();
  IntegrityView integrity_view() const;
  void setup_contact();

  /// The energy audit's frame (energy_audit.h): the bodies' energies at its start are
  /// those at the last frame's end, measured afresh after a construction or a resume.
  EnergyAudit audit_energy_frame(FrameStats& fs);

  StepContext c_;
  std::vector<Slot> stages_;
  IntegrityMonitor integrity_;
  EnergyTrace trace_;                     ///< SHELLMPM_ENERGY_TRACE (energy_trace.h)
  std::vector<BodyEnergy> energy_start_;  ///< empty: not measured yet
};

}  // namespace shellmpm
