// Small helpers shared by the benchmark programs.
#pragma once
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
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

/// One `--name value` option and what it sets.
struct Option {
  const char* name;
  std::function<void(const char*)> set;
};

/// Parses `--name value` pairs against `options`; prints the offending argument (unknown,
/// or without a value) and returns false on the first bad one. `--help` (or `-h`) lists
/// the options and exits 0.
inline bool parse_options(int argc, char** argv, const std::vector<Option>& options) {
  for (int i = 1; i < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--help" || k == "-h") {
      std::printf("usage: %s", argv[0]);
      for (const Option& c : options) std::printf(" [%s VALUE]", c.name);
      std::printf(
          "\nwhat it measures and what each option means: the comment at the top of "
          "its source file in bench/\n");
      std::exit(0);
    }
    const Option* o = nullptr;
    for (const Option& c : options)
      if (k == c.name) o = &c;
    if (o == nullptr || i + 1 >= argc) {
      std::fprintf(stderr, "%s: %s %s\n", argv[0], o ? "no value for" : "unknown option",
                   k.c_str());
      return false;
    }
    o->set(argv[i + 1]);
  }
  return true;
}

/// Options of the sheet benchmarks: --vertices N --steps S --threads 1,2
/// --contact-at surface|stencil.
struct SheetArgs {
  double vertices = 100000;
  int steps = 20;
  std::vector<int> threads = {1, 2};
  std::string contact_at = "surface";  ///< shot.contact_at
  /// Quads per side of a square sheet with about `vertices` vertices.
  int quads_per_side() const { return static_cast<int>(std::round(std::sqrt(vertices))) - 1; }
};

/// Parses SheetArgs; prints the offending option and returns false on an unknown one.
inline bool parse_sheet_args(int argc, char** argv, SheetArgs& a) {
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--vertices")
      a.vertices = std::atof(argv[i + 1]);
    else if (k == "--steps")
      a.steps = std::atoi(argv[i + 1]);
    else if (k == "--threads")
      a.threads = parse_int_list(argv[i + 1]);
    else if (k == "--contact-at" &&
             (std::string(argv[i + 1]) == "surface" || std::string(argv[i + 1]) == "stencil"))
      a.contact_at = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return false;
    }
  }
  return true;
}

}  // namespace shellmpm_bench
