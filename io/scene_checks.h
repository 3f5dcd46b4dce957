// The scene reader's checks that span more than one key's type and bounds: ordered
// corners, output file names, mesh paths, the position range, vertex indices, unique
// names and references by name. Each fails with a UserError at the file, line and key.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "io/scene_map_reader.h"
#include "io/user_error.h"
#include "sim/scene/scene.h"

namespace shellmpm::scenefile {

inline constexpr const char* kAxis[3] = {"x", "y", "z"};

/// hi > lo on every axis, else a failure at `key` naming the axis.
void require_greater(const Vec3d& lo, const Vec3d& hi, const Origin& o, const std::string& key);

/// The pattern holds exactly one run of '#' (the zero-padded frame number).
void require_one_hash_run(const std::string& pattern, const Origin& o, const std::string& key);

/// A file name inside output.directory: relative, naming a file (not a folder), with any
/// sub-folders before it; the `#` run of a pattern (`is_pattern`) in the file name itself,
/// since the folders are made once before the run (io/output_folders.h).
void require_output_file(const std::string& path, bool is_pattern, const Origin& o,
                         const std::string& key);

/// "file:line: key" (or "--set K=V: key"), the prefix of a UserError, for fields that io/
/// reports problems at after the scene is read.
std::string where_text(const Origin& o, const std::string& key);

/// A UserError at a where_text() string ("file:line: key", "--set K=V: key"), with `suffix`
/// appended to the key; at `fallback_file` / `fallback_key` when `where` is empty.
UserError error_at_where(const std::string& where, const std::string& fallback_file,
                         const std::string& fallback_key, const std::string& suffix,
                         const std::string& message);

/// Reads a mesh file path, resolved relative to the scene file; the file must be readable.
/// Returns the resolved path and where it was given ("file:line: key").
std::pair<std::string, std::string> read_mesh_path(MapReader& r, const std::string& key,
                                                   const std::string& scene_path);

/// Fails at `key` when a coordinate of `p` lies beyond the position range
/// (kPositionRangeCells cells of the origin); `what` names p ("the translation").
void require_in_position_range(const Vec3d& p, const ShotSettings& shot, const Origin& o,
                               const std::string& key, const std::string& what);

/// "index 121 is out of range: the sheet has 121 vertices (0..120)".
std::string index_range_message(long long index, long long num_vertices, const std::string& what);

/// The item's `name`, or `<kind><i>` ("source2") when it gives none.
std::string name_or_default(MapReader& r, const std::string& kind, std::size_t i);

/// Names used in output file names: [A-Za-z0-9_-]+.
bool file_name_safe(const std::string& name);

/// The names given so far in one list, for its "unique" rule.
class NameSet {
 public:
  /// @param what the item's kind in messages ("material", "shell material")
  explicit NameSet(std::string what);
  /// Records `name` of the item at `item_path` ("materials[2]"); a name given before fails
  /// at `key`: "duplicate material name 'steel' (also materials[0])".
  void add(const std::string& name, const std::string& item_path, const Origin& o,
           const std::string& key);

 private:
  std::string what_;
  std::map<std::string, std::string> first_;  // name -> path of its first use
};

[[noreturn]] void fail_unknown_name(const std::string& name, const std::vector<std::string>& names,
                                    const std::string& what, const std::string& list_key,
                                    const Origin& o, const std::string& key);

/// The index of the item whose `name` is `name`, or a failure at `key`: "unknown material
/// 'x' (materials: a, b)" or "(no materials are defined)".
/// @param what     the item's kind ("material")
/// @param list_key the list's key ("materials")
template <class T>
int index_by_name(const std::vector<T>& items, const std::string& name, const std::string& what,
                  const std::string& list_key, const Origin& o, const std::string& key) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (items[i].name == name) return static_cast<int>(i);
    names.push_back(items[i].name);
  }
  fail_unknown_name(name, names, what, list_key, o, key);
}

}  // namespace shellmpm::scenefile
