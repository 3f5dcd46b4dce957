// Small helpers shared by the benchmark programs.
#pragma once
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace shellmpm_bench {

/// "1,2,4" -> {1, 2, 4}.
inline std::vector<int> parse_int_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string t;
  while (std::getline(ss, t, ',')) out.push_back(std::atoi(t.c_str()));
  return out;
}

}  // namespace shellmpm_bench
