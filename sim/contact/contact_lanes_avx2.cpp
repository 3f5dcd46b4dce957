// contact_lanes.h's AVX2 entry points: compiled with -mavx2 -mno-fma -ffp-contract=off
// (CMakeLists.txt), so that they give the SSE instance's bits.
#include "sim/contact/contact_lanes.h"

SHELLMPM_CONTACT_LANES_ENTRIES(avx2)

namespace shellmpm::contact_lanes {
__attribute__((flatten)) void frames_avx2(FrameLanes& f) {
  frames_body(f);
}
}  // namespace shellmpm::contact_lanes
