#include "io/scene_checks.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "io/number_text.h"
#include "io/scene_reader.h"

namespace shellmpm::scenefile {

namespace fs = std::filesystem;

void require_greater(const Vec3d& lo, const Vec3d& hi, const Origin& o, const std::string& key) {
  for (int a = 0; a < 3; ++a) {
    if (!(hi[a] > lo[a])) {
      fail(o, key,
           std::string("must be greater than min on every axis, but on ") + kAxis[a] +
               " max = " + fmt_num(hi[a]) + " <= min = " + fmt_num(lo[a]));
    }
  }
}

void require_one_hash_run(const std::string& pattern, const Origin& o, const std::string& key) {
  int runs = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i)
    if (pattern[i] == '#' && (i == 0 || pattern[i - 1] != '#')) ++runs;
  if (runs != 1) {
    fail(o, key,
         "must contain exactly one run of '#' (replaced by the zero-padded frame number), got '" +
             pattern + "'");
  }
}

void require_output_file(const std::string& path, bool is_pattern, const Origin& o,
                         const std::string& key) {
  if (!path.empty() && path.front() == '/') {
    fail(o, key,
         "must be relative to output.directory (files are written inside it), got '" + path + "'");
  }
  const std::size_t slash = path.rfind('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  if (name.empty() || name == "." || name == "..") {
    fail(o, key, "must end in a file name, got '" + path + "'");
  }
  if (is_pattern && slash != std::string::npos && path.find('#') < slash) {
    fail(
        o, key,
        "the '#' run (frame number) must be in the file name, not in a folder: got '" + path + "'");
  }
}

std::string where_text(const Origin& o, const std::string& key) {
  return (o.line > 0 ? o.where + ":" + std::to_string(o.line) : o.where) + ": " + key;
}

UserError error_at_where(const std::string& where, const std::string& fallback_file,
                         const std::string& fallback_key, const std::string& suffix,
                         const std::string& message) {
  if (where.empty()) return UserError(fallback_file, 0, fallback_key + suffix, message);
  // Keys never hold ": ", so the last one ends the location. A "--set" location has no line.
  const std::size_t sep = where.rfind(": ");
  std::string head = sep == std::string::npos ? where : where.substr(0, sep);
  const std::string key = sep == std::string::npos ? fallback_key : where.substr(sep + 2);
  int line = 0;
  const std::size_t colon = head.rfind(':');
  if (head.compare(0, 6, "--set ") != 0 && colon != std::string::npos && colon + 1 < head.size() &&
      head.size() - colon - 1 < 10 &&
      std::all_of(head.begin() + static_cast<std::ptrdiff_t>(colon) + 1, head.end(), is_digit)) {
    line = std::stoi(head.substr(colon + 1));
    head.erase(colon);
  }
  return UserError(head, line, key + suffix, message);
}

std::pair<std::string, std::string> read_mesh_path(MapReader& r, const std::string& key,
                                                   const std::string& scene_path) {
  const std::string raw = r.string(key);
  fs::path p(raw);
  if (p.is_relative()) p = fs::path(scene_path).parent_path() / p;
  p = p.lexically_normal();
  const Origin& o = r.origin_of(key);
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  if (!fs::exists(st)) fail(o, r.path_of(key), "mesh file not found: " + p.string());
  if (!fs::is_regular_file(st)) fail(o, r.path_of(key), "not a regular file: " + p.string());
  if (!std::ifstream(p, std::ios::binary)) {
    fail(o, r.path_of(key), "cannot read mesh file " + p.string() + ": " + std::strerror(errno));
  }
  return {p.string(), where_text(o, r.path_of(key))};
}

void require_in_position_range(const Vec3d& p, const ShotSettings& shot, const Origin& o,
                               const std::string& key, const std::string& what) {
  const double range = kPositionRangeCells * shot.dx;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(p[a]) <= range) continue;
    fail(o, key,
         what + " reaches " + kAxis[a] + " = " + fmt_num(p[a]) +
             " m, more than 2^17 = 131072 cells of dx = " + fmt_num(shot.dx) + " m (" +
             fmt_num(range) +
             " m) from the origin, where a float position no longer resolves "
             "1/64 of a cell");
  }
}

std::string index_range_message(long long index, long long num_vertices, const std::string& what) {
  return "index " + std::to_string(index) + " is out of range: " + what + " has " +
         std::to_string(num_vertices) + " vert" + (num_vertices == 1 ? "ex" : "ices") +
         (num_vertices > 0 ? " (0.." + std::to_string(num_vertices - 1) + ")" : "");
}

std::string name_or_default(MapReader& r, const std::string& kind, std::size_t i) {
  return r.has("name") ? r.string("name") : kind + std::to_string(i);
}

bool file_name_safe(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || is_digit(c) || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

NameSet::NameSet(std::string what) : what_(std::move(what)) {}

void NameSet::add(const std::string& name, const std::string& item_path, const Origin& o,
                  const std::string& key) {
  auto [it, fresh] = first_.emplace(name, item_path);
  if (!fresh) fail(o, key, "duplicate " + what_ + " name '" + name + "' (also " + it->second + ")");
}

[[noreturn]] void fail_unknown_name(const std::string& name, const std::vector<std::string>& names,
                                    const std::string& what, const std::string& list_key,
                                    const Origin& o, const std::string& key) {
  fail(o, key,
       "unknown " + what + " '" + name + "' (" +
           (names.empty() ? "no " + list_key + " are defined" : list_key + ": " + join(names)) +
           ")");
}

}  // namespace shellmpm::scenefile
