#include "io/scene_schema.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <unordered_map>
#include <utility>

#include "io/number_text.h"
#include "io/scene_spec.h"
#include "sim/scene/scene.h"
#include "sim/scene/scene_words.h"

namespace shellmpm {
namespace scenefile {

namespace {

const std::unordered_map<std::string, const KeySpec*>& schema_index() {
  static const std::unordered_map<std::string, const KeySpec*> index = [] {
    std::unordered_map<std::string, const KeySpec*> m;
    for (const KeySpec& s : scene_schema()) m.emplace(s.key, &s);
    return m;
  }();
  return index;
}

}  // namespace

const KeySpec* find_spec(const std::string& key) {
  auto it = schema_index().find(key);
  return it == schema_index().end() ? nullptr : it->second;
}

std::string join_key(const std::string& prefix, const std::string& name) {
  return prefix.empty() ? name : prefix + "." + name;
}

/// The schema prefix under which a key's children (or list items' keys) live.
std::string child_prefix(const KeySpec& s) {
  if (s.type == KeyType::Shape) return "shape";
  if (s.type == KeyType::List) return s.key + "[]";
  return s.key;
}

const std::vector<const KeySpec*>& schema_children(const std::string& prefix) {
  static const std::unordered_map<std::string, std::vector<const KeySpec*>> children = [] {
    std::unordered_map<std::string, std::vector<const KeySpec*>> m;
    for (const KeySpec& s : scene_schema()) {
      // "a.b[].c" -> parent "a.b[]"; a key without a dot is at the top level ("").
      const std::size_t dot = s.key.rfind('.');
      m[dot == std::string::npos ? "" : s.key.substr(0, dot)].push_back(&s);
    }
    return m;
  }();
  static const std::vector<const KeySpec*> none;
  auto it = children.find(prefix);
  return it == children.end() ? none : it->second;
}

bool allowed_for(const KeySpec& s, const std::string* variant) {
  return !variant || s.only_for.empty() ||
         std::find(s.only_for.begin(), s.only_for.end(), *variant) != s.only_for.end();
}

std::string known_keys(const std::string& prefix, const std::string* variant) {
  std::vector<std::string> names;
  for (const KeySpec* s : schema_children(prefix))
    if (allowed_for(*s, variant)) names.push_back(s->name());
  return names.empty() ? "none" : join(names);
}

/// "(0, 1]", "> 0", ">= 0", "< 90", "= 1", or "" when unbounded.
std::string bounds_text(const KeySpec& s) {
  const bool lo = std::isfinite(s.min), hi = std::isfinite(s.max);
  if (lo && hi && s.min == s.max && !s.min_open && !s.max_open) return "= " + fmt_bound(s.min);
  if (lo && hi) {
    return std::string(s.min_open ? "(" : "[") + fmt_bound(s.min) + ", " + fmt_bound(s.max) +
           (s.max_open ? ")" : "]");
  }
  if (lo) return std::string(s.min_open ? "> " : ">= ") + fmt_bound(s.min);
  if (hi) return std::string(s.max_open ? "< " : "<= ") + fmt_bound(s.max);
  return "";
}

bool in_bounds(const KeySpec& s, double x) {
  if (s.min_open ? !(x > s.min) : !(x >= s.min)) return false;
  if (s.max_open ? !(x < s.max) : !(x <= s.max)) return false;
  return true;
}

/// "must be > 0", "must be in (0, 1]", "must be 1".
std::string bounds_requirement(const KeySpec& s) {
  std::string b = bounds_text(s);
  if (b.compare(0, 2, "= ") == 0) return "must be " + b.substr(2);
  if (b[0] == '(' || b[0] == '[') return "must be in " + b;
  return "must be " + b;
}

}  // namespace scenefile

using scenefile::bounds_text;

std::string KeySpec::name() const {
  const std::size_t dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

std::string KeySpec::type_text() const {
  switch (type) {
    case KeyType::Int:
      return "integer";
    case KeyType::Number:
      return "number";
    case KeyType::Bool:
      return "boolean";
    case KeyType::String:
      return "string";
    case KeyType::Enum:
      return "enum";
    case KeyType::Vec3:
      return "vec3";
    case KeyType::Vec2:
      return "vec2";
    case KeyType::Int2:
      return "int2";
    case KeyType::IntList:
      return "integer list";
    case KeyType::Bool3:
      return "bool3";
    case KeyType::FrameRange:
      return "frame range";
    case KeyType::Map:
      return "mapping";
    case KeyType::List:
      return "list";
    case KeyType::Shape:
      return "shape";
  }
  return "?";
}

std::string KeySpec::unit_text() const {
  return unit.empty() ? "-" : unit;
}

std::string KeySpec::default_text() const {
  switch (presence) {
    case Presence::Required:
      return "required";
    case Presence::Default:
      return "`" + default_value + "`";
    case Presence::Optional:
      return default_value;
  }
  return "?";
}

std::string KeySpec::range_text() const {
  std::vector<std::string> parts;
  if (type == KeyType::FrameRange) {
    parts.push_back("first " + bounds_text(*this) + ", last >= first");
  } else if (!bounds_text(*this).empty()) {
    parts.push_back(bounds_text(*this));
  }
  if (!choices.empty()) parts.push_back("one of: " + join(choices));
  if (nonempty) parts.push_back("non-empty");
  if (unit_vector) parts.push_back("nonzero; normalized");
  if (!rule.empty()) parts.push_back(rule);
  return parts.empty() ? "-" : join(parts, "; ");
}

std::string KeySpec::only_for_text() const {
  return only_for.empty() ? "-" : join(only_for);
}

const std::vector<KeySpec>& scene_schema() {
  static const std::vector<KeySpec> schema = scenefile::build_schema();
  return schema;
}

}  // namespace shellmpm
