// The --frames A-B (or A) flag of `run` and `render`.
#pragma once
#include <string>

#include "io/frame_number.h"  // kMaxFrameNumber

namespace shellmpm {

struct FrameRange {
  int first = 1, last = 1;
};

/// Parses "A-B" or "A" (whole numbers, 1 <= A <= B <= kMaxFrameNumber; any number of
/// digits is checked without overflow). Throws std::invalid_argument saying what is
/// wrong (the caller names the flag and the text).
FrameRange parse_frame_range(const std::string& text);

/// As parse_frame_range, throwing UserError "--frames TEXT: what is wrong" (exit 2).
FrameRange parse_frames_flag(const std::string& text);

}  // namespace shellmpm
