// The key a line of a YAML file belongs to, read from indentation alone, for the messages
// of syntax errors (the text does not parse, so yaml-cpp cannot say).
#pragma once
#include <string>

namespace shellmpm {

/// The key path, as the scene reader names keys ("materials[1].shape.radius"), of the
/// last mapping key that starts at or before `line` (1-based) of `text`, with the keys
/// above it by indentation and the index of each list item on the way. Only the first
/// key of a line counts (keys inside a flow mapping `{a: 1, b: 2}` are not split out).
/// Empty when no key starts at or before the line.
std::string yaml_key_near_line(const std::string& text, int line);

}  // namespace shellmpm
