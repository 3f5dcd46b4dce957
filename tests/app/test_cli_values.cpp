// Values through the command line (issue 12): what overflows float or could never advance
// is an exit-2 error at its key for check and run alike (it used to end in an internal
// check, or hang); values at the edges of the ranges run without one; output names with
// folders are created; Latin-1 text is refused at its line; --set shows how to quote.
#include <catch2/catch.hpp>

#include <filesystem>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

const std::string kCloth = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/cloth_swing.yaml";

std::string write_scene(const TempDir& d, std::string text, const std::string& extra = "") {
  text.replace(text.find("OUT"), 3, d.file("out"));
  return d.write("scene.yaml", text + extra);
}

/// Single-quotes an argument for /bin/sh.
std::string sh(const std::string& a) {
  std::string q = "'";
  for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool has(const CmdResult& r, const std::string& s) {
  return r.output.find(s) != std::string::npos;
}

}  // namespace

TEST_CASE("CLI values: float overflow and degenerate timing are exit 2 at their key",
          "[cli][values]") {
  TempDir d("cli_values");
  struct Case {
    std::string set, key;
  };
  const Case cases[] = {
      {"shell_materials[0].thickness=1e30", "shell_materials[0].thickness"},
      {"shells[0].translate=[0,-3.5e38,0]", "shells[0].translate"},
      {"shot.fps=1e-300", "shot.fps"},
      {"shot.dt_min=1e-301", "shot.dt_min"},
      {"shot.fps=0.01", "shot.fps"},  // 100 s frames of up to 1e8 steps of dt_min
  };
  for (const Case& c : cases) {
    for (const std::string& cmd : {std::string("check "), "run -o " + d.file("out") + " "}) {
      const CmdResult r = run_shellmpm(cmd + kCloth + " --set " + sh(c.set));
      INFO(cmd << c.set << "\n" << r.output);
      CHECK(r.code == 2);
      CHECK(has(r, "--set " + c.set + ": " + c.key + ": "));
      CHECK(!has(r, "internal check"));
    }
  }
  CHECK(!std::filesystem::exists(d.file("out")));
}

TEST_CASE("CLI values: the edges of the ranges run without an internal error", "[cli][values]") {
  TempDir d("cli_edges");
  const std::string s = write_scene(d, kTinyJellyScene,
                                    "shell_materials:\n"
                                    "  - {name: foil}\n"
                                    "shells:\n"
                                    "  - {material: foil, geometry: {type: sheet, size: [0.6, "
                                    "0.6], resolution: [4, 4]}, translate: [0, 0.2, 0]}\n");
  const std::vector<std::vector<std::string>> edges = {
      {"materials[0].youngs_modulus=1e12", "materials[0].poisson_ratio=0.49",
       "materials[0].density=0.1"},
      {"shell_materials[0].youngs_modulus=1e12", "shell_materials[0].thickness=1",
       "shell_materials[0].density=0.1"},
      {"shell_materials[0].youngs_modulus=1", "shell_materials[0].thickness=1e-7",
       "shell_materials[0].density=1e5", "materials[0].youngs_modulus=1"},
      {"shot.gravity=[0,-1e4,0]", "sources[0].velocity=[1e5,0,0]", "shells[0].velocity=[0,-1e5,0]"},
      {"shells[0].pressure=1e12", "shell_materials[0].yield_stress=1e12"},
      {"shot.fps=1e5", "shot.dt_max=1e-9", "shot.dt_min=1e-9"},
  };
  for (const auto& set : edges) {
    std::string args;
    for (const std::string& a : set) args += " --set " + sh(a);
    const CmdResult r = run_shellmpm("run " + s + " -q" + args);
    INFO(args << "\n" << r.output);
    CHECK((r.code == 0 || r.code == 1));
    CHECK(!has(r, "internal check"));
  }
}

TEST_CASE("CLI values: output names with folders are created before the run", "[cli][values]") {
  TempDir d("cli_folders");
  const std::string s = write_scene(d, kTinyJellyScene,
                                    "  stats: logs/stats.json\n"
                                    "  density_pattern: vdb/density.####.vdb\n"
                                    "  particles: true\n"
                                    "  particles_pattern: points/p.####.ply\n");
  const CmdResult c = run_shellmpm("check " + s);
  INFO(c.output);
  REQUIRE(c.code == 0);
  CHECK(!std::filesystem::exists(d.file("out")));  // check writes nothing
  const CmdResult r = run_shellmpm("run " + s + " -q");
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(std::filesystem::exists(d.file("out/logs/stats.json")));
  CHECK(std::filesystem::exists(d.file("out/vdb/density.0002.vdb")));
  CHECK(std::filesystem::exists(d.file("out/points/p.0002.ply")));
  const CmdResult bad = run_shellmpm("check " + s + " --set " + sh("output.stats=/tmp/s.json"));
  CHECK(bad.code == 2);
  CHECK(has(bad, "output.stats: must be relative to output.directory"));
}

TEST_CASE("CLI values: a Latin-1 comment is refused at its line by check and run",
          "[cli][values]") {
  TempDir d("cli_latin1");
  const std::string s = write_scene(d, kTinyJellyScene, "# r\xe9sum\xe9 of the shot\n");
  for (const char* cmd : {"check ", "run "}) {
    const CmdResult r = run_shellmpm(std::string(cmd) + s);
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(has(r, "scene.yaml:13: not valid UTF-8: byte 0xE9 at column 4"));
    CHECK(!has(r, "json"));
  }
  CHECK(!std::filesystem::exists(d.file("out")));
}

TEST_CASE("CLI values: an unquoted pattern in --set says how to quote it", "[cli][values]") {
  TempDir d("cli_quote");
  const std::string s = write_scene(d, kTinyJellyScene);
  const CmdResult r =
      run_shellmpm("check " + s + " --set " + sh("output.shell_pattern={name}.####.ply"));
  INFO(r.output);
  REQUIRE(r.code == 2);
  CHECK(has(r, "'{' starts a YAML flow mapping"));
  const std::string suggestion = "--set 'output.shell_pattern=\"{name}.####.ply\"'";
  REQUIRE(has(r, suggestion));
  // The suggested argument, pasted into a shell, works.
  const CmdResult ok = run_shellmpm("check " + s + " " + suggestion);
  INFO(ok.output);
  CHECK(ok.code == 0);
}

TEST_CASE("CLI values: check with a quality preset prints the study's measured errors",
          "[cli][values]") {
  // It read freed memory (a pointer into a temporary copy of the runs) and ended in a JSON
  // library error, exit 1.
  const std::string scene = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/study/incline_sheet.yaml";
  for (const char* q : {"draft", "preview", "production", "final"}) {
    const CmdResult r = run_shellmpm("check " + scene + " --quality " + q);
    INFO(q << ": " << r.output);
    CHECK(r.code == 0);
    CHECK(has(r, std::string("quality ") + q + ": dx"));
    CHECK(has(r, "measured with this preset (docs/accuracy.md): incline_collider "));
    CHECK(has(r, " incline_sheet "));
    CHECK(!has(r, "json"));
  }
}
