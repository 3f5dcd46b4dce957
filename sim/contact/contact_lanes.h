// The contact particles' frames and gradients eight sites at a time, one per lane of a GCC
// vector (contact_frame_parts and contact_gradient_parts, contact_energy.h): the friction
// return mapping's double-precision frames and the contact forces' gradients
// (ShellContact). Their square roots and divisions overlap across the lanes.
//
// The library compiles them for x86-64-v2 (contact_lanes.cpp); contact_lanes_avx2.cpp and
// contact_lanes_avx512.cpp compile the same bodies for wider units, with no contraction
// into fused multiply-adds, and frames() and gradients() pick one at run time
// (simd_level()). Each lane does contact_frame's and contact_gradient's operations on its
// site, so every instruction set gives the bits of the site alone
// (tests/sim/contact/test_contact_lanes.cpp). Internal to sim/contact.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "sim/contact/contact_energy.h"
#include "sim/core/types.h"

namespace shellmpm::contact_lanes {

constexpr int kLanes = 8;
typedef double D __attribute__((vector_size(kLanes * sizeof(double))));
typedef Real R __attribute__((vector_size(kLanes * sizeof(Real))));

/// contact_frame in double: inputs a1, a2, a3e, outputs the frame q and s, each
/// [component][lane] (q[i][component][lane]).
struct FrameLanes {
  D a1[3], a2[3], a3e[3];
  D q[3][3], s[3];
};
/// contact_gradient in Real: inputs a1, a2, a3e, outputs psi and G (g[column][component]
/// [lane]).
struct GradientLanes {
  R a1[3], a2[3], a3e[3];
  R psi, g[3][3];
};

/// Contact sites' stencils, as ShellContact stores them: site p's control points
/// idx[off[p] .. off[p + 1]) with the basis values table[3 (row[p] + k) + 0, 1, 2]
/// (N, dN/dxi1, dN/dxi2) for its k-th; and where their positions and tangents go.
struct SiteStencils {
  const Vec3* ctrl;
  const std::uint32_t *off, *idx, *row;
  const Real* table;
  Vec3 *x, *a1, *a2;
};

/// Fills f's outputs from its inputs.
void frames(FrameLanes& f);
/// Fills g's outputs from its inputs with the contact material p.
void gradients(GradientLanes& g, const ContactParams& p);

template <class V>
[[gnu::always_inline]] inline void lane_sqrt(V& v) {
  for (int j = 0; j < kLanes; ++j) v[j] = std::sqrt(v[j]);
}

[[gnu::always_inline]] inline void frames_body(FrameLanes& f) {
  D r11, r12, r22;
  contact_frame_parts(
      f.a1, f.a2, f.a3e, [](D& v) { lane_sqrt(v); }, f.q, r11, r12, r22, f.s);
}

[[gnu::always_inline]] inline void gradients_body(GradientLanes& g, const ContactParams& p) {
  R q[3][3], r11, r12, r22, s[3];
  contact_frame_parts(
      g.a1, g.a2, g.a3e, [](R& v) { lane_sqrt(v); }, q, r11, r12, r22, s);
  contact_gradient_parts<Real>(q, r11, r12, r22, s, p, g.psi, g.g);
}

/// The per-ISA entry points (contact_lanes_avx2.cpp, contact_lanes_avx512.cpp).
void frames_avx2(FrameLanes& f);  // (also on AVX-512 machines: contact_lanes.cpp)
void gradients_avx2(GradientLanes& g, const ContactParams& p);
void gradients_avx512(GradientLanes& g, const ContactParams& p);
/// x, a1 and a2 of sites [p0, p0 + n) (ShellContact::position_and_tangents, the same
/// operations on each component: its sums on 4-vectors, three of them in one register).
void stencils_avx512(const SiteStencils& s, std::size_t p0, std::size_t n);

}  // namespace shellmpm::contact_lanes

#define SHELLMPM_CONTACT_LANES_ENTRIES(isa)                                                 \
  namespace shellmpm::contact_lanes {                                                       \
  __attribute__((flatten)) void gradients_##isa(GradientLanes& g, const ContactParams& p) { \
    gradients_body(g, p);                                                                   \
  }                                                                                         \
  }
