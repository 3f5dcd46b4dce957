// Reading back what a `shellmpm run` wrote, for measurements: stats.json per frame, each
// shell's mesh per frame and the particle cache per frame. The study and `converge`
// start their runs with the outputs this reader expects (run_outputs_overrides).
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

/// The `--set` values that make a run write what RunFolder reads: stats.json, binary PLY
/// shell meshes "{name}.####.ply", a particle cache when `particles`, no density volumes,
/// checkpoints or previews.
std::vector<std::string> run_outputs_overrides(bool particles);

/// A finished run's output folder.
class RunFolder {
 public:
  /// Reads DIR/stats.json. @throws std::runtime_error naming the file when it is missing
  /// or holds no frames.
  explicit RunFolder(std::string dir);

  const std::string& dir() const { return dir_; }
  const nlohmann::json& stats() const { return stats_; }
  /// The frames stats.json holds, in order.
  const nlohmann::json& frames() const { return stats_.at("frames"); }
  int first_frame() const;
  int last_frame() const;
  /// Simulation time of a frame's state [s] (stats "time").
  double time(int frame) const;
  /// The stats object of one frame. @throws std::runtime_error when it is not there.
  const nlohmann::json& frame_stats(int frame) const;
  /// A shell's limit-surface vertices at a frame [m] (DIR/NAME.####.ply).
  std::vector<Vec3d> shell_vertices(const std::string& shell, int frame) const;
  /// Bulk particle positions at a frame [m] (DIR/particles.####.ply).
  std::vector<Vec3d> particles(int frame) const;

 private:
  std::string dir_;
  nlohmann::json stats_;
};

}  // namespace shellmpm
