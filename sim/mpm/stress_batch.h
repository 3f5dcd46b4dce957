// The constitutive batch calls (ConstitutiveModelT::kirchhoff_batch, project_batch,
// project_and_kirchhoff_batch: the batched SVD and the models' principal stresses) on the
// widest vector unit the machine has, chosen at run time, so one binary runs on any
// x86-64-v2 machine and uses AVX2 or AVX-512 where they exist.
//
// The same templates are compiled three times: in the library (x86-64-v2: SSE, 8 float
// SVD lanes), in stress_batch_avx2.cpp (-mavx2, 16 lanes) and stress_batch_avx512.cpp
// (-march=x86-64-v4, 32 lanes). Each lane does the same IEEE operations in the same
// order: no fused multiply-adds (-ffp-contract=off; -mavx2 without -mfma; these paths call
// no FMA intrinsic, though Eigen needs -mfma with AVX-512) and exact square roots
// (EIGEN_FAST_MATH=0 everywhere; Eigen's default took the CPU's rsqrt estimate, which
// differs between AVX-512 and SSE and between vendors). So the three give bit-identical
// results: caches, checkpoints and --resume do not depend on the machine's instruction
// set (tests/sim/mpm/test_stress_batch.cpp). The per-ISA entry points are flattened
// (every call inlined), so their objects define no inline function that the linker could
// pick for the other translation units (tools/check-isa-symbols.sh, the isa_symbols test).
//
// Measured (bench/svd_bench, fixed corotated Kirchhoff stress, float, ns per particle,
// 1 thread): 82 with Eigen's rsqrt square roots, 74 exact (SSE), 46 AVX2, 35 AVX-512.
#pragma once
#include <cstddef>

#include "sim/core/types.h"

namespace shellmpm {

template <class T>
struct ConstitutiveModelT;

enum class SimdLevel { Sse = 0, Avx2 = 1, Avx512 = 2 };

/// The widest level this CPU supports.
SimdLevel simd_supported();
/// The level the batch calls use: simd_supported(), lowered by the environment variable
/// SHELLMPM_SIMD (sse, avx2, avx512) or by set_simd_level.
SimdLevel simd_level();
/// Uses at most `level` (clamped to what the CPU supports); for tests and benchmarks.
void set_simd_level(SimdLevel level);
const char* simd_name(SimdLevel level);

namespace stress_batch {

/// The batch calls at the current level for the simulation precision; false: the
/// level is SSE (the caller runs its own, library-compiled code).
bool kirchhoff(const ConstitutiveModelT<Real>& m, const Mat3* F, const Real* plastic, Mat3* tau,
               std::size_t n);
bool project(const ConstitutiveModelT<Real>& m, Mat3* F, Real* plastic, std::size_t n);
bool project_and_kirchhoff(const ConstitutiveModelT<Real>& m, Mat3* F, Real* plastic, Mat3* tau,
                           std::size_t n);

/// The per-ISA entry points (stress_batch_avx2.cpp, stress_batch_avx512.cpp): op 0
/// kirchhoff, 1 project, 2 project_and_kirchhoff.
void run_avx2(int op, const ConstitutiveModelT<Real>& m, Mat3* F, const Real* plastic_in,
              Real* plastic, Mat3* tau, std::size_t n);
void run_avx512(int op, const ConstitutiveModelT<Real>& m, Mat3* F, const Real* plastic_in,
                Real* plastic, Mat3* tau, std::size_t n);

}  // namespace stress_batch
}  // namespace shellmpm
