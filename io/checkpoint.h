// Checkpoints: the full solver state at the end of a frame, so `--resume` continues a
// killed run and produces output bit-identical to an uninterrupted one.
#pragma once
#include <cstdint>
#include <string>

#include "sim/mpm/particles.h"

namespace shellmpm {

struct Checkpoint {
  std::uint64_t scene_fingerprint = 0;  ///< hash of the scene text and overrides
  int frame = 0;                        ///< last frame completed
  double time = 0;                      ///< simulation time [s]
  ParticleSet particles;
  std::string stats_json;               ///< statistics of the frames written so far
  /// Per shell: control point positions, velocities and the denting plastic state.
  struct ShellState {
    std::vector<Vec3> x, v;
    std::vector<Real> plastic;
    std::vector<Mat3> C;    ///< APIC matrices of the control points (contact on; else empty)
    std::vector<Vec3> a3e;  ///< contact particles' normal columns (contact on; else empty)
  };
  std::vector<ShellState> shells;
  double shell_plastic_work = 0;
  double friction_work = 0;
};

class Solver;
/// Copies the shells' state from the solver into the checkpoint, and back.
void save_shells(const Solver& solver, Checkpoint& c);
void restore_shells(Solver& solver, const Checkpoint& c);

/// Writes atomically; the file records the scalar size so a float build refuses a
/// double checkpoint.
void write_checkpoint(const std::string& path, const Checkpoint& c);
/// Reads a checkpoint; throws UserError naming the file when it is not one or is damaged.
Checkpoint read_checkpoint(const std::string& path);
/// The newest checkpoint in `dir` (highest frame <= max_frame), or "" if none.
std::string latest_checkpoint(const std::string& dir, int max_frame);
/// FNV-1a 64-bit hash.
std::uint64_t fingerprint(const std::string& text);

}  // namespace shellmpm
