// Internal invariant checks (house style 10). A failed check is a bug in shellmpm,
// never a user error: user errors are reported by io/ with file, line and key.
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>

namespace shellmpm {

/// Thrown when an internal invariant is violated.
struct InvariantError : std::logic_error {
  using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] inline void check_failed(const char* expr, const char* file, int line,
                                      const std::string& msg) {
  std::ostringstream os;
  os << "internal check failed: " << expr << " at " << file << ":" << line;
  if (!msg.empty()) os << " (" << msg << ")";
  throw InvariantError(os.str());
}
}  // namespace detail
}  // namespace shellmpm

/// SHELLMPM_CHECK(cond, stream-expression): throws InvariantError printing the values.
#define SHELLMPM_CHECK(cond, ...)                                                            \
  do {                                                                                       \
    if (!(cond)) {                                                                           \
      std::ostringstream shellmpm_check_os_;                                                 \
      shellmpm_check_os_ << "" __VA_ARGS__;                                                  \
      ::shellmpm::detail::check_failed(#cond, __FILE__, __LINE__, shellmpm_check_os_.str()); \
    }                                                                                        \
  } while (0)
