#include "io/yaml_key_near.h"

#include <cctype>
#include <sstream>
#include <vector>

namespace shellmpm {
namespace {

struct Entry {
  int col;  ///< column of the key
  std::string key;
  int item = -1;      ///< index of the current list item under this key (-1: none)
  int item_col = -1;  ///< column of that list's "- " markers
};

/// A plain key at the start of s ("name:" followed by a space, end or comment); its length.
std::size_t key_at(const std::string& s, std::string& key) {
  std::size_t i = 0;
  if (s.empty()) return 0;
  if (s[0] == '"' || s[0] == '\'') {  // a quoted key
    const std::size_t end = s.find(s[0], 1);
    if (end == std::string::npos || end + 1 >= s.size() || s[end + 1] != ':') return 0;
    key = s.substr(1, end - 1);
    i = end + 1;
  } else {
    while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_' ||
                            s[i] == '-' || s[i] == '.'))
      ++i;
    if (i == 0 || i >= s.size() || s[i] != ':') return 0;
    key = s.substr(0, i);
  }
  const std::size_t after = i + 1;
  if (after < s.size() && s[after] != ' ' && s[after] != '\t' && s[after] != '#') return 0;
  return after;
}

}  // namespace

std::string yaml_key_near_line(const std::string& text, int line) {
  std::vector<Entry> stack;
  std::istringstream in(text);
  std::string l;
  for (int n = 1; n <= line && std::getline(in, l); ++n) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    int col = 0;
    while (col < static_cast<int>(l.size()) && l[static_cast<std::size_t>(col)] == ' ') ++col;
    std::string rest = l.substr(static_cast<std::size_t>(col));
    if (rest.empty() || rest[0] == '#' || rest.rfind("---", 0) == 0 || rest.rfind("...", 0) == 0)
      continue;
    // List item markers, possibly nested ("- - a").
    while (rest == "-" || rest.rfind("- ", 0) == 0) {
      while (!stack.empty() && stack.back().col > col) stack.pop_back();
      if (!stack.empty() && stack.back().col <= col) {
        Entry& owner = stack.back();
        if (owner.item_col != col) {
          owner.item_col = col;
          owner.item = -1;
        }
        ++owner.item;
      }
      std::size_t skip = 1;
      while (skip < rest.size() && rest[skip] == ' ') ++skip;
      col += static_cast<int>(skip);
      rest = rest.substr(skip);
    }
    std::string key;
    if (key_at(rest, key) == 0) continue;
    while (!stack.empty() && stack.back().col >= col) stack.pop_back();
    stack.push_back({col, key});
  }
  std::string path;
  for (const Entry& e : stack) {
    if (!path.empty()) path += '.';
    path += e.key;
    if (e.item >= 0) path += "[" + std::to_string(e.item) + "]";
  }
  // The index belongs to the key's list; a key that only owns a list is named with it
  // ("shells[0]"), which is what the reader calls the item.
  return path;
}

}  // namespace shellmpm
