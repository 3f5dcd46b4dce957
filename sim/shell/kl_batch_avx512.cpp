// The batched Kirchhoff-Love kernel on sixteen lanes: compiled with -march=x86-64-v4
// -ffp-contract=off (CMakeLists.txt), so that it gives the SSE instance's bits.
#define SHELLMPM_KL_BATCH_ENTRY eval_batch_avx512
#define SHELLMPM_KL_PATCH_ENTRY eval_patches_avx512
#define SHELLMPM_KL_BATCH_WIDTH 16
#include "sim/shell/kl_batch_body.h"
