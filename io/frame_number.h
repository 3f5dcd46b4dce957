// Frame numbers and times, shared by checkpoints, the shot runner and --frames.
// Frame f holds the state at t = (f - 1) / fps: frame 1 is the initial state.
#pragma once

namespace shellmpm {

/// The largest frame number --frames and checkpoint names accept (9 digits, so frame
/// arithmetic stays far from int's limit).
constexpr int kMaxFrameNumber = 999999999;

/// Time of a frame's state [s].
inline double frame_time(int frame, double fps) {
  return (frame - 1) / fps;
}

}  // namespace shellmpm
