// The batched Kirchhoff-Love kernel on eight lanes: compiled with -mavx2 -mno-fma
// -ffp-contract=off (CMakeLists.txt), so that it gives the SSE instance's bits.
#define SHELLMPM_KL_BATCH_ENTRY eval_batch_avx2
#define SHELLMPM_KL_PATCH_ENTRY eval_patches_avx2
#define SHELLMPM_KL_BATCH_WIDTH 8
#include "sim/shell/kl_batch_body.h"
