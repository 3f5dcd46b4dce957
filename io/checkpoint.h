// Checkpoints: the full solver state at the end of a frame, so `--resume` continues a
// killed run and produces output bit-identical to an uninterrupted one.
//
// File layout (little-endian), format 5 (particle kinds: a material and rest volume each;
// the contact particles' return-mapping states):
//   header   "SHMPMCK5", u32 sizeof(Real), u64 payload size
//   payload  scene fingerprint, frame, time, particles, statistics, shells (checkpoint.cpp)
//   trailer  u32 CRC-32 of header and payload (io/checksum.h), "SHMPMEND"
// A damaged file (any byte changed, truncated, extended) fails the length or checksum
// test; the payload is then still parsed with every count checked against the bytes
// left and every value checked for range, so no file can make the reader or the solver
// read out of bounds.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/user_error.h"
#include "sim/mpm/particles.h"

namespace shellmpm {

struct Checkpoint {
  std::uint64_t scene_fingerprint = 0;  ///< hash of the scene text and overrides
  int frame = 0;                        ///< last frame completed
  double time = 0;                      ///< simulation time [s]
  ParticleSet particles;
  std::string stats_json;  ///< statistics of the frames written so far
  /// Per shell: control point positions, velocities and the denting plastic state.
  struct ShellState {
    std::vector<Vec3> x, v;
    std::vector<Real> plastic;
    std::vector<Mat3> C;    ///< APIC matrices of the control points (contact on; else empty)
    std::vector<Vec3> a3e;  ///< contact particles' normal columns (contact on; else empty)
    std::vector<std::uint8_t> contact_state;  ///< their ContactState after the last step
  };
  std::vector<ShellState> shells;
  double shell_plastic_work = 0;
  double friction_work = 0;
};

/// A checkpoint file that is not intact (damaged, truncated, not a checkpoint, or holding
/// values no run could have written). `--resume` falls back to an older checkpoint.
struct CheckpointDamaged : UserError {
  CheckpointDamaged(const std::string& path, const std::string& what)
      : UserError(path, 0, "", "damaged checkpoint: " + what) {}
};

class Solver;
/// Copies the shells' state from the solver into the checkpoint.
void save_shells(const Solver& solver, Checkpoint& c);

/// Checks that checkpoint `c`, read from `path`, fits `solver` (built from the same scene):
/// material indices within the material table, plastic state where the materials need
/// it, the shells' sizes, a time that belongs to its frame, and positions no run leaves
/// (CheckpointDamaged: a particle outside the domain, a shell point farther from it than
/// the domain's size); then moves the particles,
/// shells and time into the solver. Throws UserError naming `path` when it does not fit
/// (e.g. a mesh file changed since the checkpoint was written).
void restore_checkpoint(Solver& solver, Checkpoint&& c, const std::string& path);

/// Writes atomically; the file records the scalar size so a float build refuses a
/// double checkpoint. Throws std::system_error naming the file on I/O failure.
void write_checkpoint(const std::string& path, const Checkpoint& c);
/// Reads a checkpoint and checks it (see the file layout above): throws CheckpointDamaged
/// naming the file when it cannot be opened, is not a checkpoint, is damaged or holds
/// impossible values (non-finite numbers, non-positive volumes, ids past next_id or used
/// twice, deformation gradients of non-positive determinant, zero contact normals, frame
/// < 1), and UserError when it was written by a build of another precision.
Checkpoint read_checkpoint(const std::string& path);

/// A checkpoint file found in an output directory.
struct CheckpointFile {
  std::string path;
  int frame = 0;  ///< the frame number in its name
};
/// The checkpoints in `dir` named checkpoint.<digits>.bin with a frame in 1..max_frame,
/// newest first. A name whose number does not fit a frame is skipped, with a message
/// naming it in `warnings` (if given). A missing `dir` gives none.
std::vector<CheckpointFile> list_checkpoints(const std::string& dir, int max_frame,
                                             std::vector<std::string>* warnings = nullptr);
/// The newest checkpoint in `dir` (highest frame <= max_frame), or "" if none.
std::string latest_checkpoint(const std::string& dir, int max_frame);
/// FNV-1a 64-bit hash.
std::uint64_t fingerprint(const std::string& text);

}  // namespace shellmpm
