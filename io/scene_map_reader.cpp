#include "io/scene_map_reader.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "io/number_text.h"
#include "sim/core/check.h"

namespace shellmpm::scenefile {
namespace {

void set_origin(DocNode& n, const Origin& o) {
  n.origin = o;
  for (DocNode& c : n.items) set_origin(c, o);
  for (DocEntry& e : n.entries) {
    e.key_origin = o;
    set_origin(e.value, o);
  }
}

/// One item of a list value, within the row's bounds.
double bounded_number(const KeySpec& s, const DocNode& item, const std::string& item_key) {
  const double x = to_number(item, item_key);
  if (!in_bounds(s, x)) fail(item.origin, item_key, bounds_requirement(s) + ", got " + item.text);
  return x;
}

int bounded_int(const KeySpec& s, const DocNode& item, const std::string& item_key) {
  const long long x = to_integer(item, item_key);
  if (!in_bounds(s, static_cast<double>(x))) {
    fail(item.origin, item_key, bounds_requirement(s) + ", got " + item.text);
  }
  if (x > INT_MAX || x < INT_MIN)
    fail(item.origin, item_key, "integer " + item.text + " is too large");
  return static_cast<int>(x);
}

std::string item_key(const std::string& key, std::size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

}  // namespace

MapReader::MapReader(const DocNode& node, std::string prefix, std::string path,
                     bool defer_key_check)
    : node_(node), prefix_(std::move(prefix)), path_(std::move(path)) {
  if (node_.kind != DocNode::Kind::Map) {
    fail(node_.origin, path_,
         "expected a mapping (key: value lines or {...}), got " + describe(node_));
  }
  consumed_.assign(node_.entries.size(), false);
  if (!defer_key_check) check_keys(nullptr);
}

void MapReader::check_keys(const std::string* variant) const {
  for (const DocEntry& e : node_.entries) {
    const KeySpec* s = find_spec(join_key(prefix_, e.key));
    const std::string where_text = path_.empty() ? "the top level" : path_;
    if (!s) {
      fail(e.key_origin, path_of(e.key),
           "unknown key '" + e.key + "' in " + where_text + " (known" +
               (variant ? " for type " + *variant : std::string()) + ": " +
               known_keys(prefix_, variant) + ")");
    }
    if (variant && !allowed_for(*s, variant)) {
      fail(e.key_origin, path_of(e.key),
           "'" + e.key + "' is not allowed for type " + *variant + " (only for " +
               join(s->only_for) + "; keys for " + *variant + ": " + known_keys(prefix_, variant) +
               ")");
    }
  }
}

const Origin& MapReader::origin_of(const std::string& key) const {
  const int i = index_of(key);
  return i >= 0 ? node_.entries[i].value.origin : node_.origin;
}

const Origin& MapReader::key_origin_of(const std::string& key) const {
  const int i = index_of(key);
  return i >= 0 ? node_.entries[i].key_origin : node_.origin;
}

long long MapReader::integer(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Int);
  const DocNode& v = value(key, s);
  const long long x = to_integer(v, path_of(key));
  if (!in_bounds(s, static_cast<double>(x))) {
    fail(v.origin, path_of(key), bounds_requirement(s) + ", got " + v.text);
  }
  return x;
}

int MapReader::int32(const std::string& key) {
  const long long x = integer(key);
  if (x > INT_MAX || x < INT_MIN) {
    fail(origin_of(key), path_of(key), "integer " + std::to_string(x) + " is too large");
  }
  return static_cast<int>(x);
}

void MapReader::get(const std::string& key, unsigned& out) {
  const long long x = integer(key);
  SHELLMPM_CHECK(x >= 0 && x <= UINT_MAX, "schema bounds of " << key << " exceed unsigned");
  out = static_cast<unsigned>(x);
}

double MapReader::number(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Number);
  const DocNode& v = value(key, s);
  const double x = to_number(v, path_of(key));
  if (!in_bounds(s, x)) fail(v.origin, path_of(key), bounds_requirement(s) + ", got " + v.text);
  return x;
}

bool MapReader::boolean(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Bool);
  const DocNode& v = value(key, s);
  if (v.kind == DocNode::Kind::Scalar && v.plain && v.text == "true") return true;
  if (v.kind == DocNode::Kind::Scalar && v.plain && v.text == "false") return false;
  fail(v.origin, path_of(key), "expected true or false, got " + describe(v));
}

std::string MapReader::string(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::String);
  const DocNode& v = value(key, s);
  std::string x = to_string_value(v, path_of(key));
  if (s.nonempty && x.empty()) fail(v.origin, path_of(key), "must not be empty");
  return x;
}

std::string MapReader::choice(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Enum);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::Scalar) {
    fail(v.origin, path_of(key), "expected one of " + join(s.choices) + ", got " + describe(v));
  }
  if (std::find(s.choices.begin(), s.choices.end(), v.text) == s.choices.end()) {
    fail(v.origin, path_of(key), "expected one of " + join(s.choices) + ", got '" + v.text + "'");
  }
  return v.text;
}

Vec3d MapReader::vec3(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Vec3);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::List || v.items.size() != 3) {
    fail(v.origin, path_of(key), "expected a list of 3 numbers [x, y, z], got " + describe(v));
  }
  Vec3d x;
  for (int i = 0; i < 3; ++i) x[i] = bounded_number(s, v.items[i], item_key(path_of(key), i));
  if (s.unit_vector) {
    const double len = x.norm();
    if (!(len > 0.0) || !std::isfinite(len)) {
      fail(v.origin, path_of(key), "must be a nonzero vector, got [0, 0, 0]");
    }
    x /= len;
  }
  if (s.color) {
    for (int a = 0; a < 3; ++a) {
      if (!(x[a] >= 0.0 && x[a] <= 1.0)) {
        fail(v.origin, item_key(path_of(key), a),
             "a colour component must be in [0, 1] (linear RGB), got " + fmt_num(x[a]));
      }
    }
  }
  return x;
}

std::pair<int, int> MapReader::frames(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::FrameRange);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::List || v.items.size() != 2) {
    fail(v.origin, path_of(key), "expected [first, last] frames, got " + describe(v));
  }
  int f[2];
  for (int i = 0; i < 2; ++i) {
    const std::string ik = item_key(path_of(key), i);
    const long long x = to_integer(v.items[i], ik);
    if (!in_bounds(s, static_cast<double>(x)) || x > INT_MAX) {
      fail(v.items[i].origin, ik,
           (x > INT_MAX ? std::string("is too large") : bounds_requirement(s)) + ", got " +
               v.items[i].text);
    }
    f[i] = static_cast<int>(x);
  }
  if (f[1] < f[0]) {
    fail(v.origin, path_of(key),
         "last frame " + std::to_string(f[1]) + " is before first frame " + std::to_string(f[0]));
  }
  return {f[0], f[1]};
}

std::array<double, 2> MapReader::vec2(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Vec2);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::List || v.items.size() != 2) {
    fail(v.origin, path_of(key), "expected a list of 2 numbers, got " + describe(v));
  }
  std::array<double, 2> x{};
  for (int i = 0; i < 2; ++i) x[i] = bounded_number(s, v.items[i], item_key(path_of(key), i));
  return x;
}

std::array<int, 2> MapReader::int2(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Int2);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::List || v.items.size() != 2) {
    fail(v.origin, path_of(key), "expected a list of 2 integers, got " + describe(v));
  }
  std::array<int, 2> x{};
  for (int i = 0; i < 2; ++i) x[i] = bounded_int(s, v.items[i], item_key(path_of(key), i));
  return x;
}

std::vector<int> MapReader::int_list(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::IntList);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::List) {
    fail(v.origin, path_of(key), "expected a list of integers, got " + describe(v));
  }
  if (v.items.empty()) fail(v.origin, path_of(key), "must not be empty");
  std::vector<int> x;
  for (std::size_t i = 0; i < v.items.size(); ++i) {
    x.push_back(bounded_int(s, v.items[i], item_key(path_of(key), i)));
  }
  return x;
}

std::array<bool, 3> MapReader::bool3(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Bool3);
  const DocNode& v = value(key, s);
  if (v.kind != DocNode::Kind::List || v.items.size() != 3) {
    fail(v.origin, path_of(key), "expected a list of 3 booleans [x, y, z], got " + describe(v));
  }
  std::array<bool, 3> x{};
  for (int i = 0; i < 3; ++i) {
    const DocNode& item = v.items[i];
    const bool ok = item.kind == DocNode::Kind::Scalar && item.plain &&
                    (item.text == "true" || item.text == "false");
    if (!ok) {
      fail(item.origin, item_key(path_of(key), i), "expected true or false, got " + describe(item));
    }
    x[i] = item.text == "true";
  }
  return x;
}

const DocNode* MapReader::present(const std::string& key) const {
  const int i = index_of(key);
  return i >= 0 ? &node_.entries[i].value : nullptr;
}

const DocNode* MapReader::block(const std::string& key) {
  const KeySpec& s = spec(key, KeyType::Map, KeyType::List, KeyType::Shape);
  if (s.presence == Presence::Optional && !has(key)) return nullptr;
  const DocNode& v = value(key, s);
  const bool want_list = s.type == KeyType::List;
  const DocNode::Kind want = want_list ? DocNode::Kind::List : DocNode::Kind::Map;
  if (v.kind != want) {
    fail(v.origin, path_of(key),
         std::string(want_list ? "expected a list (write [] for none), got "
                               : "expected a mapping (key: value lines or {...}), got ") +
             describe(v));
  }
  return &v;
}

void MapReader::finish() const {
  for (std::size_t i = 0; i < node_.entries.size(); ++i) {
    SHELLMPM_CHECK(consumed_[i], "scene key " << path_of(node_.entries[i].key)
                                              << " is in the schema but was never read");
  }
}

int MapReader::index_of(const std::string& key) const {
  for (std::size_t i = 0; i < node_.entries.size(); ++i)
    if (node_.entries[i].key == key) return static_cast<int>(i);
  return -1;
}

const KeySpec& MapReader::spec(const std::string& key, KeyType t1, KeyType t2, KeyType t3) const {
  const KeySpec* s = find_spec(join_key(prefix_, key));
  SHELLMPM_CHECK(s != nullptr, "no schema entry for " << join_key(prefix_, key));
  SHELLMPM_CHECK(s->type == t1 || s->type == t2 || s->type == t3,
                 "schema type of " << s->key << " does not match the reader");
  return *s;
}

const DocNode& MapReader::value(const std::string& key, const KeySpec& s) {
  const int i = index_of(key);
  if (i >= 0) {
    consumed_[i] = true;
    return node_.entries[i].value;
  }
  if (s.presence == Presence::Required) {
    std::string hint;
    if (s.type == KeyType::Enum) hint = " (one of " + join(s.choices) + ")";
    fail(node_.origin, path_of(key), "required key '" + key + "' is missing" + hint);
  }
  SHELLMPM_CHECK(s.presence == Presence::Default,
                 "optional key " << s.key << " read without a has() check");
  // A default is validated exactly like user input; it is reported at this mapping.
  defaults_.push_back(load_document(s.default_value, "default of " + s.key, s.key, false));
  set_origin(defaults_.back(), node_.origin);
  return defaults_.back();
}

}  // namespace shellmpm::scenefile
