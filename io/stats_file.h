// The per-run statistics file (JSON): one object per written frame. Everything in it
// is deterministic except the "wall" object (wall-clock seconds per stage).
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "sim/solver/frame_stats.h"

namespace shellmpm {

/// The JSON object for one frame.
nlohmann::json frame_stats_json(const FrameStats& s);

/// Accumulates frames and rewrites the file atomically after each one.
class StatsFile {
 public:
  StatsFile(std::string path, nlohmann::json header);
  void add(const FrameStats& s);
  /// Replaces the frames (when resuming from a checkpoint).
  void set_frames(nlohmann::json frames) { frames_ = std::move(frames); }
  const nlohmann::json& frames() const { return frames_; }
  void write() const;

 private:
  std::string path_;
  nlohmann::json header_;
  nlohmann::json frames_ = nlohmann::json::array();
};

}  // namespace shellmpm
