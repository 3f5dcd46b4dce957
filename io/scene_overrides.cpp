#include "io/scene_overrides.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <system_error>
#include <vector>

#include "io/scene_schema.h"
#include "io/user_error.h"

namespace shellmpm::scenefile {
namespace {

struct PathSeg {
  std::string name;  ///< key name, or empty for an index
  std::size_t index = 0;
  bool is_index = false;
};

std::vector<PathSeg> split_override_path(const std::string& key, const std::string& where) {
  std::vector<PathSeg> segs;
  std::size_t i = 0;
  auto bad = [&](const std::string& why) {
    throw UserError(where, 0, "", "bad key path '" + key + "': " + why);
  };
  auto parse_index = [&](const std::string& digits) {
    std::size_t v = 0;
    auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (ec != std::errc() || ptr != digits.data() + digits.size()) bad("bad index " + digits);
    return v;
  };
  while (true) {
    std::size_t j = i;
    while (j < key.size() && key[j] != '.' && key[j] != '[') ++j;
    const std::string name = key.substr(i, j - i);
    if (name.empty()) bad("empty key name");
    const bool digits = std::all_of(name.begin(), name.end(), is_digit);
    segs.push_back(digits ? PathSeg{"", parse_index(name), true} : PathSeg{name, 0, false});
    while (j < key.size() && key[j] == '[') {
      const std::size_t close = key.find(']', j);
      if (close == std::string::npos) bad("missing ']'");
      const std::string idx = key.substr(j + 1, close - j - 1);
      if (idx.empty() || !std::all_of(idx.begin(), idx.end(), is_digit)) {
        bad("list index must be a number, got [" + idx + "]");
      }
      segs.push_back(PathSeg{"", parse_index(idx), true});
      j = close + 1;
    }
    if (j == key.size()) break;
    if (key[j] != '.') bad("expected '.' or '[' after ']'");
    i = j + 1;
  }
  return segs;
}

/// What in an override's text YAML reads as syntax, for the quoting hint: "'{' starts a
/// YAML flow mapping"; empty when nothing stands out.
std::string yaml_special_in(const std::string& text) {
  const std::size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const char c = text[first];
  switch (c) {
    case '{':
      return "'{' starts a YAML flow mapping";
    case '[':
      return "'[' starts a YAML flow list";
    case '#':
      return "'#' at the start starts a YAML comment";
    case '*':
      return "'*' starts a YAML alias";
    case '&':
      return "'&' starts a YAML anchor";
    case '!':
      return "'!' starts a YAML tag";
    case '|':
    case '>':
      return std::string("'") + c + "' starts a YAML block scalar";
    case '%':
      return "'%' starts a YAML directive";
    case '@':
    case '`':
      return std::string("'") + c + "' is reserved in YAML";
    case '"':
    case '\'':
      return std::string("the quote ") + c + " at the start is not closed at the end";
    default:
      break;
  }
  if (text.compare(first, 3, "---") == 0) return "'---' starts a new YAML document";
  if (text.compare(first, 2, "- ") == 0) return "'- ' starts a YAML list item";
  for (std::size_t i = first + 1; i < text.size(); ++i) {
    if (text[i] == '#' && (text[i - 1] == ' ' || text[i - 1] == '\t'))
      return "' #' starts a YAML comment";
    if (text[i] == ':' && (i + 1 == text.size() || text[i + 1] == ' '))
      return "': ' makes it a YAML mapping";
  }
  return "";
}

/// `--set 'KEY="VALUE"'`: the override with VALUE as a YAML double-quoted string, the
/// whole argument in shell single quotes.
std::string quoted_override(const std::string& key, const std::string& value) {
  std::string yaml = "\"";
  for (char c : value) {
    if (c == '"' || c == '\\') yaml += '\\';
    yaml += c;
  }
  yaml += "\"";
  std::string arg = key + "=" + yaml, shell = "'";
  for (char c : arg) shell += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return "--set " + shell + "'";
}

/// Parses an override's value. A value YAML does not read as one plain value (a syntax
/// error, several documents, a comment where a value was meant, a mapping or list for a
/// string key) is an error that names the character and shows the quoted form.
YAML::Node load_override_value(const std::string& text, const std::string& where,
                               const std::string& key, const KeySpec* spec) {
  std::string problem;
  YAML::Node value;
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    problem = "YAML syntax error: " + e.msg;
  }
  if (problem.empty() && docs.size() > 1)
    problem = "YAML reads it as " + std::to_string(docs.size()) + " documents";
  if (problem.empty() && !docs.empty()) value = docs.front();
  const bool blank = text.find_first_not_of(" \t") == std::string::npos;
  if (problem.empty() && (docs.empty() || value.IsNull()) && !blank && text != "null" &&
      text != "~" && text != "Null" && text != "NULL")
    problem = "YAML reads it as nothing (null)";
  const bool wants_word = spec && (spec->type == KeyType::String || spec->type == KeyType::Enum);
  // A plain word cut short by " #" (the rest read as a comment) is not what was meant.
  if (problem.empty() && value.IsScalar() && value.Tag() == "?" &&
      (text.find(" #") != std::string::npos || text.find("\t#") != std::string::npos))
    problem = "YAML reads it as '" + value.Scalar() + "': the rest is a comment";
  if (problem.empty() && wants_word && (value.IsMap() || value.IsSequence()))
    problem = std::string("YAML reads it as a ") + (value.IsMap() ? "mapping" : "list");
  if (problem.empty()) return value;
  const std::string special = yaml_special_in(text);
  throw UserError(where, 0, key,
                  "the value '" + text + "' is not one plain YAML value (" + problem + ")" +
                      (special.empty() ? "" : ": " + special) +
                      ". Quote it for YAML, and the whole argument for the shell: " +
                      quoted_override(key, text));
}

/// Where an override's key path has got to: the node, what the schema says it is, and
/// its schema prefix.
struct OverrideWalk {
  enum class Expect { Map, List, Leaf };
  explicit OverrideWalk(DocNode* root) : cur(root) {}
  DocNode* cur;
  Expect expect = Expect::Map;
  std::string prefix;             // Map: prefix of its keys; List: prefix of its items' keys
  std::string path;               // instance path so far
  const KeySpec* leaf = nullptr;  // the schema entry of the last key segment

  std::string shown() const { return path.empty() ? "the top level" : path; }

  /// Steps into list entry seg.index (which must exist).
  void index(const PathSeg& seg, const std::string& where) {
    const std::string item_path = path + "[" + std::to_string(seg.index) + "]";
    if (expect != Expect::List) {
      throw UserError(where, 0, item_path, shown() + " is not a list");
    }
    if (cur->kind != DocNode::Kind::List) {
      throw UserError(where, 0, item_path,
                      path + " is " + describe(*cur) + " in the scene, not a list");
    }
    if (seg.index >= cur->items.size()) {
      throw UserError(where, 0, item_path,
                      "index " + std::to_string(seg.index) + " is out of range: " + path + " has " +
                          std::to_string(cur->items.size()) + " entr" +
                          (cur->items.size() == 1 ? "y" : "ies"));
    }
    cur = &cur->items[seg.index];
    path = item_path;
    expect = Expect::Map;  // every list in the format is a list of mappings
  }

  /// Steps into key seg.name (a schema key here), adding it to the document if absent.
  void key(const PathSeg& seg, const std::string& where) {
    const std::string key_path = join_key(path, seg.name);
    if (expect == Expect::List) {
      throw UserError(where, 0, key_path,
                      path + " is a list; select an entry by index, e.g. " + path + "[0]." +
                          seg.name + " or " + path + ".0." + seg.name);
    }
    const KeySpec* s = expect == Expect::Map ? find_spec(join_key(prefix, seg.name)) : nullptr;
    if (!s) {
      throw UserError(where, 0, key_path,
                      "unknown key '" + seg.name + "' in " + shown() + " (known: " +
                          (expect == Expect::Map ? known_keys(prefix, nullptr)
                                                 : "none; " + path + " has no sub-keys") +
                          ")");
    }
    if (cur->kind != DocNode::Kind::Map) {
      throw UserError(where, 0, key_path,
                      shown() + " is " + describe(*cur) + " in the scene, not a mapping");
    }
    DocEntry* entry = nullptr;
    for (DocEntry& e : cur->entries)
      if (e.key == seg.name) entry = &e;
    if (!entry) {
      const Origin origin{where, 0};
      DocNode fresh;
      fresh.origin = origin;
      fresh.kind = s->type == KeyType::List ? DocNode::Kind::List : DocNode::Kind::Map;
      cur->entries.push_back(DocEntry{seg.name, origin, fresh});
      entry = &cur->entries.back();
    }
    cur = &entry->value;
    path = key_path;
    leaf = s;
    prefix = child_prefix(*s);
    expect = s->type == KeyType::List                                 ? Expect::List
             : (s->type == KeyType::Map || s->type == KeyType::Shape) ? Expect::Map
                                                                      : Expect::Leaf;
  }
};

}  // namespace

void apply_override(DocNode& root, const std::string& ov) {
  const std::string where = "--set " + ov;
  const std::size_t eq = ov.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw UserError(where, 0, "", "expected KEY=VALUE, e.g. shot.dx=0.01");
  }
  const std::string key = ov.substr(0, eq);
  const std::string text = ov.substr(eq + 1);
  const std::vector<PathSeg> segs = split_override_path(key, where);
  OverrideWalk walk(&root);
  for (std::size_t si = 0; si < segs.size(); ++si) {
    if (segs[si].is_index) {
      walk.index(segs[si], where);
      if (si + 1 == segs.size()) break;
    } else {
      walk.key(segs[si], where);
    }
  }
  const bool item = !segs.empty() && segs.back().is_index;  // a whole list entry: a mapping
  *walk.cur = convert(load_override_value(text, where, walk.path, item ? nullptr : walk.leaf),
                      where, false, 0, walk.path);
}

}  // namespace shellmpm::scenefile
