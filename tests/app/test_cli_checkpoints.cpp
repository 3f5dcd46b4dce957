// --resume with damaged checkpoints, through the binary: a byte damaged in any section
// of a real checkpoint (header, particles, statistics, shells, checksum) makes the run
// fall back to the previous checkpoint, say so and give the uninterrupted run's results;
// with no intact checkpoint it stops with exit 2 naming the files. Stray checkpoint
// names and leftover temporaries are dealt with; --frames numbers are range-checked.
#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/app/cli_harness.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

namespace {

// Sand (plastic particles) poured on a pinned cloth (with denting plasticity) with
// contact: every checkpoint section has data.
const char* kScene = R"(version: 1
shot:
  frames: [1, 4]
  dx: 0.05
  domain: {min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5]}
materials:
  - {name: sand, type: sand, youngs_modulus: 1.0e5, poisson_ratio: 0.3, density: 1600}
sources:
  - {material: sand, shape: {type: box, min: [-0.1, 0.5, -0.1], max: [0.1, 0.6, 0.1]}}
shell_materials:
  - {name: cotton, youngs_modulus: 2.0e4, poisson_ratio: 0.3, density: 400, thickness: 0.001, damping: 0.2, yield_stress: 1.0e3}
shells:
  - name: cloth
    material: cotton
    geometry: {type: sheet, size: [0.6, 0.6], resolution: [16, 16]}
    translate: [0, 0.4, 0]
    pins:
      - indices: [0, 16, 272, 288]
output:
  directory: OUT
  checkpoint_every: 1
  particles: true
)";

std::string make_scene(const TempDir& d) {
  std::string t = kScene;
  t.replace(t.find("OUT"), 3, d.file("default_out"));
  return d.write("sand_cloth.yaml", t);
}

struct Section {
  std::string name;
  std::size_t offset;  ///< a byte inside it
};

/// Byte offsets inside each section of a checkpoint, from the layout documented in
/// io/checkpoint.h (read here independently of the reader).
std::vector<Section> sections(const std::string& b) {
  auto u64 = [&](std::size_t at) {
    std::uint64_t v;
    REQUIRE(at + 8 <= b.size());
    std::memcpy(&v, b.data() + at, 8);
    return v;
  };
  std::uint32_t real = 0;
  std::memcpy(&real, b.data() + 8, 4);
  REQUIRE((real == 4 || real == 8));
  std::vector<Section> s = {
      {"magic", 3},        {"precision", 8}, {"payload size", 13},   {"scene fingerprint", 22},
      {"frame", 28},       {"time", 36},     {"particle count", 40}, {"next id", 49},
      {"plastic flag", 52}};
  std::size_t at = 53;
  auto array = [&](const std::string& name, std::size_t elem) {
    const std::uint64_t n = u64(at);
    INFO(name);
    REQUIRE(n > 0);  // every section is exercised
    s.push_back({name + " length", at + 1});
    s.push_back({name, at + 8 + n * elem / 2});
    at += 8 + n * elem;
  };
  for (const auto& [name, elem] : std::vector<std::pair<std::string, std::size_t>>{
           {"particle positions", 3 * real},
           {"particle velocities", 3 * real},
           {"particle APIC matrices", 9 * real},
           {"particle deformation gradients", 9 * real},
           {"particle kind materials", 2},
           {"particle kind volumes", real},
           {"particle kinds", 2},
           {"particle ids", 4},
           {"particle plastic state", real}})
    array(name, elem);
  const std::uint64_t stats = u64(at);
  s.push_back({"statistics", at + 8 + stats / 2});
  at += 8 + stats;
  REQUIRE(u64(at) == 1);
  s.push_back({"shell count", at});
  s.push_back({"accumulated work", at + 8 + 3});
  at += 8 + 16;
  for (const auto& [name, elem] :
       std::vector<std::pair<std::string, std::size_t>>{{"shell positions", 3 * real},
                                                        {"shell velocities", 3 * real},
                                                        {"shell plastic state", real},
                                                        {"shell APIC matrices", 9 * real},
                                                        {"shell contact normals", 3 * real},
                                                        {"shell contact states", 1}})
    array(name, elem);
  s.push_back({"checksum", at + 1});
  s.push_back({"end marker", at + 4 + 6});
  REQUIRE(at + 12 == b.size());
  return s;
}

/// The statistics without the wall-clock timings.
nlohmann::json physics_stats(const std::string& path) {
  auto j = nlohmann::json::parse(read_text(path));
  for (auto& f : j["frames"]) f.erase("wall");
  return j["frames"];
}

/// The resumed run's frames 3 and 4 match the uninterrupted run's, byte for byte.
void expect_same_results(const std::string& full, const std::string& resumed) {
  for (const char* f :
       {"cloth.0003.ply", "cloth.0004.ply", "particles.0003.ply", "particles.0004.ply"}) {
    INFO(f);
    const std::string a = read_text(full + "/" + f);
    REQUIRE(!a.empty());
    CHECK(a == read_text(resumed + "/" + f));
  }
  CHECK(physics_stats(full + "/stats.json").dump() ==
        physics_stats(resumed + "/stats.json").dump());
}

void damage(const std::string& path, std::size_t offset) {
  std::string b = read_text(path);
  REQUIRE(offset < b.size());
  b[offset] = static_cast<char>(b[offset] ^ 0xFF);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << b;
}

/// A fresh copy of the interrupted run's output folder.
std::string copy_of(const TempDir& d, const std::string& from, const std::string& name) {
  const std::string to = d.file(name);
  fs::remove_all(to);
  fs::copy(from, to, fs::copy_options::recursive);
  return to;
}

/// The uninterrupted run and one killed after frame 3 (checkpoints 1, 2 and 3).
struct Runs {
  TempDir d{"ck_fallback"};
  std::string scene = make_scene(d);
  std::string full = d.file("full"), part = d.file("part");
  Runs() {
    REQUIRE(run_shellmpm("run " + scene + " -q -o " + full).code == 0);
    REQUIRE(run_shellmpm("run " + scene + " -q --frames 1-3 -o " + part).code == 0);
  }
  /// Damages checkpoint.0003.bin at `offset` (or cuts it in half if offset is npos) in
  /// a copy of the killed run, resumes it and expects the fallback to frame 2, with the
  /// uninterrupted run's results.
  void expect_fallback(const std::string& what, std::size_t offset) {
    INFO("damaged: " << what << " (byte " << offset << ")");
    const std::string out = copy_of(d, part, "case");
    const std::string ck = out + "/checkpoint.0003.bin";
    if (offset == std::string::npos) {
      const std::string b = read_text(ck);
      std::ofstream(ck, std::ios::binary | std::ios::trunc) << b.substr(0, b.size() / 2);
    } else {
      damage(ck, offset);
    }
    const CmdResult r = run_shellmpm("run " + scene + " --resume -o " + out);
    INFO(r.output);
    REQUIRE(r.code == 0);
    CHECK(r.output.find(ck + ": damaged checkpoint") != std::string::npos);
    CHECK(r.output.find("resuming from the older checkpoint") != std::string::npos);
    CHECK(r.output.find("resuming after frame 2") != std::string::npos);
    expect_same_results(full, out);
    const auto header = nlohmann::json::parse(read_text(out + "/stats.json"));
    CHECK(header["resume"]["frame"] == 2);
    REQUIRE(header["resume"]["damaged"].size() == 1);
    CHECK(header["resume"]["damaged"][0]["file"] == ck);
  }
};

}  // namespace

TEST_CASE("CLI: a damaged newest checkpoint falls back to the previous one, none intact is exit 2",
          "[cli][resume][checkpoint]") {
  Runs runs;
  // An intact checkpoint resumes from frame 3 itself.
  {
    const std::string out = copy_of(runs.d, runs.part, "intact");
    const CmdResult r = run_shellmpm("run " + runs.scene + " --resume -o " + out);
    INFO(r.output);
    REQUIRE(r.code == 0);
    CHECK(r.output.find("resuming after frame 3") != std::string::npos);
    CHECK(r.output.find("older checkpoint") == std::string::npos);
    expect_same_results(runs.full, out);
  }
  // One byte in each kind of section (every section: the [slow] case below; every byte
  // of a small checkpoint: tests/io/test_checkpoint.cpp). No Catch sections: each would
  // rerun the two runs.
  const std::vector<Section> secs = sections(read_text(runs.part + "/checkpoint.0003.bin"));
  for (const Section& sec : secs)
    for (const char* pick : {"magic", "payload size", "frame", "particle positions",
                             "particle kinds", "statistics", "shell contact normals", "checksum"})
      if (sec.name == pick) runs.expect_fallback(sec.name, sec.offset);
  runs.expect_fallback("cut in half", std::string::npos);
  {
    INFO("all damaged: exit 2 naming every file, nothing written");
    const std::string out = copy_of(runs.d, runs.part, "case");
    for (int f = 1; f <= 3; ++f) damage(out + "/checkpoint.000" + std::to_string(f) + ".bin", 100);
    const std::string stats = read_text(out + "/stats.json");
    const CmdResult r = run_shellmpm("run " + runs.scene + " --resume -o " + out);
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find("no intact checkpoint to resume from (3 damaged)") != std::string::npos);
    for (int f = 1; f <= 3; ++f)
      CHECK(r.output.find(out + "/checkpoint.000" + std::to_string(f) + ".bin") !=
            std::string::npos);
    CHECK_FALSE(fs::exists(out + "/cloth.0004.ply"));
    CHECK(read_text(out + "/stats.json") == stats);
  }
}

TEST_CASE(
    "CLI: a byte damaged in every section of a real checkpoint falls back to the previous one",
    "[cli][resume][checkpoint][slow]") {
  Runs runs;
  for (const Section& sec : sections(read_text(runs.part + "/checkpoint.0003.bin")))
    runs.expect_fallback(sec.name, sec.offset);
}

TEST_CASE("CLI: --resume skips a stray checkpoint name and removes a killed run's temporaries",
          "[cli][resume][checkpoint]") {
  TempDir d("ck_stray");
  const std::string s = make_scene(d);
  REQUIRE(run_shellmpm("run " + s + " -q --frames 1-3 -o " + d.file("o")).code == 0);
  d.write("o/checkpoint.99999999999.bin", "stray");
  d.write("o/cloth.0004.ply.tmp.4242", "half a frame");
  d.write("o/density.0004.vdb.tmp.4242", "half a frame");
  d.write("o/notes.tmp.txt", "not ours");
  const CmdResult r = run_shellmpm("run " + s + " --resume -o " + d.file("o"));
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("warning: ignoring '" + d.file("o/checkpoint.99999999999.bin") + "'") !=
        std::string::npos);
  CHECK(r.output.find("resuming after frame 3") != std::string::npos);
  CHECK(r.output.find("removed 2 temporary file(s) left by a killed run") != std::string::npos);
  CHECK_FALSE(fs::exists(d.file("o/cloth.0004.ply.tmp.4242")));
  CHECK_FALSE(fs::exists(d.file("o/density.0004.vdb.tmp.4242")));
  CHECK(fs::exists(d.file("o/notes.tmp.txt")));
  CHECK(fs::exists(d.file("o/cloth.0004.ply")));
}

TEST_CASE("CLI: --frames numbers out of range are refused naming the flag", "[cli]") {
  TempDir d("frames_range");
  const std::string s = make_scene(d);
  for (const char* bad : {"1-99999999999", "99999999999", "0-3", "4-2", "1-2-3", "x"}) {
    const CmdResult r = run_shellmpm("run " + s + " -q --frames " + bad + " -o " + d.file("o"));
    INFO(bad << ": " << r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find("--frames") != std::string::npos);
    CHECK(r.output.find(bad) != std::string::npos);
    CHECK(r.output.find("stoi") == std::string::npos);
  }
  CHECK_FALSE(fs::exists(d.file("o")));  // refused before anything was written
  REQUIRE(run_shellmpm("run " + s + " -q --frames 1 -o " + d.file("o")).code == 0);
  const CmdResult r = run_shellmpm("render " + d.file("o") + " --frames 1-99999999999");
  INFO(r.output);
  CHECK(r.code == 2);
  CHECK(
      r.output.find("--frames 1-99999999999: frame 99999999999 is past the largest frame number") !=
      std::string::npos);
}
