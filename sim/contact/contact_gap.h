// The distance between two bodies' contact surfaces at a grid node, so that grid contact
// acts where the surfaces meet rather than wherever two B-spline stencils overlap.
//
// Why a gap at the node (displacement-based contact detection): multi-field MPM applies
// Bardenhagen's rule (field_contact.h) wherever two bodies put mass on one node, and a
// quadratic B-spline spreads a body's mass 1.5 dx past it, so bodies stop one to two
// cells apart. Nairn's multi-material MPM (NairnMPM, "displacement check") and Homel and
// Herbold 2017 (field-gradient partitioning, GEOS) keep, per body and node, where that
// body is, and fire contact only when the separation along the contact normal closes.
// We do the same with what each field already sums at a node:
// - a shell: the mass centroid of its control points in the node's stencil, which lies on
//   the shell's surface where the shell is flat over the stencil (exactly, for a plane);
//   its contact surfaces lie half its contact thickness on either side;
// - bulk material: its volume fraction at the node, phi = sum_p w_ip V_p / dx^3, which for
//   material filling a half-space is the share of the node's kernel inside it, a known
//   monotone function of the node's distance to the material's surface (the kernel's
//   cumulative distribution across the surface): inverting it places the surface where
//   the particles' volume ends, half a particle spacing beyond the outermost centres.
// The rule then lets the bodies close by at most the gap within the step (a look-ahead by
// the step's relative motion, so fast and heavy bodies cannot pass between two checks),
// and Coulomb's friction acts on the normal velocity it removes.
#pragma once
#include <algorithm>
#include <cmath>

#include "sim/core/types.h"

namespace shellmpm {

/// The share of a quadratic B-spline kernel centred at a node that lies beyond a plane at
/// signed distance s (in cells) from the node: F(s) = integral_s^1.5 N(u) du, N the 1-D
/// quadratic B-spline. F(-1.5) = 1, F(0) = 1/2, F(1.5) = 0.
inline Real kernel_share_beyond(Real s) {
  if (s < 0) return Real(1) - kernel_share_beyond(-s);
  if (s >= Real(1.5)) return Real(0);
  if (s >= Real(0.5)) {
    const Real a = Real(1.5) - s;
    return a * a * a / Real(6);
  }
  return Real(0.5) - Real(0.75) * s + s * s * s / Real(3);
}

/// The inverse of kernel_share_beyond: the signed distance [cells] from a node to the
/// surface of material that fills a share phi of its kernel (phi in [0, 1]; positive:
/// the node is outside the material). Clamped to [-1.5, 1.5].
inline Real surface_distance_from_share(Real phi) {
  if (!(phi > 0)) return Real(1.5);
  if (phi >= 1) return Real(-1.5);
  if (phi > Real(0.5)) return -surface_distance_from_share(Real(1) - phi);
  if (phi <= Real(1) / Real(6)) return Real(1.5) - std::cbrt(Real(6) * phi);
  // s^3 / 3 - 0.75 s + 0.5 - phi = 0 on [0, 0.5]: Newton from the linear guess (the
  // derivative s^2 - 0.75 stays within [-0.75, -0.5], so four steps reach round-off).
  Real s = (Real(0.5) - phi) / Real(0.75);
  for (int it = 0; it < 4; ++it) {
    const Real f = s * s * s / Real(3) - Real(0.75) * s + Real(0.5) - phi;
    s -= f / (s * s - Real(0.75));
  }
  return std::clamp(s, Real(0), Real(0.5));
}

/// Share of an overlap between two contact surfaces the pair rule undoes per step.
constexpr Real kOverlapRecovery = Real(0.25);
/// The fastest an overlap is undone [1/s]: a share kOverlapRecovery per step, but no more
/// than this share per second (a time constant of 1 ms). The separation is velocity the
/// contact gives the bodies that no force paid for, so it must not grow as the step
/// shrinks: at a stiff shell's explicit step (6e-7 s) a quarter per step would part 0.1 mm
/// of overlap at 40 m/s, and a 0.2 mm steel can crushed onto sand dented from that energy
/// alone (7.2 J unpaid in a frame; 0.01 J dented, balanced, with this cap). Slower
/// recovery lets loaded bodies creep through: at 240/s sand dropped on a cloth at dx/2
/// (steps of 1.4e-4 s) crossed it; at 600/s and 1000/s it did not. Steps of 1/4000 s and
/// longer are unchanged.
constexpr Real kOverlapRecoveryRate = Real(1000);

/// The normal velocity two bodies may still close at within a step of dt [s] when their
/// contact surfaces are `gap` [m] apart at its start: gap / dt while apart; once they
/// overlap, minus a share of the overlap per step, min(kOverlapRecovery / dt,
/// kOverlapRecoveryRate) per second (they separate at least that fast, so an overlap left
/// by one step's round-off or a node's estimate does not accumulate into a creep through
/// the other body; the shell guard stays the backstop). field_contact's `allow`; 0 where
/// the gap is not finite (contact at the stencils).
inline Real closing_allowance(Real gap, Real dt) {
  if (!(dt > 0) || !std::isfinite(gap)) return Real(0);
  if (gap > 0) return gap / dt;
  return std::min(kOverlapRecovery / dt, kOverlapRecoveryRate) * gap;
}

}  // namespace shellmpm
