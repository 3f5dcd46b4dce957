// stress_batch.h's AVX-512 entry point: compiled with -march=x86-64-v4 -ffp-contract=off
// (CMakeLists.txt; Eigen needs FMA with AVX-512, and no contraction keeps a * b + c two
// roundings).
#define SHELLMPM_STRESS_BATCH_ENTRY run_avx512
#include "sim/mpm/stress_batch_body.h"
