// The peak memory of `shellmpm run` for a scene, before anything of it is allocated: the
// solver (sim/solver/memory_estimate.h), the largest transient of the frame writers (the
// density VDB, the particle cache, a checkpoint, the shell meshes) and what the process
// already holds (libraries, the scene, mesh level sets). `check` prints it; `run` refuses
// a scene whose estimate exceeds the available memory (shot/available_memory.h).
#pragma once
#include <string>

#include "sim/solver/memory_estimate.h"

namespace shellmpm {

struct RunMemory {
  SolverMemory solver;
  double baseline = 0;  ///< the process before the solver is built [bytes]
  double writers = 0;   ///< the largest writer's transient [bytes]
  std::string writer;   ///< which writer that is ("density VDB", "checkpoint", ...)
  /// The estimated peak resident size of the run [bytes]: baseline + what a run touches
  /// of its libraries beyond check (8 MiB) + the larger of the
  /// solver's construction and what it holds plus the larger of a step's scratch and the
  /// writers' transient (the writers run between steps).
  double peak = 0;
};

/// The estimate for `scene` (meshes loaded). `baseline`: the process's resident bytes now
/// (resident_bytes()), or any figure for tests.
RunMemory estimate_run_memory(const Scene& scene, double baseline);

}  // namespace shellmpm
