#include "app/frame_range.h"

#include <stdexcept>

#include "io/user_error.h"

namespace shellmpm {
namespace {

/// One frame number: digits only, checked against kMaxFrameNumber before conversion so
/// that no length of digits overflows.
int parse_frame(const std::string& digits) {
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos)
    throw std::invalid_argument("expected A-B or A with whole frame numbers from 1");
  const auto nz = digits.find_first_not_of('0');
  const std::string significant = nz == std::string::npos ? "0" : digits.substr(nz);
  if (significant.size() > 9 || std::stol(significant) > kMaxFrameNumber)
    throw std::invalid_argument("frame " + digits + " is past the largest frame number, " +
                                std::to_string(kMaxFrameNumber));
  const int f = static_cast<int>(std::stol(significant));
  if (f < 1) throw std::invalid_argument("frames start at 1");
  return f;
}

}  // namespace

FrameRange parse_frame_range(const std::string& text) {
  const auto dash = text.find('-');
  FrameRange r;
  r.first = parse_frame(text.substr(0, dash));
  r.last = dash == std::string::npos ? r.first : parse_frame(text.substr(dash + 1));
  if (r.last < r.first)
    throw std::invalid_argument("need 1 <= A <= B (the range ends before it starts)");
  return r;
}

FrameRange parse_frames_flag(const std::string& text) {
  try {
    return parse_frame_range(text);
  } catch (const std::invalid_argument& e) {
    throw UserError("--frames " + text, 0, "", e.what());
  }
}

}  // namespace shellmpm
