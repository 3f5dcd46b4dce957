// shell_blocks.h's AVX-512 entry points: compiled with -march=x86-64-v4 -ffp-contract=off
// (CMakeLists.txt): every a * b + c keeps its two roundings.
#include "sim/contact/shell_blocks.h"

SHELLMPM_SHELL_BLOCKS_ENTRIES(avx512)
