// The batched Kirchhoff-Love kernel on eight lanes: compiled with -mavx2 -mfma
// -ffp-contract=off (CMakeLists.txt): FMA instructions only where the kernel asks for one
// (kl_lanes.h madd), which the SSE instance computes to the same bits.
#define SHELLMPM_KL_BATCH_ENTRY eval_batch_avx2
#define SHELLMPM_KL_PATCH_ENTRY eval_patches_avx2
#define SHELLMPM_KL_BATCH_WIDTH 8
#include "sim/shell/kl_batch_body.h"
