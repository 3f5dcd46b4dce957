// Reads a scene file (YAML or JSON) into a Scene, validating every key against one schema.
// The schema (scene_schema()) drives the validation and is what docs/scene-format.md
// documents; a test keeps the two in step.
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "io/user_error.h"
#include "sim/scene/scene.h"

namespace shellmpm {

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
  std::string rule;                   ///< further constraint the reader checks, as prose

  // The texts docs/scene-format.md shows in its tables ("-" when there is nothing to say).
  std::string type_text() const;      ///< "number", "integer", "vec3", ...
  std::string unit_text() const;      ///< unit or "-"
  std::string default_text() const;   ///< "required", "`value`", or prose
  std::string range_text() const;     ///< "(0, 1]", "> 0", "one of: apic, mls", plus `rule`
  std::string only_for_text() const;  ///< "sand" or "sphere, cylinder"; "-" when always allowed
};

/// Positions that place simulated things (the domain corners, collider shapes and
/// keyframes, pin keyframes) must lie within this many cells (shot.dx) of the origin: up to
/// 2^17 cells a float position is resolved to 1/64 of a cell (ulp(2^17 dx) = dx/64). The
/// same bound holds in a double build, so a scene valid in one build is valid in the other.
constexpr double kPositionRangeCells = 131072.0;  // 2^17

/// The most steps one frame may take at the smallest step: 1 / (fps dt_min) <= this.
constexpr double kMaxStepsPerFrame = 1e7;

/// Every key of the scene format, in document order.
const std::vector<KeySpec>& scene_schema();

/// Parses and validates a scene file. Mesh paths are resolved relative to the scene file and
/// must name readable files; meshes are not loaded (ShapeDesc::sdf stays empty).
/// @param overrides "key.path=value" strings (from `--set`), applied in order to the document
///   before validation; the value is parsed as YAML and replaces the whole value at that key.
/// @throws UserError naming file, line and key for any problem with the file or an override.
Scene read_scene(const std::string& path, const std::vector<std::string>& overrides = {});

/// Checks the pin and point-load indices of `shell` against its vertex count, for meshes
/// whose count is known only once the file is loaded (the reader checks procedural geometry
/// itself). Call it from io/ after loading ShellDesc::mesh.
/// @param num_vertices number of control points of the shell's mesh (>= 0)
/// @param scene_path   the scene file, for messages when a pin or load has no `where`
/// @throws UserError at the offending key ("file:line: shells[0].pins[1].indices[3]", from
///   PinDesc::where / PointLoadDesc::where) when an index is >= num_vertices.
void check_shell_indices(const ShellDesc& shell, int num_vertices, const std::string& scene_path);

/// As read_scene, from text; `path` is used for messages and to resolve relative mesh paths.
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides = {});

}  // namespace shellmpm
