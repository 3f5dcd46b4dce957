#include "io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <streambuf>
#include <system_error>
#include <vector>

namespace shellmpm {
namespace {

[[noreturn]] void throw_errno(int err, const std::string& what, const std::string& path) {
  throw std::system_error(err, std::generic_category(), what + " '" + path + "'");
}

/// Flushes a file (or directory) to stable storage.
void fsync_path(const std::string& path, bool directory) {
  const int fd = ::open(path.c_str(), directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) {
    if (directory) return;  // some file systems do not allow opening directories
    throw_errno(errno, "cannot open for fsync", path);
  }
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  // Directories on some file systems reject fsync with EINVAL; the rename still holds.
  if (rc != 0 && !(directory && (err == EINVAL || err == EBADF)))
    throw_errno(err, "cannot fsync", path);
}

std::string parent_dir(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

void rename_over(const std::string& tmp, const std::string& path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw_errno(errno, "cannot rename onto", path);
  fsync_path(parent_dir(path), true);
}

}  // namespace

/// A put area over a file descriptor. A failed write or seek records errno (the first
/// one wins) and makes every later operation fail, so the stream goes bad and stays so.
class CheckedFile::Buffer : public std::streambuf {
 public:
  explicit Buffer(int fd) : fd_(fd), data_(1 << 16) { reset(); }
  int fd() const { return fd_; }
  int error() const { return error_; }
  void set_error(int err) {
    if (error_ == 0) error_ = err != 0 ? err : EIO;
  }
  /// Writes the buffered bytes out; false after any failure.
  bool drain() {
    if (error_ != 0) return false;
    const char* p = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    reset();
    return write_fd(p, left);
  }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (error_ != 0) return 0;
    if (n <= 0) return 0;  // an empty write (s may be null: memcpy must not see it)
    const auto room = epptr() - pptr();
    if (n <= room) {
      std::memcpy(pptr(), s, static_cast<std::size_t>(n));
      pbump(static_cast<int>(n));
      return n;
    }
    if (!drain() || !write_fd(s, static_cast<std::size_t>(n))) return 0;
    return n;
  }
  int sync() override { return drain() ? 0 : -1; }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
    if (!drain()) return pos_type(off_type(-1));
    const int whence = dir == std::ios_base::beg   ? SEEK_SET
                       : dir == std::ios_base::cur ? SEEK_CUR
                                                   : SEEK_END;
    const off_t r = ::lseek(fd_, static_cast<off_t>(off), whence);
    if (r < 0) {
      set_error(errno);
      return pos_type(off_type(-1));
    }
    return pos_type(off_type(r));
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }

 private:
  void reset() { setp(data_.data(), data_.data() + data_.size()); }
  bool write_fd(const char* p, std::size_t left) {
    while (left > 0) {
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        set_error(errno);
        return false;
      }
      if (n == 0) {  // no progress and no errno: treat as an I/O error, never spin
        set_error(EIO);
        return false;
      }
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    return true;
  }

  int fd_;
  std::vector<char> data_;
  int error_ = 0;
};

CheckedFile::CheckedFile(const std::string& path) : path_(path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_errno(errno, "cannot create", path);
  buf_ = std::make_unique<Buffer>(fd);
  stream_ = std::make_unique<std::ostream>(buf_.get());
}

CheckedFile::~CheckedFile() {
  if (buf_ && buf_->fd() >= 0 && stream_) ::close(buf_->fd());
}

std::ostream& CheckedFile::stream() {
  return *stream_;
}

void CheckedFile::write(const void* data, std::size_t size) {
  stream_->write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void CheckedFile::close() {
  if (!stream_) throw std::logic_error("CheckedFile::close called twice for '" + path_ + "'");
  stream_->flush();
  buf_->drain();
  if (buf_->error() == 0 && stream_->fail()) buf_->set_error(EIO);  // a stream-level failure
  if (buf_->error() == 0 && ::fsync(buf_->fd()) != 0) buf_->set_error(errno);
  const int fd = buf_->fd();
  stream_.reset();  // the descriptor is closed below, once
  if (::close(fd) != 0) buf_->set_error(errno);
  if (buf_->error() != 0) throw_errno(buf_->error(), "cannot write", path_);
}

void write_stream_atomic(const std::string& path,
                         const std::function<void(CheckedFile& out)>& fill) {
  const std::string tmp = atomic_temp_path(path);
  try {
    CheckedFile out(tmp);
    fill(out);
    out.close();
    rename_over(tmp, path);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

void write_file_atomic(const std::string& path,
                       const std::function<void(const std::string& tmp_path)>& writer) {
  const std::string tmp = atomic_temp_path(path);
  try {
    writer(tmp);
    fsync_path(tmp, false);
    rename_over(tmp, path);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

void write_bytes_atomic(const std::string& path, const void* data, std::size_t size) {
  write_stream_atomic(path, [&](CheckedFile& out) { out.write(data, size); });
}

void write_text_atomic(const std::string& path, const std::string& text) {
  write_bytes_atomic(path, text.data(), text.size());
}

std::string atomic_temp_path(const std::string& path) {
  return path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
}

bool is_atomic_temp_name(const std::string& name) {
  const auto at = name.rfind(".tmp.");
  if (at == std::string::npos || at == 0) return false;
  std::size_t i = at + 5, digits = 0;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i, ++digits;
  if (digits == 0) return false;
  if (i == name.size()) return true;
  // One extension after the pid ("preview.mp4.tmp.123.mp4"), letters and digits only.
  if (name[i] != '.' || i + 1 == name.size()) return false;
  for (std::size_t k = i + 1; k < name.size(); ++k)
    if (!std::isalnum(static_cast<unsigned char>(name[k]))) return false;
  return true;
}

int remove_atomic_temps(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  std::vector<fs::path> doomed;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file(ec) && is_atomic_temp_name(e.path().filename().string()))
      doomed.push_back(e.path());
  int n = 0;
  for (const fs::path& p : doomed)
    if (fs::remove(p, ec)) ++n;
  return n;
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
