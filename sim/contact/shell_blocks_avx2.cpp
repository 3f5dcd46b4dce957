// shell_blocks.h's AVX2 entry points: compiled with -mavx2 -mno-fma -ffp-contract=off
// (CMakeLists.txt), so that they give the SSE instance's bits.
#include "sim/contact/shell_blocks.h"

SHELLMPM_SHELL_BLOCKS_ENTRIES(avx2)
