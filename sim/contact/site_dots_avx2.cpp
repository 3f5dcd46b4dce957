// site_dots.h's AVX2 entry point: compiled with -mavx2 -mno-fma -ffp-contract=off
// (CMakeLists.txt), so that it gives the SSE instance's bits.
#include "sim/contact/site_dots.h"

SHELLMPM_SITE_DOTS_ENTRY(avx2)
