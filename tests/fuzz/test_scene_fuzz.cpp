// The scene-file fuzzer (issue 12): byte-level and structural mutations of every example
// scene (scenes/, scenes/stress/, tests/data/scenes/) go through `shellmpm check`, and the
// accepted ones through a short `run` (two frames at 1000 fps). Every case must end in
// exit 0, 1 (a run that stopped on its physics) or 2 (bad input), within a time limit:
// no crash, no hang, no internal check (exit 3). Every exit-2 message names the file,
// and the line and key where they can be known:
//   "error: FILE:LINE: KEY: message"                           (a value or key)
//   "error: FILE:LINE: YAML syntax error in or after key KEY: ..." (text that does not parse)
//   "error: FILE:LINE: YAML syntax error (before the first key): ..."
//   "error: FILE:LINE: ... at the top level" (a top-level entry that is not a key)
// and the whole-file forms listed in kFileLevel (the key cannot be known: the file is
// not UTF-8, is several documents, or a mesh/asset it names is broken).
//
// [fuzz_fast] (the default suite): 300 cases, runs only for the cheap scenes. [fuzz]: 3000
// cases, a run for every fifth accepted case (`ctest --test-dir build -L fuzz`).
// SHELLMPM_FUZZ_KEEP=DIR keeps every failing case's file in DIR.
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "tests/app/cli_harness.h"
#include "tests/support/temp_dir.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

namespace {

struct Seed {
  fs::path path;
  std::string text;
  bool cheap;  ///< a short run takes well under a second
};

std::vector<Seed> seeds() {
  const fs::path root(SHELLMPM_SOURCE_DIR);
  std::vector<fs::path> files;
  for (const char* dir : {"scenes", "scenes/stress", "scenes/study", "tests/data/scenes"})
    for (const auto& e : fs::directory_iterator(root / dir))
      if (e.path().extension() == ".yaml" && e.path().filename().string().rfind("bad_", 0) != 0)
        files.push_back(e.path());
  std::sort(files.begin(), files.end());
  const std::vector<std::string> cheap = {"minimal.yaml",      "shells.yaml", "guard_pair.yaml",
                                          "elastic_drop.yaml", "flag.yaml",   "cloth_swing.yaml"};
  std::vector<Seed> out;
  for (const fs::path& f : files)
    out.push_back({f, read_text(f.string()),
                   std::find(cheap.begin(), cheap.end(), f.filename().string()) != cheap.end()});
  return out;
}

const std::vector<std::string> kTokens = {
    ":",   "- ", "[",      "]",     "{", "}", "#", "\"", "'",        "\t",   "\n",
    "&a ", "*a", "!!str ", "---\n", "%", "|", ">", "? ", "\xc3\x28", "\xff", std::string(1, '\0'),
    ",",   "  ", "\\",     "@",     "`"};
const std::vector<std::string> kValues = {"-1",
                                          "0",
                                          "1e308",
                                          "1e400",
                                          "-1e400",
                                          ".nan",
                                          ".inf",
                                          "-.inf",
                                          "nan",
                                          "1e-320",
                                          "99999999999999999999",
                                          "[]",
                                          "{}",
                                          "[1, 2]",
                                          "~",
                                          "\"\"",
                                          "yes",
                                          "abc",
                                          "0x10",
                                          std::string(3000, 'x'),
                                          "[1e30, 1e30, 1e30]",
                                          "-0",
                                          "[-1e38, 0, 0]",
                                          "2147483648",
                                          "1.5",
                                          "[0, 0, 0]",
                                          "[.nan, 0, 0]",
                                          "\"{name}.ply\"",
                                          "/nonexistent/x.obj",
                                          "-2147483649"};

/// One mutation of s with r.
void mutate(std::string& s, std::mt19937_64& r) {
  const auto pick = [&](std::size_t n) {
    return n == 0 ? std::size_t(0) : static_cast<std::size_t>(r() % n);
  };
  // Line view for the structural mutations.
  std::vector<std::string> lines;
  {
    std::size_t a = 0;
    while (a <= s.size()) {
      const std::size_t b = s.find('\n', a);
      lines.push_back(s.substr(a, b == std::string::npos ? std::string::npos : b - a));
      if (b == std::string::npos) break;
      a = b + 1;
    }
  }
  const auto join = [&]() {
    std::string t;
    for (std::size_t i = 0; i < lines.size(); ++i)
      t += lines[i] + (i + 1 < lines.size() ? "\n" : "");
    s = t;
  };
  switch (r() % 12) {
    case 0:  // replace a byte
      if (!s.empty()) s[pick(s.size())] = static_cast<char>(r() % 256);
      break;
    case 1: {  // delete a range
      if (s.empty()) break;
      const std::size_t a = pick(s.size());
      s.erase(a, 1 + pick(20));
      break;
    }
    case 2: {  // duplicate a range
      if (s.empty()) break;
      const std::size_t a = pick(s.size());
      s.insert(a, s.substr(a, 1 + pick(40)));
      break;
    }
    case 3:  // insert a token
      s.insert(pick(s.size() + 1), kTokens[pick(kTokens.size())]);
      break;
    case 4:  // truncate
      s.resize(pick(s.size() + 1));
      break;
    case 5:  // delete a line
      if (lines.size() > 1)
        lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(pick(lines.size())));
      join();
      break;
    case 6: {  // duplicate a line
      const std::size_t i = pick(lines.size());
      lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
      join();
      break;
    }
    case 7:  // swap two lines
      std::swap(lines[pick(lines.size())], lines[pick(lines.size())]);
      join();
      break;
    case 8: {  // indent or dedent a line
      std::string& l = lines[pick(lines.size())];
      if (r() % 2 && l.rfind("  ", 0) == 0)
        l.erase(0, 1 + pick(2));
      else
        l.insert(0, std::string(1 + pick(4), ' '));
      join();
      break;
    }
    case 9:
    case 10: {  // a value after "key: " (or inside a flow list) replaced by a nasty one
      std::vector<std::size_t> at;
      for (std::size_t i = 0; i + 2 < s.size(); ++i)
        if ((s[i] == ':' && s[i + 1] == ' ') || (s[i] == ',' && s[i + 1] == ' ') ||
            (s[i] == '[' && s[i + 1] != ']'))
          at.push_back(i + (s[i] == '[' ? 1 : 2));
      if (at.empty()) break;
      const std::size_t a = at[pick(at.size())];
      std::size_t b = a;
      while (b < s.size() && s[b] != ',' && s[b] != '\n' && s[b] != ']' && s[b] != '}' &&
             s[b] != '#')
        ++b;
      s.replace(a, b - a, kValues[pick(kValues.size())]);
      break;
    }
    default: {  // a key misspelt: one character of a "key:" dropped
      std::vector<std::size_t> at;
      for (std::size_t i = 1; i + 1 < s.size(); ++i)
        if (s[i] == ':' && s[i + 1] == ' ' && std::isalpha(static_cast<unsigned char>(s[i - 1])))
          at.push_back(i - 1);
      if (!at.empty()) s.erase(at[pick(at.size())], 1);
      break;
    }
  }
}

/// Runs shellmpm with a time limit; code 124 or 137 is a hang, >= 128 a signal.
CmdResult run_limited(const std::string& args, int seconds) {
  return run_shellmpm_prefixed("timeout -s KILL " + std::to_string(seconds) + " ", args);
}

/// Key-less whole-file messages (the key cannot be known there).
const std::vector<std::string> kFileLevel = {"YAML documents", "not valid UTF-8",
                                             "YAML syntax error",
                                             "expected a mapping of keys at the top level"};

/// Whether an exit-2 message names the file, the line and the key (or a known key-less
/// form). Returns an empty string when it does, else why not.
std::string message_problem(const std::string& out, const std::string& file) {
  const std::size_t e = out.find("error: ");
  if (e == std::string::npos) return "no 'error: ' line";
  const std::string line = out.substr(e, out.find('\n', e) - e);
  // The file, or a file it names (a mesh, an SDF), with a line where there is one.
  static const std::regex located(R"(^error: ([^:]+):(\d+): (.*)$)");
  std::smatch m;
  if (!std::regex_match(line, m, located)) {
    // Messages about another file the scene names (a mesh) give that file, maybe no line.
    if (line.find(file) == std::string::npos && line.find("error: /") != 0 &&
        line.find("error: scenes/") != 0)
      return "names no file: " + line;
    return "";
  }
  if (m[1].str() != file) return "";  // another file (an asset): its own form
  const std::string rest = m[3].str();
  for (const std::string& f : kFileLevel)
    if (rest.find(f) == 0) return "";
  // A key path (a misspelt key is named as written, e.g. "shot.dom[ain").
  static const std::regex keyed(R"(^[A-Za-z_"'][^ ]*: .*)");
  if (std::regex_match(rest, keyed)) return "";
  // A misspelt key with spaces in it, named as written.
  if (rest.find(": unknown key '") != std::string::npos ||
      rest.find(": duplicate key '") != std::string::npos)
    return "";
  if (rest.find(" at the top level") != std::string::npos) return "";  // no key to name
  return "names no key: " + line;
}

void fuzz(int cases, bool cheap_runs_only, int run_every) {
  const std::vector<Seed> all = seeds();
  REQUIRE(all.size() >= 20);
  TempDir d("fuzz");
  std::mt19937_64 r(20261202);
  const char* keep = std::getenv("SHELLMPM_FUZZ_KEEP");
  int accepted = 0, rejected = 0, runs = 0, bad = 0;
  for (int c = 0; c < cases; ++c) {
    const Seed& seed = all[static_cast<std::size_t>(r() % all.size())];
    std::string text = seed.text;
    const int n = r() % 4 == 0 ? 2 : 1;
    for (int k = 0; k < n; ++k) mutate(text, r);
    // Next to the seed's assets (relative mesh paths), in the temporary folder.
    const fs::path dir = fs::path(d.file("c" + std::to_string(c % 50)));
    fs::create_directories(dir);
    const fs::path assets = seed.path.parent_path() / "assets";
    if (fs::exists(assets) && !fs::exists(dir / "assets"))
      fs::create_directory_symlink(assets, dir / "assets");
    if (!fs::exists(assets) && fs::exists(dir / "assets")) fs::remove(dir / "assets");
    const std::string file = (dir / "scene.yaml").string();
    std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
    const CmdResult ck = run_limited("check " + file, 60);
    std::string why;
    if (ck.code == 2) {
      ++rejected;
      why = message_problem(ck.output, file);
    } else if (ck.code == 0) {
      ++accepted;
      if ((!cheap_runs_only || seed.cheap) && accepted % run_every == 0) {
        ++runs;
        const CmdResult rn = run_limited("run " + file +
                                             " -q --set shot.frames=[1,2] --set shot.fps=1000"
                                             " --set output.checkpoint_every=0 -o " +
                                             (dir / "out").string(),
                                         120);
        if (rn.code != 0 && rn.code != 1 && rn.code != 2)
          why = "run exit " + std::to_string(rn.code) + ": " + rn.output.substr(0, 400);
      }
    } else {
      why = "check exit " + std::to_string(ck.code) + ": " + ck.output.substr(0, 400);
    }
    // SHELLMPM_FUZZ_KEEP with SHELLMPM_FUZZ_CASE=N also keeps case N whatever it gave (to
    // replay a case that failed only on a slower build, such as the sanitizer's).
    const char* only = std::getenv("SHELLMPM_FUZZ_CASE");
    if (keep && only && std::atoi(only) == c) {
      fs::create_directories(keep);
      fs::copy_file(file, fs::path(keep) / ("case" + std::to_string(c) + ".yaml"),
                    fs::copy_options::overwrite_existing);
    }
    if (!why.empty()) {
      ++bad;
      UNSCOPED_INFO("case " << c << " (from " << seed.path.filename().string() << "): " << why);
      if (keep) {
        fs::create_directories(keep);
        fs::copy_file(file, fs::path(keep) / ("case" + std::to_string(c) + ".yaml"),
                      fs::copy_options::overwrite_existing);
      }
    }
  }
  WARN("fuzz: " << cases << " cases, " << rejected << " rejected, " << accepted << " accepted, "
                << runs << " runs, " << bad << " failures");
  CHECK(bad == 0);
  // The mutations reach both sides (the fuzzer is not only making garbage).
  CHECK(rejected > cases / 10);
  CHECK(accepted > cases / 20);
}

}  // namespace

TEST_CASE("scene fuzzer: 300 mutated scenes, no crash, hang or internal error", "[fuzz_fast]") {
  fuzz(300, true, 1);
}

TEST_CASE("scene fuzzer: 3000 mutated scenes", "[fuzz]") {
  fuzz(3000, false, 5);
}
