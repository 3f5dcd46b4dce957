// The scene format as data: one KeySpec row per key, in document order. A row says the
// key's type, presence, default, unit, range and rules (validation and docs/scene-format.md
// come from it), and, where the value goes straight into a struct field, binds that field
// (KeySpec::binding; the table is io/scene_schema_table.cpp), so a key is written once.
#pragma once
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <typeindex>
#include <vector>

namespace shellmpm {

namespace scenefile {
class MapReader;
}

/// The value type of a scene key.
enum class KeyType {
  Int,         ///< integer written without a decimal point or exponent
  Number,      ///< finite real number
  Bool,        ///< true or false
  String,      ///< any scalar
  Enum,        ///< one of KeySpec::choices
  Vec3,        ///< list of exactly 3 numbers
  Vec2,        ///< list of exactly 2 numbers (bounds apply to each)
  Int2,        ///< list of exactly 2 integers (bounds apply to each)
  IntList,     ///< list of integers (bounds apply to each)
  Bool3,       ///< list of exactly 3 booleans
  FrameRange,  ///< list of exactly 2 integers [first, last]
  Map,         ///< mapping with its own keys
  List,        ///< list of mappings (keys under "<key>[].")
  Shape,       ///< mapping with the keys under "shape." (see docs/scene-format.md)
};

/// Whether a key must be given, and what happens when it is not.
enum class Presence {
  Required,  ///< absent is an error
  Default,   ///< absent means KeySpec::default_value, a YAML text validated like user input
  Optional,  ///< absent has a meaning described by KeySpec::default_value (prose)
};

/// Where a key's value goes: a field of a struct of type `owner`, filled by `fill` from the
/// mapping being read (MapReader::fill calls it for every bound key of that mapping).
struct FieldBinding {
  std::type_index owner;
  std::function<void(scenefile::MapReader& reader, const std::string& name, void* object)> fill;
  /// Whether two objects of type `owner` hold the same value in the bound field(s) (lets a
  /// test check that a schema default equals the struct's default member value).
  std::function<bool(const void* a, const void* b)> same;
};

/// One key of the scene format.
struct KeySpec {
  /// Schema path: "shot.dx", "materials[].density", "colliders[].keyframes[].time".
  /// Shape keys are under "shape." ("shape.radius") whether in a source or a collider.
  std::string key;
  KeyType type = KeyType::Number;
  Presence presence = Presence::Default;
  std::string default_value;  ///< see Presence
  std::string unit;           ///< "" when dimensionless or not a quantity
  /// Numeric bounds of Int, Number, Vec2, Int2, IntList and FrameRange items (infinite =
  /// unbounded).
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;              ///< bound excluded: value > min
  bool max_open = false;              ///< bound excluded: value < max
  std::vector<std::string> choices;   ///< Enum: the allowed words
  std::vector<std::string> only_for;  ///< allowed only when the block's `type` is one of these
  bool nonempty = false;              ///< String: must not be empty
  bool unit_vector = false;           ///< Vec3: must be nonzero; normalized on read
  bool color = false;                 ///< Vec3: a linear RGB colour, each component in [0, 1]
  std::string rule;                   ///< further constraint the reader checks, as prose
  /// The struct field the value fills; null when the reader fills it by hand (names, cross
  /// references, blocks).
  std::shared_ptr<const FieldBinding> binding;

  /// The last segment of `key` ("density" for "materials[].density").
  std::string name() const;

  // The texts docs/scene-format.md shows in its tables ("-" when there is nothing to say).
  std::string type_text() const;      ///< "number", "integer", "vec3", ...
  std::string unit_text() const;      ///< unit or "-"
  std::string default_text() const;   ///< "required", "`value`", or prose
  std::string range_text() const;     ///< "(0, 1]", "> 0", "one of: apic, mls", plus `rule`
  std::string only_for_text() const;  ///< "sand" or "sphere, cylinder"; "-" when always allowed
};

/// Every key of the scene format, in document order.
const std::vector<KeySpec>& scene_schema();

namespace scenefile {

/// The row of a schema path, or null.
const KeySpec* find_spec(const std::string& key);

/// The rows directly under `prefix` ("shot", "materials[]", "" = top level), schema order.
const std::vector<const KeySpec*>& schema_children(const std::string& prefix);

/// "a.b" ("b" when prefix is empty).
std::string join_key(const std::string& prefix, const std::string& name);

/// The schema prefix under which a key's children (or list items' keys) live.
std::string child_prefix(const KeySpec& s);

/// Whether the key is allowed in a block of type `variant` (null: any).
bool allowed_for(const KeySpec& s, const std::string* variant);

/// Names of the keys directly under `prefix`, in schema order; with `variant`, only those
/// allowed for that block type; "none" when there are none.
std::string known_keys(const std::string& prefix, const std::string* variant);

/// "(0, 1]", "> 0", ">= 0", "< 90", "= 1", or "" when unbounded.
std::string bounds_text(const KeySpec& s);

/// Whether x lies within the row's bounds.
bool in_bounds(const KeySpec& s, double x);

/// "must be > 0", "must be in (0, 1]", "must be 1".
std::string bounds_requirement(const KeySpec& s);

}  // namespace scenefile
}  // namespace shellmpm
