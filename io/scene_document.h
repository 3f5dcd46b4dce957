// A scene file as a tree of values that remember where they came from (file and line, or
// the --set override), read from YAML or JSON; and the scalar lexing of that tree (numbers,
// integers) with errors that name the file, line and key.
#pragma once
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace shellmpm::scenefile {

/// Where a value came from: a file and 1-based line, or "--set k=v" with line 0.
struct Origin {
  std::string where;
  int line = 0;
};

struct DocEntry;

/// One value of the document.
struct DocNode {
  enum class Kind { Null, Scalar, List, Map };
  Kind kind = Kind::Null;
  std::string text;               ///< Scalar: the text as written
  bool plain = false;             ///< Scalar: unquoted and untagged (may be a number or boolean)
  std::vector<DocNode> items;     ///< List
  std::vector<DocEntry> entries;  ///< Map, in file order
  Origin origin;
};

/// One key of a mapping and its value.
struct DocEntry {
  std::string key;
  Origin key_origin;
  DocNode value;
};

/// The value of `key` in a mapping, or null.
const DocNode* find_entry(const DocNode& map, const std::string& key);

/// Throws the UserError "where:line: key: msg".
[[noreturn]] void fail(const Origin& o, const std::string& key, const std::string& msg);

/// "nothing (null)", "'abc'", "the string \"abc\"", "a list of 2 items", "a mapping".
std::string describe(const DocNode& n);

/// Converts a yaml-cpp node. `from_file`: lines come from marks; otherwise line 0.
/// `fallback_line` is used for nodes without a useful mark (null values). `path` is the
/// node's key path, for messages (duplicate keys, non-scalar keys).
DocNode convert(const YAML::Node& n, const std::string& where, bool from_file, int fallback_line,
                const std::string& path);

/// Parses YAML text into one document tree; syntax errors are UserErrors at the file and
/// line (and the key, found by indentation when the text does not parse).
DocNode load_document(const std::string& text, const std::string& where, const std::string& key,
                      bool from_file);

bool is_digit(char c);

/// A finite double from a plain scalar, or a UserError at the node naming `key`.
double to_number(const DocNode& n, const std::string& key);

/// An integer (no decimal point or exponent) from a plain scalar, or a UserError.
long long to_integer(const DocNode& n, const std::string& key);

/// The text of any scalar, or a UserError for a list, mapping or null.
std::string to_string_value(const DocNode& n, const std::string& key);

}  // namespace shellmpm::scenefile
