// Crash-safe file output: every frame and cache file is written to a temporary
// name in the same directory, flushed to disk and renamed over the target, so a
// killed job never leaves a half-written frame (DESIGN.md, output conventions).
#pragma once
#include <cstddef>
#include <functional>
#include <string>

namespace shellmpm {

/// Writes `path` atomically. `writer(tmp_path)` must create and fill `tmp_path`
/// (a sibling "<path>.tmp.<pid>"); the temporary is then fsync'ed and renamed over
/// `path`, and the directory entry is fsync'ed. If `writer` throws, or the flush or
/// rename fails, the temporary is removed, `path` is left as it was, and the
/// exception propagates (I/O failures throw std::system_error naming the path).
void write_file_atomic(const std::string& path,
                       const std::function<void(const std::string& tmp_path)>& writer);

/// Writes `text` to `path` atomically (binary-exact, no newline translation).
void write_text_atomic(const std::string& path, const std::string& text);

/// Writes `size` bytes from `data` to `path` atomically.
void write_bytes_atomic(const std::string& path, const void* data, std::size_t size);

/// The file name of `frame` in a sequence: the run of '#' in `pattern` is replaced by
/// the frame number zero-padded to the run's length (wider numbers are not cut), and
/// the result is joined to `dir` (empty `dir`: no directory).
/// Example: frame_path("out", "density.####.vdb", 7) == "out/density.0007.vdb".
/// Throws std::invalid_argument when `pattern` has no '#' or more than one run of them.
std::string frame_path(const std::string& dir, const std::string& pattern, int frame);

}  // namespace shellmpm
