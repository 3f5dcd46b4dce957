#include "sim/contact/site_dots.h"

#include "sim/mpm/stress_batch.h"

namespace shellmpm {

void site_dots_batch(SiteLaneInputs& in, int n, Real dx, bool weighted, Real (&out)[27][kSiteLanes],
                     bool (&any)[kSiteLanes]) {
  switch (simd_level()) {
    case SimdLevel::Avx512:
      site_dots::dots_avx512(in, n, dx, weighted, out, any);
      return;
    case SimdLevel::Avx2:
      site_dots::dots_avx2(in, n, dx, weighted, out, any);
      return;
    case SimdLevel::Sse:
      break;
  }
  site_dots::dots_lanes<site_dots::Lanes>(in, n, dx, weighted, out, any);
}

}  // namespace shellmpm
