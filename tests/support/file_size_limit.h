// A real write failure without privileges or a full disk: RLIMIT_FSIZE makes every
// write past `bytes` into a regular file fail with EFBIG, as ENOSPC does on a full
// disk. SIGXFSZ, which the kernel also sends, is ignored meanwhile.
#pragma once
#include <sys/resource.h>

#include <csignal>
#include <cstddef>

namespace shellmpm_test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(std::size_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit r = old_;
    r.rlim_cur = bytes;
    ok_ = setrlimit(RLIMIT_FSIZE, &r) == 0;
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = SIG_DFL;
  bool ok_ = false;
};

}  // namespace shellmpm_test
