// transfer_blocks.h's AVX2 entry points: compiled with -mavx2 -mno-fma -ffp-contract=off
// (CMakeLists.txt).
#include "sim/mpm/transfer_blocks.h"

SHELLMPM_TRANSFER_BLOCKS_ENTRIES(avx2)
