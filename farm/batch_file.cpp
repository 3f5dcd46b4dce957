#include "farm/batch_file.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/user_error.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;
using scenefile::DocEntry;
using scenefile::DocNode;
using scenefile::fail;

/// Refuses any key of `map` not in `allowed`, naming the ones that are.
void check_keys(const DocNode& map, const std::vector<std::string>& allowed,
                const std::string& path) {
  for (const DocEntry& e : map.entries) {
    if (std::find(allowed.begin(), allowed.end(), e.key) != allowed.end()) continue;
    std::string list;
    for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail(e.key_origin, path.empty() ? e.key : path + "." + e.key,
         "unknown key '" + e.key + "' (expected one of: " + list + ")");
  }
}

const DocNode& need_map(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Map)
    fail(n.origin, key, "expected a mapping, got " + scenefile::describe(n));
  return n;
}

const DocNode& need_list(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::List)
    fail(n.origin, key, "expected a list, got " + scenefile::describe(n));
  if (n.items.empty()) fail(n.origin, key, "must not be empty");
  return n;
}

/// A name that is one folder: letters, digits, '.', '_', '-', not starting with '.', '_'
/// or '-' (folders starting with '_' are the batch's own, e.g. _farm).
std::string folder_name(const DocNode& n, const std::string& key) {
  const std::string s = scenefile::to_string_value(n, key);
  bool ok = !s.empty() && std::isalnum(static_cast<unsigned char>(s[0]));
  for (char c : s)
    ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-');
  if (!ok)
    fail(n.origin, key,
         "'" + s +
             "' is not a usable folder name (letters, digits, '.', '_' and '-', starting "
             "with a letter or digit)");
  return s;
}

int positive_int(const DocNode& n, const std::string& key, long long min) {
  const long long v = scenefile::to_integer(n, key);
  if (v < min || v > 1000000)
    fail(n.origin, key,
         "must be between " + std::to_string(min) + " and 1000000, got " + std::to_string(v));
  return static_cast<int>(v);
}

/// An absolute path from one relative to the batch file's folder.
std::string resolve(const std::string& base_dir, const std::string& p) {
  fs::path path(p);
  if (path.is_relative()) path = fs::path(base_dir) / path;
  return path.lexically_normal().string();
}

/// `set: {KEY: VALUE, ...}` as overrides, in file order.
std::vector<Override> read_set(const DocNode& n, const std::string& key) {
  need_map(n, key);
  std::vector<Override> out;
  for (const DocEntry& e : n.entries) {
    const std::string k = key + "." + e.key;
    if (e.value.kind == DocNode::Kind::Null) fail(e.key_origin, k, "needs a value");
    out.push_back(Override{e.key, yaml_value_text(e.value), e.value.origin, k});
  }
  return out;
}

/// A value's part of a product member's name: its text with anything but letters, digits,
/// '.', '+' and '-' made '_' ("[0, -5, 0]" -> "0_-5_0").
std::string name_part(const std::string& value) {
  std::string s;
  for (char c : value) {
    if (c == '[' || c == ']' || c == '{' || c == '}' || c == ' ' || c == '"' || c == '\'') continue;
    s +=
        (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-') ? c : '_';
  }
  return s.empty() ? "empty" : s;
}

/// The label of a key in product member names: its last word ("colliders[1].friction" ->
/// "friction"), or the whole key made a name when two keys share a last word.
std::vector<std::string> key_labels(const std::vector<std::string>& keys) {
  auto last_word = [](const std::string& k) {
    std::string w = k.substr(k.rfind('.') == std::string::npos ? 0 : k.rfind('.') + 1);
    return w.substr(0, w.find('['));
  };
  std::vector<std::string> labels;
  for (const std::string& k : keys) {
    int same = 0;
    for (const std::string& o : keys) same += last_word(o) == last_word(k);
    labels.push_back(same > 1 || last_word(k).empty() ? name_part(k) : last_word(k));
  }
  return labels;
}

/// `product: {KEY: [V1, V2], KEY2: [...]}`: every combination, the first key slowest.
void read_product(const DocNode& n, const std::string& key, WedgeSpec& w) {
  need_map(n, key);
  if (n.entries.empty()) fail(n.origin, key, "must name at least one key");
  std::vector<std::vector<Override>> axes;
  for (const DocEntry& e : n.entries) {
    const std::string k = key + "." + e.key;
    need_list(e.value, k);
    std::vector<Override> axis;
    for (std::size_t i = 0; i < e.value.items.size(); ++i) {
      const DocNode& v = e.value.items[i];
      if (v.kind == DocNode::Kind::Null) fail(v.origin, k, "a value is missing (null)");
      axis.push_back(
          Override{e.key, yaml_value_text(v), v.origin, k + "[" + std::to_string(i) + "]"});
    }
    w.keys.push_back(e.key);
    axes.push_back(axis);
  }
  const std::vector<std::string> labels = key_labels(w.keys);
  std::vector<std::size_t> at(axes.size(), 0);
  for (;;) {
    WedgeMember m;
    for (std::size_t a = 0; a < axes.size(); ++a) {
      m.values.push_back(axes[a][at[a]]);
      m.name += (a ? "_" : "") + labels[a] + "-" + name_part(axes[a][at[a]].value);
    }
    w.members.push_back(m);
    std::size_t a = axes.size();
    while (a > 0 && ++at[a - 1] == axes[a - 1].size()) at[--a] = 0;
    if (a == 0) break;
  }
}

/// `sets: [{name: N, set: {...}}, ...]`.
void read_sets(const DocNode& n, const std::string& key, WedgeSpec& w) {
  need_list(n, key);
  for (std::size_t i = 0; i < n.items.size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    const DocNode& item = need_map(n.items[i], k);
    check_keys(item, {"name", "set"}, k);
    const DocNode* name = scenefile::find_entry(item, "name");
    const DocNode* set = scenefile::find_entry(item, "set");
    if (!name || !set) fail(item.origin, k, std::string("needs '") + (name ? "set" : "name") + "'");
    WedgeMember m{folder_name(*name, k + ".name"), read_set(*set, k + ".set")};
    for (const Override& o : m.values)
      if (std::find(w.keys.begin(), w.keys.end(), o.key) == w.keys.end()) w.keys.push_back(o.key);
    w.members.push_back(m);
  }
}

WedgeSpec read_wedge(const DocNode& n, const std::string& key, const std::string& default_name) {
  need_map(n, key);
  check_keys(n, {"name", "sets", "product"}, key);
  WedgeSpec w;
  w.origin = n.origin;
  const DocNode* name = scenefile::find_entry(n, "name");
  if (name)
    w.name = folder_name(*name, key + ".name");
  else if (default_name.empty())
    fail(n.origin, key, "needs a 'name'");
  else
    w.name = default_name;
  const DocNode* sets = scenefile::find_entry(n, "sets");
  const DocNode* product = scenefile::find_entry(n, "product");
  if ((sets != nullptr) == (product != nullptr))
    fail(n.origin, key, "needs exactly one of 'sets' (a list of override sets) or 'product'");
  if (sets)
    read_sets(*sets, key + ".sets", w);
  else
    read_product(*product, key + ".product", w);
  for (std::size_t i = 0; i < w.members.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (w.members[i].name == w.members[j].name)
        fail(n.origin, key,
             "two members are both named '" + w.members[i].name +
                 "' (their folders would be one); name them apart");
  return w;
}

PreviewSpec read_preview(const DocNode& n, const std::string& key) {
  PreviewSpec p;
  if (n.kind == DocNode::Kind::Scalar && n.plain && (n.text == "true" || n.text == "false")) {
    p.enabled = n.text == "true";
    return p;
  }
  if (n.kind != DocNode::Kind::Map)
    fail(n.origin, key,
         "expected true, false or a mapping {size, camera, renderer}, got " +
             scenefile::describe(n));
  check_keys(n, {"size", "camera", "renderer"}, key);
  p.enabled = true;
  if (const DocNode* s = scenefile::find_entry(n, "size")) {
    p.size = scenefile::to_string_value(*s, key + ".size");
    const std::size_t x = p.size.find('x');
    if (x == std::string::npos || x == 0 || x + 1 == p.size.size() ||
        p.size.find_first_not_of("0123456789x") != std::string::npos)
      fail(s->origin, key + ".size", "expected WIDTHxHEIGHT (e.g. 640x360), got '" + p.size + "'");
  }
  if (const DocNode* c = scenefile::find_entry(n, "camera"))
    p.camera = scenefile::to_string_value(*c, key + ".camera");
  if (const DocNode* r = scenefile::find_entry(n, "renderer")) {
    p.renderer = scenefile::to_string_value(*r, key + ".renderer");
    if (p.renderer != "raster" && p.renderer != "raytrace")
      fail(r->origin, key + ".renderer", "expected raster or raytrace, got '" + p.renderer + "'");
  }
  return p;
}

void read_frames(const DocNode& n, const std::string& key, ShotSpec& s) {
  if (n.kind != DocNode::Kind::List || n.items.size() != 2)
    fail(n.origin, key, "expected [FIRST, LAST], got " + scenefile::describe(n));
  s.frame_start = positive_int(n.items[0], key + "[0]", 1);
  s.frame_end = positive_int(n.items[1], key + "[1]", 1);
  if (*s.frame_end < *s.frame_start)
    fail(n.origin, key,
         "the last frame (" + std::to_string(*s.frame_end) + ") is before the first (" +
             std::to_string(*s.frame_start) + ")");
}

ShotSpec read_shot(const DocNode& n, const std::string& key, const std::string& base_dir,
                   std::vector<WedgeSpec>& inline_wedges) {
  need_map(n, key);
  check_keys(n, {"name", "scene", "frames", "set", "wedge", "preview"}, key);
  ShotSpec s;
  s.origin = n.origin;
  const DocNode* name = scenefile::find_entry(n, "name");
  const DocNode* scene = scenefile::find_entry(n, "scene");
  if (!name || !scene)
    fail(n.origin, key, std::string("needs '") + (name ? "scene" : "name") + "'");
  s.name = folder_name(*name, key + ".name");
  s.scene = resolve(base_dir, scenefile::to_string_value(*scene, key + ".scene"));
  std::error_code ec;
  if (!fs::is_regular_file(s.scene, ec))
    fail(scene->origin, key + ".scene", "no scene file '" + s.scene + "'");
  if (const DocNode* f = scenefile::find_entry(n, "frames")) read_frames(*f, key + ".frames", s);
  if (const DocNode* set = scenefile::find_entry(n, "set"))
    s.overrides = read_set(*set, key + ".set");
  if (const DocNode* w = scenefile::find_entry(n, "wedge")) {
    if (w->kind == DocNode::Kind::Map) {
      inline_wedges.push_back(read_wedge(*w, key + ".wedge", "shot." + s.name));
      s.wedge = inline_wedges.back().name;
    } else {
      s.wedge = scenefile::to_string_value(*w, key + ".wedge");
    }
  }
  if (const DocNode* p = scenefile::find_entry(n, "preview"))
    s.preview = read_preview(*p, key + ".preview");
  return s;
}

SlurmSettings read_slurm(const DocNode& n, const std::string& key) {
  need_map(n, key);
  check_keys(n,
             {"partition", "time", "mem", "cpus", "throttle", "signal_seconds", "account", "qos",
              "preview_partition"},
             key);
  SlurmSettings s;
  auto text = [&](const char* k, std::string& out) {
    if (const DocNode* v = scenefile::find_entry(n, k))
      out = scenefile::to_string_value(*v, key + "." + k);
  };
  text("partition", s.partition);
  text("time", s.time);
  text("mem", s.mem);
  text("account", s.account);
  text("qos", s.qos);
  text("preview_partition", s.preview_partition);
  if (const DocNode* v = scenefile::find_entry(n, "cpus"))
    s.cpus = positive_int(*v, key + ".cpus", 1);
  if (const DocNode* v = scenefile::find_entry(n, "throttle"))
    s.throttle = positive_int(*v, key + ".throttle", 1);
  if (const DocNode* v = scenefile::find_entry(n, "signal_seconds"))
    s.signal_seconds = positive_int(*v, key + ".signal_seconds", 1);
  if (s.signal_seconds > 65535)
    fail(n.origin, key + ".signal_seconds", "Slurm takes at most 65535 s");
  return s;
}

FarmSettings read_farm(const DocNode& n, const std::string& key) {
  need_map(n, key);
  check_keys(n, {"slots", "threads", "slurm"}, key);
  FarmSettings f;
  if (const DocNode* v = scenefile::find_entry(n, "slots"))
    f.slots = positive_int(*v, key + ".slots", 1);
  if (const DocNode* v = scenefile::find_entry(n, "threads"))
    f.threads = positive_int(*v, key + ".threads", 0);
  if (const DocNode* v = scenefile::find_entry(n, "slurm"))
    f.slurm = read_slurm(*v, key + ".slurm");
  return f;
}

/// Every shot's wedge names one that exists; shot names and wedge names are unique.
void check_references(const BatchSpec& b, const DocNode& root) {
  for (std::size_t i = 0; i < b.shots.size(); ++i) {
    const ShotSpec& s = b.shots[i];
    for (std::size_t j = 0; j < i; ++j)
      if (b.shots[j].name == s.name)
        fail(s.origin, "shots[" + std::to_string(i) + "].name",
             "a second shot named '" + s.name + "' (first at line " +
                 std::to_string(b.shots[j].origin.line) + ")");
    if (s.wedge.empty()) continue;
    const bool found = std::any_of(b.wedges.begin(), b.wedges.end(),
                                   [&](const WedgeSpec& w) { return w.name == s.wedge; });
    if (!found) {
      std::string names;
      for (const WedgeSpec& w : b.wedges)
        if (w.name.rfind("shot.", 0) != 0) names += (names.empty() ? "" : ", ") + w.name;
      fail(s.origin, "shots[" + std::to_string(i) + "].wedge",
           "no wedge named '" + s.wedge + "' (wedges: " + (names.empty() ? "none" : names) + ")");
    }
  }
  for (std::size_t i = 0; i < b.wedges.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (b.wedges[i].name == b.wedges[j].name)
        fail(b.wedges[i].origin, "wedges", "a second wedge named '" + b.wedges[i].name + "'");
  (void)root;
}

}  // namespace

std::string yaml_value_text(const DocNode& n) {
  switch (n.kind) {
    case DocNode::Kind::Null:
      return "null";
    case DocNode::Kind::Scalar: {
      if (n.plain) return n.text;
      std::string q = "\"";
      for (char c : n.text)
        q += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
      return q + "\"";
    }
    case DocNode::Kind::List: {
      std::string s = "[";
      for (std::size_t i = 0; i < n.items.size(); ++i)
        s += (i ? ", " : "") + yaml_value_text(n.items[i]);
      return s + "]";
    }
    case DocNode::Kind::Map: {
      std::string s = "{";
      for (std::size_t i = 0; i < n.entries.size(); ++i)
        s += (i ? ", " : "") + n.entries[i].key + ": " + yaml_value_text(n.entries[i].value);
      return s + "}";
    }
  }
  return "";
}

BatchSpec parse_batch(const std::string& text, const std::string& path) {
  const DocNode root = scenefile::load_document(text, path, "", true);
  if (root.kind != DocNode::Kind::Map)
    fail(root.origin, "", "a batch file is a mapping (version, shots, wedges, ...)");
  check_keys(root, {"version", "name", "output", "shots", "wedges", "farm"}, "");
  BatchSpec b;
  b.path = fs::absolute(path).lexically_normal().string();
  const std::string base_dir = fs::path(b.path).parent_path().string();
  const DocNode* version = scenefile::find_entry(root, "version");
  if (!version) fail(root.origin, "version", "missing (write 'version: 1' first)");
  if (scenefile::to_integer(*version, "version") != 1)
    fail(version->origin, "version", "this shellmpm reads batch files of version 1");
  const DocNode* name = scenefile::find_entry(root, "name");
  b.name = name ? folder_name(*name, "name") : fs::path(b.path).stem().string();
  const DocNode* output = scenefile::find_entry(root, "output");
  b.output =
      resolve(base_dir, output ? scenefile::to_string_value(*output, "output") : "out/" + b.name);
  if (const DocNode* w = scenefile::find_entry(root, "wedges")) {
    need_list(*w, "wedges");
    for (std::size_t i = 0; i < w->items.size(); ++i)
      b.wedges.push_back(read_wedge(w->items[i], "wedges[" + std::to_string(i) + "]", ""));
  }
  const DocNode* shots = scenefile::find_entry(root, "shots");
  if (!shots) fail(root.origin, "shots", "missing: a batch needs at least one shot");
  need_list(*shots, "shots");
  for (std::size_t i = 0; i < shots->items.size(); ++i)
    b.shots.push_back(
        read_shot(shots->items[i], "shots[" + std::to_string(i) + "]", base_dir, b.wedges));
  if (const DocNode* f = scenefile::find_entry(root, "farm")) b.farm = read_farm(*f, "farm");
  check_references(b, root);
  return b;
}

BatchSpec read_batch_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError(path, 0, "", "cannot read the batch file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_batch(ss.str(), path);
}

}  // namespace shellmpm
