// Static equilibrium of a shell: minimise the potential energy over the free (unpinned)
// degrees of freedom with L-BFGS (Nocedal & Wright 2006, alg. 7.4). The line search
// uses only forces (a secant search for a zero of the directional derivative), so it is
// not misled by round-off in energies.
//
// With a coupling pattern (which points' forces depend on which positions), the initial
// inverse Hessian of L-BFGS is a factorised stiffness matrix instead of a scalar: the
// tangent stiffness is assembled by finite differences of the forces, perturbing many
// points at once (a distance-2 colouring of the coupling graph, Curtis, Powell & Reid
// 1974), and factorised with a sparse LDL^T (shifted towards its diagonal until it is
// positive definite). It is refreshed every `hessian_every` iterations. For a nearly linear
// problem this is Newton's method and converges in a few iterations, where plain L-BFGS
// needs thousands on stiff plates (its iteration count grows with the condition number,
// ~ (L / h)^4 for bending).
//
// Everything runs in double: positions, forces and the solver state.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

struct StaticSolveOptions {
  double tolerance = 1e-6;  ///< stop when max |free force component| < tolerance [N]
  int max_iterations = 1000;
  /// Optional sparsity: coupling[j] lists every point i whose force depends on the
  /// position of point j, j itself included (symmetric for forces from an energy). Empty:
  /// plain L-BFGS with a scalar initial Hessian.
  std::vector<std::vector<int>> coupling;
  int hessian_every = 10;  ///< iterations between stiffness refreshes (with coupling)
  /// Finite-difference step for the stiffness, relative to the bounding-box diagonal of x.
  double fd_step = 1e-8;
  /// Largest move of any coordinate in one iteration, relative to the bounding-box diagonal.
  double max_move = 0.25;
  /// Give up (stalled) when the residual has not fallen below half its best value of
  /// `stall_iterations` iterations ago (e.g. a shell with no pins under gravity).
  int stall_iterations = 500;
};

struct StaticSolveResult {
  int iterations = 0;
  double residual = 0;  ///< max |force component| over free degrees of freedom [N]
  bool converged = false;
  bool stalled = false;  ///< stopped early: no progress in options.stall_iterations
  int force_evaluations = 0;
  int hessian_evaluations = 0;  ///< stiffness assemblies (0 without coupling)
};

/// forces(x, f): total force (internal + external) at positions x into f (sized and
/// zeroed by the solver to x.size()). free_mask[i] bit a set = component a of point i may
/// move; the others keep their values. Stops when the residual < options.tolerance [N] or
/// after options.max_iterations; x holds the last iterate either way.
StaticSolveResult solve_static(
    std::vector<Vec3d>& x, const std::vector<std::uint8_t>& free_mask,
    const std::function<void(const std::vector<Vec3d>&, std::vector<Vec3d>&)>& forces,
    const StaticSolveOptions& options);

}  // namespace shellmpm
