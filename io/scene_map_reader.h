// MapReader: one mapping of the scene document read against the schema rows under one
// prefix. Typed reads check the type, the bounds and the rules the row states and fall
// back to its default; fill() reads every key the schema binds to a struct field;
// finish() checks that every key given was read.
#pragma once
#include <array>
#include <deque>
#include <optional>
#include <string>
#include <typeindex>
#include <utility>
#include <vector>

#include "io/scene_document.h"
#include "io/scene_schema.h"
#include "sim/core/types.h"
#include "sim/scene/scene_words.h"

namespace shellmpm::scenefile {

class MapReader {
 public:
  /// @param prefix schema prefix of the keys ("shot", "materials[]", "shape"; "" = top level)
  /// @param path   instance path for messages ("materials[2]"; "" = top level)
  /// @param defer_key_check the caller reads `type` first, then calls check_keys(&type)
  MapReader(const DocNode& node, std::string prefix, std::string path, bool defer_key_check);

  /// Rejects keys the schema does not know here, and keys not allowed for `variant` (the
  /// block's type) when given.
  void check_keys(const std::string* variant) const;

  /// Reads every key under this prefix that the schema binds to a field of S (those allowed
  /// for `variant`; Optional ones only when given) into `object`, in schema order.
  template <class S>
  void fill(S& object, const std::string* variant = nullptr) {
    for (const KeySpec* s : schema_children(prefix_)) {
      if (!s->binding || s->binding->owner != std::type_index(typeid(S))) continue;
      if (!allowed_for(*s, variant)) continue;
      if (s->presence == Presence::Optional && !has(s->name())) continue;
      s->binding->fill(*this, s->name(), &object);
    }
  }

  /// Reads the list at `key`: calls f(item, i) with a MapReader for each of its mappings
  /// (schema keys under "<prefix>.<key>[]", instance path "<path>.<key>[i]").
  /// @param defer_key_check as for the constructor (the item's `type` is read first)
  template <class F>
  void each(const std::string& key, bool defer_key_check, F&& f) {
    const DocNode& list = *block(key);
    const std::string item_prefix = join_key(prefix_, key) + "[]";
    for (std::size_t i = 0; i < list.items.size(); ++i) {
      MapReader item(list.items[i], item_prefix, path_of(key) + "[" + std::to_string(i) + "]",
                     defer_key_check);
      f(item, i);
    }
  }

  bool has(const std::string& key) const { return index_of(key) >= 0; }
  const std::string& path() const { return path_; }  ///< this mapping's instance path
  std::string path_of(const std::string& key) const { return join_key(path_, key); }
  const Origin& origin() const { return node_.origin; }
  /// Origin of the key's value, or of this mapping when the key is absent.
  const Origin& origin_of(const std::string& key) const;
  /// Origin of the key itself (for "not both" errors), or of this mapping.
  const Origin& key_origin_of(const std::string& key) const;

  long long integer(const std::string& key);
  int int32(const std::string& key);
  double number(const std::string& key);
  bool boolean(const std::string& key);
  std::string string(const std::string& key);
  std::string choice(const std::string& key);
  Vec3d vec3(const std::string& key);
  std::pair<int, int> frames(const std::string& key);
  std::array<double, 2> vec2(const std::string& key);  ///< exactly 2 numbers
  std::array<int, 2> int2(const std::string& key);     ///< exactly 2 integers
  std::vector<int> int_list(const std::string& key);   ///< a non-empty list of integers
  std::array<bool, 3> bool3(const std::string& key);   ///< exactly 3 booleans

  // The typed read that matches a field's type (what a schema binding calls).
  void get(const std::string& key, double& out) { out = number(key); }
  void get(const std::string& key, int& out) { out = int32(key); }
  void get(const std::string& key, unsigned& out);
  void get(const std::string& key, bool& out) { out = boolean(key); }
  void get(const std::string& key, std::string& out) { out = string(key); }
  void get(const std::string& key, Vec3d& out) { out = vec3(key); }
  void get(const std::string& key, std::array<double, 2>& out) { out = vec2(key); }
  void get(const std::string& key, std::array<int, 2>& out) { out = int2(key); }
  void get(const std::string& key, std::array<bool, 3>& out) { out = bool3(key); }
  void get(const std::string& key, std::vector<int>& out) { out = int_list(key); }
  template <class E, class = std::enable_if_t<std::is_enum_v<E>>>
  void get(const std::string& key, E& out) {
    out = *enum_of_word<E>(choice(key));  // choice() accepts only the table's words
  }
  template <class T>
  void get(const std::string& key, std::optional<T>& out) {
    T value{};
    get(key, value);
    out = value;
  }

  /// The value node of a present key (not marked read), or nullptr.
  const DocNode* present(const std::string& key) const;

  /// A Map, List or Shape value: the given one, the default, or nullptr when an Optional key
  /// is absent. Checks the node kind.
  const DocNode* block(const std::string& key);

  /// Internal check: every key present was read by the code (the schema has no dead keys).
  void finish() const;

 private:
  int index_of(const std::string& key) const;
  const KeySpec& spec(const std::string& key, KeyType t1, KeyType t2 = KeyType::Int,
                      KeyType t3 = KeyType::Int) const;
  /// The present value (marked read), or the schema default, or a missing-key error.
  const DocNode& value(const std::string& key, const KeySpec& s);

  const DocNode& node_;
  std::string prefix_;
  std::string path_;
  std::vector<bool> consumed_;
  std::deque<DocNode> defaults_;  // stable addresses for returned defaults
};

}  // namespace shellmpm::scenefile
