// The implicit steps' collider term on shell control points. A control point that a step
// moves to X_j inside a collider (posed at the end of the step) adds
//   kappa_j phi(X_j)^2 / 2,   kappa_j = kColliderPenalty max(m_j / dt^2, E h),
// to the objective: its inertia over the step or the sheet's membrane stiffness,
// whichever is larger, times 10, so the point ends within about 10% of the depth it
// would have reached without it. (100 held it within 1% and made the can on sand's
// solves take a third more Newton iterations: docs/implicit.md.) Used by the grid solve
// (grid_shells.h: the nodes' constraints reach a control point only through stencil nodes inside
// the collider) and by the shells without contact (shell_step.h: nothing else stops them). The
// projection after the step (particle_projection.h) then puts the point on the surface.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/core/types.h"

namespace shellmpm {

/// The collider penalty's stiffness over max(m / dt^2, E h).
constexpr double kColliderPenalty = 10.0;

struct ColliderPenaltyInput {
  const std::vector<Collider>* colliders = nullptr;  ///< posed for the step; null: none
  const std::vector<Real>* mass = nullptr;           ///< per control point [kg]
  const std::vector<std::uint8_t>* held = nullptr;   ///< pinned components (7: all; skipped)
  double dt = 0;                                     ///< the step [s]
  double membrane = 0;                               ///< E h [N/m]
};

/// The penalty of the control points at X; adds kappa phi n to (*grad)[j] (with grad) and
/// kappa n n^T to (*K)[j] (with K: resized and zeroed first), and the moving colliders'
/// work over the step, the impulse -dt kappa phi n times their velocity, to *work (with
/// work). Returns its energy [J].
double collider_penalty(const ColliderPenaltyInput& in, const std::vector<Vec3d>& X,
                        std::vector<Vec3d>* grad, std::vector<Mat3d>* K, double* work = nullptr);

}  // namespace shellmpm
