#include "sim/contact/site_dots.h"

namespace shellmpm {

void site_dots_batch(SiteLaneInputs& in, int n, Real dx, bool weighted, Real (&out)[27][kSiteLanes],
                     bool (&any)[kSiteLanes]) {
  site_dots::dots_lanes<site_dots::Lanes>(in, n, dx, weighted, out, any);
}

}  // namespace shellmpm
