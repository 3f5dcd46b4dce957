#include "shot/available_memory.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "io/user_error.h"

namespace shellmpm {
namespace {

/// The number in a one-line file (cgroup limits); "max" or a missing file gives -1.
double read_number(const std::string& path) {
  std::ifstream f(path);
  std::string word;
  if (!(f >> word) || word == "max") return -1;
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  return end && *end == '\0' && v >= 0 ? v : -1;
}

/// A "Key:   123 kB" line of a /proc file, in bytes; -1 when absent.
double proc_field(const std::string& path, const std::string& key) {
  std::ifstream f(path);
  std::string line;
  while (std::getline(f, line)) {
    if (line.compare(0, key.size() + 1, key + ":") != 0) continue;
    std::istringstream in(line.substr(key.size() + 1));
    double v = 0;
    std::string unit;
    if (!(in >> v)) return -1;
    in >> unit;
    return unit == "kB" ? v * 1024 : v;
  }
  return -1;
}

/// A "key value" line of a cgroup memory.stat file; -1 when absent.
double stat_value(const std::string& path, const std::string& key) {
  std::ifstream f(path);
  std::string k;
  double v = 0;
  while (f >> k >> v)
    if (k == key) return v;
  return -1;
}

/// Room left in the cgroups of this process: min over the cgroup and its ancestors of
/// limit - usage; -1 when none is limited. v2 ("0::/path") and v1 ("N:memory:/path").
double cgroup_room() {
  std::ifstream f("/proc/self/cgroup");
  std::string line;
  double best = -1;
  auto consider = [&](double limit, double usage) {
    if (limit < 0 || limit >= 1e18 || usage < 0) return;  // unlimited (v1 writes 2^63 - 4096)
    const double room = std::max(0.0, limit - usage);
    best = best < 0 ? room : std::min(best, room);
  };
  while (std::getline(f, line)) {
    const std::size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1);
    std::string path = line.substr(b + 1);
    const bool v2 = controllers.empty();
    if (!v2 && controllers.find("memory") == std::string::npos) continue;
    const std::string root = v2 ? "/sys/fs/cgroup" : "/sys/fs/cgroup/memory";
    const std::string limit_file = v2 ? "/memory.max" : "/memory.limit_in_bytes";
    const std::string usage_file = v2 ? "/memory.current" : "/memory.usage_in_bytes";
    // Page cache the kernel can drop does not count against what a run may take.
    const std::string stat_key = v2 ? "inactive_file" : "total_inactive_file";
    // The cgroup and each ancestor (inside a container the path may not exist: then the
    // mount point itself is the cgroup).
    while (true) {
      const std::string dir = root + (path == "/" ? "" : path);
      const double usage = read_number(dir + usage_file);
      const double cache = stat_value(dir + "/memory.stat", stat_key);
      consider(read_number(dir + limit_file), usage < 0 ? usage : usage - std::max(0.0, cache));
      if (path.empty() || path == "/") break;
      const std::size_t slash = path.rfind('/');
      path = slash == 0 || slash == std::string::npos ? "/" : path.substr(0, slash);
    }
  }
  return best;
}

}  // namespace

double parse_memory_size(const std::string& text) {
  if (text.empty()) return -1;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || !std::isfinite(v) || v < 0) return -1;
  const std::string suffix = end;
  double scale = 1;
  if (suffix == "K" || suffix == "k")
    scale = 1024.0;
  else if (suffix == "M")
    scale = 1024.0 * 1024;
  else if (suffix == "G")
    scale = 1024.0 * 1024 * 1024;
  else if (suffix == "T")
    scale = 1024.0 * 1024 * 1024 * 1024;
  else if (!suffix.empty())
    return -1;
  return v * scale;
}

AvailableMemory available_memory() {
  AvailableMemory a;
  if (const char* env = std::getenv("SHELLMPM_AVAILABLE_MEMORY")) {
    const double v = parse_memory_size(env);
    if (v < 0) {
      throw UserError("SHELLMPM_AVAILABLE_MEMORY=" + std::string(env), 0, "",
                      "expected a size in bytes, or with a suffix K, M, G or T (e.g. 8G)");
    }
    a.bytes = v;
    a.known = true;
    a.source = "SHELLMPM_AVAILABLE_MEMORY";
    return a;
  }
  const double avail = proc_field("/proc/meminfo", "MemAvailable");
  if (avail >= 0) {
    a.bytes = avail;
    a.known = true;
    a.source = "MemAvailable in /proc/meminfo";
  }
  const double room = cgroup_room();
  if (room >= 0 && (!a.known || room < a.bytes)) {
    a.bytes = room;
    a.known = true;
    a.source = "the cgroup memory limit less its usage";
  }
  return a;
}

double resident_bytes() {
  const double v = proc_field("/proc/self/status", "VmRSS");
  return v > 0 ? v : 0;
}

std::string format_bytes(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int u = 0;
  while (bytes >= 1024 && u < 4) {
    bytes /= 1024;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf,
                u == 0       ? "%.0f %s"
                : bytes < 10 ? "%.2f %s"
                             : "%.1f %s",
                bytes, units[u]);
  return buf;
}

}  // namespace shellmpm
