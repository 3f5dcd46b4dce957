#include "io/scene_document.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

#include "io/scene_schema.h"
#include "io/user_error.h"
#include "io/yaml_key_near.h"
#include "io/yaml_stray_comma.h"
#include "sim/core/check.h"

namespace shellmpm::scenefile {
namespace {

/// A YAML syntax error at 1-based `line` of the text (0: unknown): for a file, at the file
/// and line, with the key found from indentation (the text does not parse;
/// io/yaml_key_near.h); for a --set value, at its key.
[[noreturn]] void syntax_error(const std::string& text, const std::string& where,
                               const std::string& key, bool from_file, int line,
                               const std::string& what) {
  if (!from_file || line <= 0) throw UserError(where, 0, key, "YAML syntax error: " + what);
  const std::string near = yaml_key_near_line(text, line);
  throw UserError(
      where, line, "",
      "YAML syntax error" +
          (near.empty() ? std::string(" (before the first key)") : " in or after key " + near) +
          ": " + what);
}

/// Parses YAML text into one yaml-cpp document; syntax errors are UserErrors at the file and
/// line.
YAML::Node load_yaml(const std::string& text, const std::string& where, const std::string& key,
                     bool from_file) {
  // yaml-cpp would never return on these (io/yaml_stray_comma.h).
  if (const int bad = stray_flow_entry_line(text))
    syntax_error(text, where, key, from_file, bad,
                 "a ',' where a value should start (outside [...] or {...})");
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    syntax_error(text, where, key, from_file, e.mark.line >= 0 ? e.mark.line + 1 : 0, e.msg);
  }
  if (docs.size() > 1) {
    throw UserError(where, 0, key,
                    "holds " + std::to_string(docs.size()) +
                        " YAML documents ('---' separators); a scene is one document");
  }
  return docs.empty() ? YAML::Node() : docs.front();
}

/// Decimal integer: [+-]?[0-9]+
bool int_syntax(const std::string& s) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i == s.size()) return false;
  for (; i < s.size(); ++i)
    if (!is_digit(s[i])) return false;
  return true;
}

/// Decimal real: [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?
bool real_syntax(const std::string& s) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  std::size_t digits = 0;
  while (i < s.size() && is_digit(s[i])) ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && is_digit(s[i])) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    std::size_t exp_digits = 0;
    while (i < s.size() && is_digit(s[i])) ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  return i == s.size();
}

bool non_finite_word(std::string s) {
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) s.erase(0, 1);
  if (!s.empty() && s[0] == '.') s.erase(0, 1);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s == "inf" || s == "nan" || s == "infinity";
}

const char* skip_plus(const std::string& s) {
  return s.c_str() + (s[0] == '+' ? 1 : 0);
}

}  // namespace

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

const DocNode* find_entry(const DocNode& map, const std::string& key) {
  for (const DocEntry& e : map.entries)
    if (e.key == key) return &e.value;
  return nullptr;
}

[[noreturn]] void fail(const Origin& o, const std::string& key, const std::string& msg) {
  throw UserError(o.where, o.line, key, msg);
}

std::string describe(const DocNode& n) {
  switch (n.kind) {
    case DocNode::Kind::Null:
      return "nothing (null)";
    case DocNode::Kind::Scalar:
      return n.plain ? "'" + n.text + "'" : "the string \"" + n.text + "\"";
    case DocNode::Kind::List:
      return "a list of " + std::to_string(n.items.size()) + " item" +
             (n.items.size() == 1 ? "" : "s");
    case DocNode::Kind::Map:
      return "a mapping";
  }
  return "?";
}

/// Converts a yaml-cpp node. `from_file`: lines come from marks; otherwise line 0.
/// `fallback_line` is used for nodes without a useful mark (null values).
DocNode convert(const YAML::Node& n, const std::string& where, bool from_file, int fallback_line,
                const std::string& path) {
  DocNode d;
  const int mark_line = n.Mark().line;
  d.origin.where = where;
  d.origin.line = !from_file ? 0 : (mark_line >= 0 && !n.IsNull()) ? mark_line + 1 : fallback_line;
  switch (n.Type()) {
    case YAML::NodeType::Undefined:
    case YAML::NodeType::Null:
      d.kind = DocNode::Kind::Null;
      break;
    case YAML::NodeType::Scalar:
      d.kind = DocNode::Kind::Scalar;
      d.text = n.Scalar();
      d.plain = n.Tag() == "?";
      break;
    case YAML::NodeType::Sequence: {
      d.kind = DocNode::Kind::List;
      std::size_t i = 0;
      for (const YAML::Node& item : n) {
        d.items.push_back(
            convert(item, where, from_file, d.origin.line, path + "[" + std::to_string(i) + "]"));
        ++i;
      }
      break;
    }
    case YAML::NodeType::Map:
      d.kind = DocNode::Kind::Map;
      for (auto it = n.begin(); it != n.end(); ++it) {
        Origin ko{where, 0};
        if (from_file) {
          const int kl = it->first.Mark().line;
          ko.line = kl >= 0 ? kl + 1 : d.origin.line;
        }
        if (!it->first.IsScalar()) {
          fail(ko, path,
               "mapping keys must be plain words, got a " +
                   std::string(it->first.IsNull() ? "null" : "list or mapping") + " as a key" +
                   (path.empty() ? " at the top level" : ""));
        }
        const std::string key = it->first.Scalar();
        const std::string key_path = join_key(path, key);
        for (const DocEntry& e : d.entries) {
          if (e.key == key) {
            fail(ko, key_path,
                 "duplicate key '" + key + "'" +
                     (e.key_origin.line > 0
                          ? " (first at line " + std::to_string(e.key_origin.line) + ")"
                          : ""));
          }
        }
        d.entries.push_back(
            DocEntry{key, ko, convert(it->second, where, from_file, ko.line, key_path)});
      }
      break;
  }
  return d;
}

DocNode load_document(const std::string& text, const std::string& where, const std::string& key,
                      bool from_file) {
  return convert(load_yaml(text, where, key, from_file), where, from_file, 0, key);
}

double to_number(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Scalar || !n.plain) {
    fail(n.origin, key,
         "expected a number, got " + describe(n) +
             (n.kind == DocNode::Kind::Scalar ? " (write numbers without quotes)" : ""));
  }
  if (non_finite_word(n.text)) fail(n.origin, key, "must be a finite number, got " + n.text);
  if (!real_syntax(n.text)) fail(n.origin, key, "expected a number, got '" + n.text + "'");
  double x = 0;
  const char* first = skip_plus(n.text);
  const char* last = n.text.c_str() + n.text.size();
  auto [ptr, ec] = std::from_chars(first, last, x);
  if (ec == std::errc::result_out_of_range) {
    fail(n.origin, key, "number " + n.text + " is out of the range of a double");
  }
  SHELLMPM_CHECK(ec == std::errc() && ptr == last, "from_chars on '" << n.text << "'");
  if (!std::isfinite(x)) fail(n.origin, key, "must be a finite number, got " + n.text);
  return x;
}

long long to_integer(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Scalar || !n.plain) {
    fail(n.origin, key,
         "expected an integer, got " + describe(n) +
             (n.kind == DocNode::Kind::Scalar ? " (write numbers without quotes)" : ""));
  }
  if (!int_syntax(n.text)) {
    fail(n.origin, key,
         "expected an integer, got '" + n.text + "'" +
             (real_syntax(n.text) ? " (no decimal point or exponent)" : ""));
  }
  long long v = 0;
  const char* first = skip_plus(n.text);
  const char* last = n.text.c_str() + n.text.size();
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec == std::errc::result_out_of_range) {
    fail(n.origin, key, "integer " + n.text + " is too large");
  }
  SHELLMPM_CHECK(ec == std::errc() && ptr == last, "from_chars on '" << n.text << "'");
  return v;
}

std::string to_string_value(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Scalar) fail(n.origin, key, "expected a string, got " + describe(n));
  return n.text;
}

}  // namespace shellmpm::scenefile
