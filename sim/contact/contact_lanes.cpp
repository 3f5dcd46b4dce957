#include "sim/contact/contact_lanes.h"

#include "sim/mpm/stress_batch.h"

namespace shellmpm::contact_lanes {

void frames(FrameLanes& f) {
  // (The AVX2 body on AVX-512 machines too: measured faster there, 9.5 against 10.7 ms per
  // step of friction in bench/contact_throughput, its eight doubles in two registers.)
  switch (simd_level()) {
    case SimdLevel::Avx512:
    case SimdLevel::Avx2:
      return frames_avx2(f);
    case SimdLevel::Sse:
      break;
  }
  frames_body(f);
}

void gradients(GradientLanes& g, const ContactParams& p) {
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return gradients_avx512(g, p);
    case SimdLevel::Avx2:
      return gradients_avx2(g, p);
    case SimdLevel::Sse:
      break;
  }
  gradients_body(g, p);
}

}  // namespace shellmpm::contact_lanes
