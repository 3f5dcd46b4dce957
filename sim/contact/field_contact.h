// Bardenhagen's contact rule between two velocity fields at one grid node (Bardenhagen
// et al. 2000, "Contact algorithm for granular materials"; used by shell_fields.cpp).
#pragma once
#include <algorithm>
#include <cmath>

#include "sim/core/types.h"

namespace shellmpm {

/// The inverse effective mass of a field with mass m at a node, `held` of it pinned (a
/// pinned share is infinitely heavy): (m - held) / m^2. Divided in two steps, since m^2
/// underflows to zero for m below about 1e-19 in float (a node a stencil's far tips reach),
/// which gave inf or NaN; a mass that is not a normal number takes no part (0): its
/// reciprocal would overflow.
inline Real inverse_field_mass(Real m, Real held) {
  if (!std::isnormal(m) || m < 0) return Real(0);
  const Real mm = m * m;
  // Where m^2 is a normal number, the one division as before (same results).
  if (std::isnormal(mm)) return std::max(m - held, Real(0)) / mm;
  return std::max(m - held, Real(0)) / m / m;
}

/// Fields a and b at one node: n the unit normal from a towards b, wa and wb their
/// inverse masses (0: pinned, infinitely heavy), va and vb their velocities. When they
/// approach along n faster than `allow` [m/s] (0: not at all; negative: they must separate
/// at least that fast; contact_gap.h: the gap between their contact surfaces over the
/// step), their relative normal velocity becomes -allow, and their relative tangential velocity
/// drops by `friction` times the normal velocity removed (sticking at zero); the momentum changes
/// are equal and opposite. Separating fields, and fields closing slower than `allow`, keep theirs.
/// Returns whether the rule acted (the bodies touch within the step).
inline bool field_contact(const Vec3& n, Real friction, Real wa, Vec3& va, Real wb, Vec3& vb,
                          Real allow = 0) {
  const Real w = wa + wb;
  if (!(w > 0)) return false;
  const Vec3 u = vb - va;
  const Real un = u.dot(n);
  if (un + allow >= 0) return false;  // separating, or not closing the gap in this step
  Vec3 ut = u - un * n;
  const Real tl = ut.norm();
  const Real drop = -friction * (un + allow);  // the normal velocity removed, times c_F
  ut = tl <= drop ? Vec3::Zero() : Vec3(ut * (1 - drop / tl));
  // allow = 0 (touching) in the same operations as before the gap existed.
  const Vec3 du = allow != 0 ? Vec3(ut - allow * n - u) : Vec3(ut - u);
  va -= (wa / w) * du;
  vb += (wb / w) * du;
  return true;
}

}  // namespace shellmpm
