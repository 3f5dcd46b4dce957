// site_dots.h's AVX-512 entry point: compiled with -march=x86-64-v4 -ffp-contract=off
// (CMakeLists.txt): every a * b + c keeps its two roundings.
#include "sim/contact/site_dots.h"

SHELLMPM_SITE_DOTS_ENTRY(avx512)
