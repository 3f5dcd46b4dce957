// A guard in front of yaml-cpp 0.7 (Debian 12), whose parser never returns, allocating
// without end, when a ',' starts a node outside any flow collection (",", "- ,",
// "---\n,": a stray comma line left by an edit). Found by the scene fuzzer under the
// sanitizer build (`check` killed after 60 s, and 2 minutes in the release build).
#pragma once
#include <string>

namespace shellmpm::scenefile {

/// The 1-based line of the first ',' that stands where a node would start in block context
/// (at a line's start, after '- ' entries or '---'), outside quotes, comments, flow
/// collections and block scalars; 0 when there is none.
int stray_flow_entry_line(const std::string& text);

}  // namespace shellmpm::scenefile
