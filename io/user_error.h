// A mistake in user input (scene file, command-line override, mesh, flag): it names
// where it came from, the line and the key, so the user can fix it without a debugger.
#pragma once
#include <stdexcept>
#include <string>
#include <utility>

namespace shellmpm {

/// An error in user input. what() reads, for example,
///   "scenes/a.yaml:12: materials[0].density: must be > 0, got -3"
///   "--set shot.dx=abc: shot.dx: expected a number, got 'abc'"
/// The app prints what() and exits non-zero; no caller should catch it to carry on.
struct UserError : std::runtime_error {
  /// @param file_   the input file, or "--set KEY=VALUE" for a value from a command-line override
  /// @param line_   1-based line in `file_`; 0 when there is none
  /// @param key_    full key path, e.g. "materials[0].density"; empty when there is none
  /// @param message_ what is wrong, without the location
  UserError(std::string file_, int line_, std::string key_, std::string message_)
      : std::runtime_error(format(file_, line_, key_, message_)),
        file(std::move(file_)),
        line(line_),
        key(std::move(key_)),
        message(std::move(message_)) {}

  std::string file;     ///< input file path, or "--set KEY=VALUE"
  int line = 0;         ///< 1-based line, 0 if none
  std::string key;      ///< full key path, empty if none
  std::string message;  ///< the message without the location prefix

  /// "file:line: key: message", leaving out the parts that are empty or zero.
  static std::string format(const std::string& file, int line, const std::string& key,
                            const std::string& message) {
    std::string s = file;
    if (line > 0) s += ":" + std::to_string(line);
    if (!s.empty()) s += ": ";
    if (!key.empty()) s += key + ": ";
    return s + message;
  }
};

}  // namespace shellmpm
