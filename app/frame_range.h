// The --frames A-B (or A) flag of `run` and `render`.
#pragma once
#include <string>

#include "io/shot_runner.h"  // kMaxFrameNumber

namespace shellmpm {

struct FrameRange {
  int first = 1, last = 1;
};

/// Parses "A-B" or "A" (whole numbers, 1 <= A <= B <= kMaxFrameNumber). Throws
/// std::invalid_argument with a message that says what is wrong and quotes `text`
/// (the caller adds the flag).
FrameRange parse_frame_range(const std::string& text);

}  // namespace shellmpm
