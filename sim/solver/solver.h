// The step loop. The solver assembles its stages from the scene (only the effects a
// scene calls for run): no bulk material means no transfer stages, no collider means
// no collider stage, no plastic material means no plasticity stage, no emitting source
// means no emission stage.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/contact/shell_fields.h"
#include "sim/contact/shell_transfer.h"
#include "sim/integrity/integrity_monitor.h"
#include "sim/mpm/constitutive.h"
#include "sim/mpm/particles.h"
#include "sim/mpm/sparse_grid.h"
#include "sim/mpm/transfer.h"
#include "sim/scene/scene.h"
#include "sim/solver/frame_stats.h"
#include "sim/shell/shell_object.h"
#include "sim/solver/source_sampler.h"

namespace shellmpm {

/// Raised when the simulation cannot go on (e.g. the step needed falls below dt_min).
struct SimulationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SolverOptions {
  bool serial = false;     ///< no threads (tests compare against parallel runs)
  bool fill_sources = true;  ///< sample fill sources at construction (off when resuming)
};

/// Called after every substep: substep index in the frame, dt taken, time reached.
using SubstepCallback = std::function<void(int, double, double)>;

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

  double time() const { return time_; }
  void set_time(double t) { time_ = t; }
  ParticleSet& particles() { return particles_; }
  const ParticleSet& particles() const { return particles_; }
  const SparseGrid& grid() const { return grid_; }
  const std::vector<ConstitutiveModel>& models() const { return models_; }
  const std::vector<Real>& densities() const { return densities_; }
  const std::vector<SourceSampler>& samplers() const { return samplers_; }
  const Scene& scene() const { return scene_; }
  /// Colliders in scene order (their pose is that of the last step).
  const std::vector<Collider>& colliders() const { return colliders_; }
  std::vector<std::unique_ptr<ShellObject>>& shells() { return shells_; }
  const std::vector<std::unique_ptr<ShellObject>>& shells() const { return shells_; }
  /// Shells whose control points are MPM particles (contact on), in scene order.
  std::vector<GridShell>& grid_shells() { return grid_shells_; }
  const std::vector<GridShell>& grid_shells() const { return grid_shells_; }
  /// Whether shell i has contact (its control points live on the grid).
  bool shell_on_grid(std::size_t i) const { return contacts_[i] != nullptr; }
  /// Contact particles of shell i (null without contact).
  ShellContact* contact(std::size_t i) { return contacts_[i].get(); }
  const ShellContact* contact(std::size_t i) const { return contacts_[i].get(); }
  /// Work dissipated by sliding friction between shells so far [J] (checkpointed).
  double friction_work() const { return friction_work_; }
  void set_friction_work(double w) { friction_work_ = w; }
  /// Plastic work dissipated by denting so far [J] (part of the checkpointed state).
  double shell_plastic_work() const { return plastic_work_; }
  void set_shell_plastic_work(double w) { plastic_work_ = w; }
  /// Settles the shells to static equilibrium without advancing time: p.method Static
  /// minimises the energy of each shell in double precision (ShellObject::settle; returns
  /// the largest iteration count), Dynamic runs damped dynamic relaxation with kinetic
  /// damping (returns the number of steps). Velocities are zero afterwards.
  /// Throws SimulationError when the residual does not fall below the tolerance.
  int preroll(const PrerollSettings& p);

 private:
  struct Stage {
    std::string name;
    std::function<void()> run;
    double seconds = 0;
  };
  void build_stages();
  /// stable_dt, and the largest particle, shell point or collider speed [m/s].
  double stable_dt(double* vmax) const;
  IntegrityView integrity_view() const;
  void add_particles_from(std::size_t source, const std::vector<Vec3d>& pts);
  void step(double dt);
  void grid_update();
  void apply_colliders();
  void project_plasticity();
  void emit();
  void clamp_to_domain();
  void setup_contact();
  int settle_shells(const PrerollSettings& p);
  void apply_walls();
  /// Nodes where shells keep one shared velocity: walls and colliders.
  bool single_velocity_node(const Vec3i& n) const;
  void add_grid_stages();
  TransferParams transfer_params();

  Scene scene_;
  SolverOptions opt_;
  std::vector<ConstitutiveModel> models_;
  std::vector<Real> densities_;
  std::vector<SourceSampler> samplers_;
  std::vector<Collider> colliders_;
  ParticleSet particles_;
  SparseGrid grid_;
  std::vector<Stage> stages_;
  std::vector<std::unique_ptr<ShellObject>> shells_;
  std::vector<std::vector<Vec3>> shell_forces_;
  std::vector<std::unique_ptr<ShellContact>> contacts_;  ///< per shell; null: no contact
  std::vector<GridShell> grid_shells_;
  ShellFields shell_fields_;  ///< per-shell velocities on shared nodes (two or more shells)
  ShellPointTable shell_table_;
  std::vector<Vec3> shell_points_;  ///< binned positions of the grid shells' points
  ContactStepStats contact_step_;   ///< the last step's return mapping
  IntegrityMonitor integrity_;
  double friction_work_ = 0;
  double shell_dt_ = 1e300;
  double plastic_work_ = 0;
  double time_ = 0, dt_ = 0;
  Vec3i domain_cells_{0, 0, 0};
  bool any_plastic_ = false, any_emit_ = false;
};

}  // namespace shellmpm
