// Crash-safe file output: every frame and cache file is written to a temporary
// name in the same directory, flushed to disk and renamed over the target, so a
// killed job never leaves a half-written frame (DESIGN.md, output conventions), and a
// failed write (disk full, quota, file size limit) never leaves a truncated file under
// the target's name: every write, the flush, the fsync and the close are checked before
// the rename, and the temporary is removed on any failure.
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <ostream>
#include <string>

namespace shellmpm {

/// A new file written through a buffered, checked file descriptor. The first failure of
/// any write, seek or flush is remembered with its errno (later writes are dropped), and
/// close() throws it, so a writer that ignores stream errors (OpenVDB's archive does)
/// cannot hide a short write. stream() is a seekable std::ostream onto the file.
class CheckedFile {
 public:
  /// Creates (or truncates) `path`. Throws std::system_error naming it on failure.
  explicit CheckedFile(const std::string& path);
  ~CheckedFile();  ///< closes the descriptor if close() was not called; never throws
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;

  std::ostream& stream();
  /// Appends `size` bytes.
  void write(const void* data, std::size_t size);
  /// Flushes, fsyncs and closes. Throws std::system_error naming the file with the
  /// errno of the first failure since it was created (write, seek, flush, fsync, close).
  void close();

 private:
  class Buffer;
  std::string path_;
  std::unique_ptr<Buffer> buf_;
  std::unique_ptr<std::ostream> stream_;
};

/// Writes `path` atomically: `fill(out)` writes the contents into a CheckedFile on a
/// sibling temporary "<path>.tmp.<pid>", which is then closed (every failure checked),
/// renamed over `path`, and the directory entry fsync'ed. If `fill` throws or any write,
/// flush, fsync, close or the rename fails, the temporary is removed, `path` is left as
/// it was, and the exception propagates (I/O failures throw std::system_error naming
/// the file).
void write_stream_atomic(const std::string& path,
                         const std::function<void(CheckedFile& out)>& fill);

/// Writes `path` atomically for writers that open the file themselves (libpng on a
/// FILE*): `writer(tmp_path)` must create, fill, check and close `tmp_path` (a sibling
/// "<path>.tmp.<pid>"); the temporary is then fsync'ed and renamed over `path`, and the
/// directory entry is fsync'ed. Failures as for write_stream_atomic. Prefer
/// write_stream_atomic, which checks the writes itself.
void write_file_atomic(const std::string& path,
                       const std::function<void(const std::string& tmp_path)>& writer);

/// Writes `text` to `path` atomically (binary-exact, no newline translation).
void write_text_atomic(const std::string& path, const std::string& text);

/// Writes `size` bytes from `data` to `path` atomically.
void write_bytes_atomic(const std::string& path, const void* data, std::size_t size);

/// The temporary name write_stream_atomic and write_file_atomic use for `path`.
std::string atomic_temp_path(const std::string& path);

/// True for the name of a temporary an atomic write leaves behind when the process is
/// killed: "<name>.tmp.<digits>", optionally followed by one ".<extension>".
bool is_atomic_temp_name(const std::string& filename);

/// Removes the leftover temporaries (is_atomic_temp_name) directly inside `dir` (not
/// recursively). Returns how many were removed; a missing `dir` removes none.
int remove_atomic_temps(const std::string& dir);

/// The file name of `frame` in a sequence: the run of '#' in `pattern` is replaced by
/// the frame number zero-padded to the run's length (wider numbers are not cut), and
/// the result is joined to `dir` (empty `dir`: no directory).
/// Example: frame_path("out", "density.####.vdb", 7) == "out/density.0007.vdb".
/// Throws std::invalid_argument when `pattern` has no '#' or more than one run of them.
std::string frame_path(const std::string& dir, const std::string& pattern, int frame);

}  // namespace shellmpm
