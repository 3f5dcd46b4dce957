// stress_batch.h's AVX2 entry point: compiled with -mavx2 -ffp-contract=off (CMakeLists.txt).
#define SHELLMPM_STRESS_BATCH_ENTRY run_avx2
#include "sim/mpm/stress_batch_body.h"
