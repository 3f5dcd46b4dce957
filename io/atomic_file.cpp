#include "io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <stdexcept>
#include <system_error>

namespace shellmpm {
namespace {

[[noreturn]] void throw_errno(const std::string& what, const std::string& path) {
  throw std::system_error(errno, std::generic_category(), what + " '" + path + "'");
}

/// Flushes a file (or directory) to stable storage.
void fsync_path(const std::string& path, bool directory) {
  const int fd = ::open(path.c_str(), directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) {
    if (directory) return;  // some file systems do not allow opening directories
    throw_errno("cannot open for fsync", path);
  }
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  // Directories on some file systems reject fsync with EINVAL; the rename still holds.
  if (rc != 0 && !(directory && (err == EINVAL || err == EBADF))) {
    errno = err;
    throw_errno("cannot fsync", path);
  }
}

std::string parent_dir(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

void write_file_atomic(const std::string& path,
                       const std::function<void(const std::string& tmp_path)>& writer) {
  const std::string tmp = path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  try {
    writer(tmp);
    fsync_path(tmp, false);
    if (std::rename(tmp.c_str(), path.c_str()) != 0) throw_errno("cannot rename onto", path);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  fsync_path(parent_dir(path), true);
}

void write_bytes_atomic(const std::string& path, const void* data, std::size_t size) {
  write_file_atomic(path, [&](const std::string& tmp) {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw_errno("cannot create", tmp);
    const char* p = static_cast<const char*>(data);
    std::size_t left = size;
    while (left > 0) {
      const ssize_t n = ::write(fd, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        const int err = errno;
        ::close(fd);
        errno = err;
        throw_errno("cannot write", tmp);
      }
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0) throw_errno("cannot close", tmp);
  });
}

void write_text_atomic(const std::string& path, const std::string& text) {
  write_bytes_atomic(path, text.data(), text.size());
}

std::string frame_path(const std::string& dir, const std::string& pattern, int frame) {
  const auto first = pattern.find('#');
  if (first == std::string::npos)
    throw std::invalid_argument("file pattern '" + pattern +
                                "' has no '#' run for the frame number");
  auto last = pattern.find_first_not_of('#', first);
  if (last == std::string::npos) last = pattern.size();
  if (pattern.find('#', last) != std::string::npos)
    throw std::invalid_argument("file pattern '" + pattern +
                                "' has more than one '#' run; use exactly one");
  const int width = static_cast<int>(last - first);
  char digits[32];
  std::snprintf(digits, sizeof digits, "%0*d", width, frame);
  std::string name = pattern.substr(0, first) + digits + pattern.substr(last);
  if (dir.empty()) return name;
  if (dir.back() == '/') return dir + name;
  return dir + "/" + name;
}

}  // namespace shellmpm
