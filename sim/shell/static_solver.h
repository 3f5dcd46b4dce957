// Static equilibrium of a shell: minimise the potential energy over the free (unpinned)
// degrees of freedom with L-BFGS (Nocedal & Wright 2006, alg. 7.4). The line search
// uses only forces (a secant search for a zero of the directional derivative), so it is
// not misled by round-off in float energies.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

struct StaticSolveResult {
  int iterations = 0;
  double residual = 0;  ///< max |force component| over free degrees of freedom [N]
  bool converged = false;
};

/// forces(x, f): total force (internal + external) at positions x into f (resized by the
/// caller to x.size()). free_mask[i] bit a set = component a of point i may move.
/// Stops when the residual < tolerance [N] or after max_iterations.
StaticSolveResult solve_static(std::vector<Vec3>& x, const std::vector<std::uint8_t>& free_mask,
                               const std::function<void(const std::vector<Vec3>&, std::vector<Vec3>&)>& forces,
                               double tolerance, int max_iterations);

}  // namespace shellmpm
