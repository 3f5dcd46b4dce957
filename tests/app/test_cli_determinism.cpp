// Whole runs through the binary: thread-count independence, kill and resume, and the
// density cache integral.
#include <signal.h>
#include <unistd.h>

#include <openvdb/openvdb.h>
#include <catch2/catch.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

const char* kSnow = R"(version: 1
shot:
  frames: [1, FRAMES]
  fps: 24
  dx: 0.025
  domain: {min: [-0.6, 0, -0.6], max: [0.6, 1, 0.6]}
materials:
  - {name: snow, type: snow, youngs_modulus: 5.0e4, poisson_ratio: 0.2, density: 400}
sources:
  - {material: snow, shape: {type: sphere, center: [-0.1, 0.35, 0], radius: 0.12}, velocity: [1.5, -2.5, 0]}
colliders:
  - {name: ground, shape: {type: plane, point: [0, 0.1, 0], normal: [0, 1, 0]}, boundary: separate, friction: 0.5}
  - {name: post, shape: {type: cylinder, center: [0.2, 0.2, 0], axis: [0, 1, 0], radius: 0.05, height: 0.3}, boundary: sticky}
output:
  directory: OUT
  checkpoint_every: 2
  velocity: true
)";

std::string make_scene(const TempDir& d, int frames) {
  std::string t = kSnow;
  t.replace(t.find("FRAMES"), 6, std::to_string(frames));
  t.replace(t.find("OUT"), 3, d.file("default_out"));
  return d.write("snow.yaml", t);
}

openvdb::FloatGrid::Ptr read_density(const std::string& path) {
  openvdb::initialize();
  openvdb::io::File f(path);
  f.open();
  auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("density"));
  f.close();
  return g;
}

/// Voxel-by-voxel bitwise comparison (files differ in their random UUID only).
bool same_density(const std::string& a, const std::string& b) {
  auto ga = read_density(a), gb = read_density(b);
  if (ga->activeVoxelCount() != gb->activeVoxelCount()) return false;
  auto acc = gb->getConstAccessor();
  for (auto it = ga->cbeginValueOn(); it; ++it) {
    const float vb = acc.getValue(it.getCoord());
    if (std::memcmp(&vb, &*it, sizeof(float)) != 0) return false;
  }
  return true;
}

/// The statistics without the wall-clock timings.
nlohmann::json physics_stats(const std::string& path) {
  auto j = nlohmann::json::parse(read_text(path));
  for (auto& f : j["frames"]) f.erase("wall");
  return j["frames"];
}

}  // namespace

TEST_CASE("runs with 1 and 2 threads give bit-identical caches and statistics",
          "[cli][determinism]") {
  TempDir d("det");
  const std::string s = make_scene(d, 8);
  REQUIRE(run_shellmpm("run " + s + " -q --threads 1 -o " + d.file("t1")).code == 0);
  REQUIRE(run_shellmpm("run " + s + " -q --threads 2 -o " + d.file("t2")).code == 0);
  for (int f = 1; f <= 8; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "/density.%04d.vdb", f);
    REQUIRE(same_density(d.file("t1") + name, d.file("t2") + name));
  }
  const auto a = physics_stats(d.file("t1/stats.json")), b = physics_stats(d.file("t2/stats.json"));
  REQUIRE(a.size() == 8);
  REQUIRE(a.dump() == b.dump());
  // The comparison can fail: a different seed changes the result.
  REQUIRE(run_shellmpm("run " + s + " -q --threads 2 --frames 1-8 --set sources[0].seed=5 -o " +
                       d.file("t3"))
              .code == 0);
  REQUIRE_FALSE(same_density(d.file("t1/density.0008.vdb"), d.file("t3/density.0008.vdb")));
}

TEST_CASE("a killed run resumed from its checkpoint equals an uninterrupted run", "[cli][resume]") {
  TempDir d("resume");
  const std::string s = make_scene(d, 10);
  REQUIRE(run_shellmpm("run " + s + " -q -o " + d.file("full")).code == 0);
  // Stop after frame 4 (as if killed), then resume to the end.
  REQUIRE(run_shellmpm("run " + s + " -q --frames 1-5 -o " + d.file("part")).code == 0);
  std::filesystem::remove(d.file("part/checkpoint.0004.bin"));  // newest left: frame 2
  const CmdResult r = run_shellmpm("run " + s + " --resume -o " + d.file("part"));
  INFO(r.output);
  REQUIRE(r.code == 0);
  REQUIRE(r.output.find("resuming after frame 2") != std::string::npos);
  for (int f = 3; f <= 10; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "/density.%04d.vdb", f);
    REQUIRE(same_density(d.file("full") + name, d.file("part") + name));
  }
  REQUIRE(physics_stats(d.file("full/stats.json")).dump() ==
          physics_stats(d.file("part/stats.json")).dump());
}

TEST_CASE("SIGKILL during a run, then --resume, matches the uninterrupted run", "[cli][resume]") {
  TempDir d("kill");
  const std::string s = make_scene(d, 12);
  REQUIRE(run_shellmpm("run " + s + " -q -o " + d.file("full")).code == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    const std::string out = d.file("killed");
    execl(SHELLMPM_BINARY, SHELLMPM_BINARY, "run", s.c_str(), "-q", "--threads", "1", "-o",
          out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!std::filesystem::exists(d.file("killed/checkpoint.0004.bin")) &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(std::filesystem::exists(d.file("killed/checkpoint.0004.bin")));
  REQUIRE(run_shellmpm("run " + s + " -q --resume -o " + d.file("killed")).code == 0);
  REQUIRE(same_density(d.file("full/density.0012.vdb"), d.file("killed/density.0012.vdb")));
  REQUIRE(physics_stats(d.file("full/stats.json")).dump() ==
          physics_stats(d.file("killed/stats.json")).dump());
  for (const auto& e : std::filesystem::directory_iterator(d.file("killed")))
    REQUIRE(e.path().string().find(".tmp.") == std::string::npos);
}

TEST_CASE("density cache integral equals particle mass over rest density", "[cli][vdb]") {
  TempDir d("integral");
  const std::string s = make_scene(d, 3);
  REQUIRE(run_shellmpm("run " + s + " -q --set output.particles=true -o " + d.file("o")).code == 0);
  auto g = read_density(d.file("o/density.0003.vdb"));
  REQUIRE(g->getGridClass() == openvdb::GRID_FOG_VOLUME);
  double sum = 0;
  for (auto it = g->cbeginValueOn(); it; ++it) sum += *it;
  const double voxel = std::pow(g->voxelSize()[0], 3);
  // Sphere of radius 0.12 sampled at 8 per cell of 0.025: volume = count * (0.025^3 / 8).
  const std::string ply = read_text(d.file("o/particles.0003.ply"));
  const auto p = ply.find("element vertex ");
  REQUIRE(p != std::string::npos);
  const double n = std::stod(ply.substr(p + 15));
  const double volume = n * std::pow(0.025, 3) / 8;
  REQUIRE(sum * voxel == Approx(volume).epsilon(0.01));
  REQUIRE(volume == Approx(4.0 / 3.0 * M_PI * std::pow(0.12, 3)).epsilon(0.03));
}
