// A fresh directory under the system temp dir for one test, removed with its contents.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace shellmpm_test {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) {
    path = std::filesystem::temp_directory_path() /
           ("shellmpm_test_" + name + "_" + std::to_string(static_cast<long>(::getpid())));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path / name).string(); }
  /// Writes `text` to `name` in the directory and returns the full path.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }
  /// Files whose name contains ".tmp." (leftovers of an atomic write), recursively.
  int temp_files() const {
    int n = 0;
    for (const auto& e : std::filesystem::recursive_directory_iterator(path))
      if (e.path().filename().string().find(".tmp.") != std::string::npos) ++n;
    return n;
  }
};

/// The whole file at `path` (empty when it cannot be read).
inline std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

}  // namespace shellmpm_test
