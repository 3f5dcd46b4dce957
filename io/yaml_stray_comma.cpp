#include "io/yaml_stray_comma.h"

#include <cctype>
#include <sstream>

namespace shellmpm::scenefile {
namespace {

/// True when line[j..] is a block scalar header's tail: indentation and chomping
/// indicators, then only spaces or a comment.
bool block_header_tail(const std::string& line, std::size_t j) {
  while (j < line.size() &&
         (std::isdigit(static_cast<unsigned char>(line[j])) || line[j] == '+' || line[j] == '-'))
    ++j;
  while (j < line.size() && (line[j] == ' ' || line[j] == '\t')) ++j;
  return j == line.size() || line[j] == '#';
}

std::size_t indent_of(const std::string& line) {
  std::size_t k = 0;
  while (k < line.size() && line[k] == ' ') ++k;
  return k;
}

}  // namespace

int stray_flow_entry_line(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  int number = 0, depth = 0;
  char quote = 0;          // inside '...' or "..." (they may span lines)
  long block_parent = -1;  // inside a block scalar: its header line's indent
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t ind = indent_of(line);
    if (block_parent >= 0) {
      if (ind == line.size() || static_cast<long>(ind) > block_parent) continue;
      block_parent = -1;
    }
    bool node_start = quote == 0;  // only indicators so far on this line
    for (std::size_t j = 0; j < line.size(); ++j) {
      const char c = line[j];
      if (quote) {
        if (quote == '"' && c == '\\') {
          ++j;
        } else if (c == quote) {
          if (quote == '\'' && j + 1 < line.size() && line[j + 1] == '\'')
            ++j;  // '' inside '...'
          else
            quote = 0;
        }
        continue;
      }
      if (c == ' ' || c == '\t') continue;
      if (c == '#' && (j == 0 || line[j - 1] == ' ' || line[j - 1] == '\t')) break;
      if (c == ',' && depth == 0 && node_start) return number;
      if (node_start && c == '-' && (j + 1 == line.size() || line[j + 1] == ' ')) continue;
      if (node_start && line.compare(j, 3, "---") == 0 &&
          (j + 3 == line.size() || line[j + 3] == ' '))
        break;  // a document marker starts no node on its own line here
      if (c == '\'' || c == '"') {
        quote = c;
      } else if (c == '[' || c == '{') {
        ++depth;
      } else if ((c == ']' || c == '}') && depth > 0) {
        --depth;
      } else if ((c == '|' || c == '>') && depth == 0 && block_header_tail(line, j + 1)) {
        block_parent = static_cast<long>(ind);
        break;
      }
      node_start = false;
    }
  }
  return 0;
}

}  // namespace shellmpm::scenefile
