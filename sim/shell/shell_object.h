// One shell in a scene: its control points (SoA), Kirchhoff-Love quadrature data,
// pins, loads, and the limit mesh it writes. Shell-only scenes integrate the control
// points directly (symplectic Euler, no grid); with contact (issue 4) the same forces
// go through the MPM grid.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "sim/core/types.h"
#include "sim/scene/scene.h"
#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/limit_mesh.h"
#include "sim/shell/loop_basis.h"
#include "sim/shell/static_solver.h"

namespace shellmpm {

/// Builds the rest control mesh of a shell: procedural or `desc.mesh`, then placed
/// with scale, rotation and translation.
ShellMesh build_shell_rest_mesh(const ShellDesc& desc);

/// The largest stable explicit step of a shell of material m whose shortest control-mesh
/// edge is min_edge [m], for its membrane and bending waves [s] (ShellObject::stable_dt).
double shell_stable_dt(const ShellMaterialDesc& m, double min_edge, double cfl);

/// The shortest edge of a mesh's triangles [m] (infinity without triangles).
double shortest_edge(const ShellMesh& mesh);

class ShellObject {
 public:
  ShellObject(const ShellDesc& desc, const ShellMaterialDesc& mat, ShellMesh rest);

  const std::string& name() const { return desc_.name; }
  std::size_t size() const { return x.size(); }

  /// Internal (elastic) forces plus gravity, pressure and point loads into `f`
  /// (resized). (The energy is not summed: Solver::measure takes it once a frame.)
  void forces(const Vec3d& gravity, std::vector<Vec3>& f, bool serial) const;
  /// Static equilibrium under the elastic forces, gravity, pressure and point loads, with
  /// pinned components held at their pin pose at `time` (pre-roll). Positions, forces
  /// and the solve are in double (a temporary double copy of the Kirchhoff-Love data):
  /// float positions round by ulp(|x|) (1.5e-8 m at 0.2 m from the origin), a membrane
  /// force noise of up to E t ulp(|x|) per control point. Measured on the cantilever of
  /// tests/sim/shell/test_cantilever.cpp (E = 1e7 Pa, t = 2 mm): 1e-4 N at the float-rounded
  /// rest state, with the double kernel as with the float one, 2 to 8 times its nodal tip
  /// loads; so the state itself, not the kernel's arithmetic, must be double.
  /// Newton-like L-BFGS with a finite-difference stiffness (static_solver.h); stops at
  /// max |free force component| < tolerance [N]. Writes x and zeroes v; the plastic
  /// state is kept (no return mapping).
  StaticSolveResult settle(const Vec3d& gravity, double time, double tolerance, int max_iterations,
                           bool serial);
  /// A double copy of the Kirchhoff-Love data with the current plastic state (the
  /// static solve and the implicit step evaluate in double); with `coupling`, also which
  /// points share a quadrature point (coupling[j]: every point whose force depends on j).
  std::unique_ptr<KirchhoffLoveShellT<double>> double_kl(
      std::vector<std::vector<int>>* coupling = nullptr) const;
  /// Copies the current plastic state into a double copy made by double_kl.
  void sync_double_kl(KirchhoffLoveShellT<double>& kl) const;
  /// Gravity, pressure and point loads (no elastic force) at positions `at` into f.
  void external_forces(const Vec3d& gravity, const std::vector<Vec3d>& at,
                       std::vector<Vec3d>& f) const;
  /// The pins over a step from t to t + dt: held[i], the components of point i a pin
  /// holds (0 once its pin is released at t), and target[i], where its pin puts it at t + dt.
  void pin_targets(double t, double dt, std::vector<std::uint8_t>& held,
                   std::vector<Vec3d>& target) const;
  /// One symplectic Euler step with the forces f: damping, pins at time t + dt. Returns
  /// the pins' work, their impulse on the held components times the pin's velocity [J].
  double integrate(const std::vector<Vec3>& f, double t, double dt, bool serial);
  /// Denting return mapping; returns plastic work [J]. No-op without a yield stress.
  double project_plasticity(bool serial);
  bool has_denting() const { return mat_.yield_stress > 0; }
  /// A pressure or point loads (external forces besides gravity).
  bool has_loads() const { return desc_.pressure != 0 || !desc_.point_loads.empty(); }
  /// The loads' forces at the control points now, without gravity [N] (empty without
  /// loads).
  std::vector<Vec3d> load_forces() const;
  /// The largest stable explicit step for this shell's membrane and bending stiffness [s].
  double stable_dt(double cfl) const;
  /// Kinetic energy [J].
  double kinetic_energy() const;
  double max_strain() const { return static_cast<double>(kl_->max_strain(x.data())); }
  /// The output mesh for the current state.
  void output_mesh(std::vector<Vec3>& pos, std::vector<Vec3>& normal) const {
    limit_->evaluate(x.data(), pos, normal);
  }
  /// Velocities [m/s] of the output mesh's vertices (same count and order as
  /// output_mesh): the limit map applied to the control-point velocities v.
  void output_velocity(std::vector<Vec3>& vel) const { limit_->evaluate_velocity(v.data(), vel); }
  const LimitMesh& limit_mesh() const { return *limit_; }
  const ShellDesc& desc() const { return desc_; }
  const ShellMaterialDesc& material() const { return mat_; }
  const LoopBasis& basis() const { return *basis_; }
  const std::vector<Eigen::Vector3i>& triangles() const { return tris_; }
  /// Shortest rest control-mesh edge [m].
  double min_edge() const { return min_edge_; }
  /// The two control points (0-based, as pins.indices) of that edge, the first one met in
  /// triangle order when several are equally short.
  const std::array<int, 2>& min_edge_vertices() const { return min_edge_vertices_; }
  KirchhoffLoveShell& kl() { return *kl_; }
  const KirchhoffLoveShell& kl() const { return *kl_; }

  std::vector<Vec3> x, v;              ///< control point positions and velocities
  std::vector<Real> mass;              ///< lumped masses [kg]
  std::vector<Vec3d> rest;             ///< rest positions
  std::vector<std::uint8_t> pin_mask;  ///< bit a: component a is held
  std::vector<int> pin_of;             ///< which pin holds the point (-1: none)

 private:
  ShellDesc desc_;
  ShellMaterialDesc mat_;
  std::vector<Eigen::Vector3i> tris_;
  std::unique_ptr<LoopBasis> basis_;
  std::unique_ptr<KirchhoffLoveShell> kl_;
  std::unique_ptr<LimitMesh> limit_;
  double min_edge_ = 0;
  std::array<int, 2> min_edge_vertices_{{-1, -1}};
};

}  // namespace shellmpm
