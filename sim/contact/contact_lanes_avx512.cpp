// contact_lanes.h's AVX-512 entry points: compiled with -march=x86-64-v4 -ffp-contract=off
// (CMakeLists.txt): every a * b + c keeps its two roundings.
#include "sim/contact/contact_lanes.h"

SHELLMPM_CONTACT_LANES_ENTRIES(avx512)
