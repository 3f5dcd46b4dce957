// The README's commands stay true, and every example scene is valid and runs.
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <regex>

#include "io/scene_reader.h"
#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {
const std::string kRoot = SHELLMPM_SOURCE_DIR;

std::vector<std::string> fenced_sh_lines(const std::string& md) {
  std::vector<std::string> out;
  const std::regex block("```sh\\n([^`]*)```");
  for (std::sregex_iterator it(md.begin(), md.end(), block), end; it != end; ++it)
    out.push_back((*it)[1].str());
  return out;
}

std::vector<std::string> example_scenes() {
  std::vector<std::string> s;
  for (const auto& e : std::filesystem::directory_iterator(kRoot + "/scenes"))
    if (e.path().extension() == ".yaml") s.push_back(e.path().string());
  std::sort(s.begin(), s.end());
  return s;
}

/// The fastest keyframed motion of a scene (colliders and pins): translation speed plus
/// rotation rate times the farthest domain corner from the origin, between any two keys.
double fastest_keyframe_speed(const shellmpm::Scene& scene) {
  const double reach = std::max(scene.shot.domain_min.norm(), scene.shot.domain_max.norm());
  double fastest = 0;
  auto motion = [&](const std::vector<shellmpm::Keyframe>& keys) {
    for (std::size_t k = 1; k < keys.size(); ++k) {
      const double dt = keys[k].time - keys[k - 1].time;
      const double move = (keys[k].translate - keys[k - 1].translate).norm();
      const double turn = (keys[k].rotate_deg - keys[k - 1].rotate_deg).norm() * M_PI / 180;
      fastest = std::max(fastest, (move + turn * reach) / dt);
    }
  };
  for (const auto& c : scene.colliders) motion(c.keyframes);
  for (const auto& sh : scene.shells)
    for (const auto& pin : sh.pins) motion(pin.keyframes);
  return fastest;
}

/// No bulk particle of the scene can move faster than this: its fastest initial velocity,
/// plus free fall across the whole domain, plus twice the fastest keyframed motion (a
/// particle bouncing off a moving wall leaves at up to twice the wall's speed).
double speed_bound(const shellmpm::Scene& scene) {
  double v0 = 0;
  for (const auto& src : scene.sources) v0 = std::max(v0, src.velocity.norm());
  for (const auto& sh : scene.shells) v0 = std::max(v0, sh.velocity.norm());
  const double fall = (scene.shot.domain_max - scene.shot.domain_min).norm();
  return v0 + std::sqrt(2 * scene.shot.gravity.norm() * fall) + 2 * fastest_keyframe_speed(scene);
}

// frames: "A-B", or empty for the scene's own range; extra: more flags for run.
void run_scene_frames(const std::string& scene, const std::string& frames,
                      const std::string& extra = "") {
  TempDir d("scene_" + std::filesystem::path(scene).stem().string());
  const std::string range = frames.empty() ? "" : " --frames " + frames;
  const CmdResult r = run_shellmpm("run " + scene + " -q" + range + extra + " -o " + d.file("o"));
  INFO(scene << "\n" << r.output);
  REQUIRE(r.code == 0);
  const auto stats = nlohmann::json::parse(read_text(d.file("o/stats.json")));
  const auto& last = stats["frames"].back();
  REQUIRE(std::isfinite(last["kinetic_energy"].get<double>()));
  REQUIRE(std::isfinite(last["elastic_energy"].get<double>()));
  REQUIRE(last["particles"].get<double>() + last.value("shell_points", 0.0) > 0);
  // Energy bound: no particle faster than the scene's motions and gravity allow.
  const double bound = speed_bound(shellmpm::read_scene(scene));
  INFO("speed bound " << bound << " m/s");
  for (const auto& f : stats["frames"]) {
    REQUIRE(f["max_speed"].get<double>() <= bound);
    // Integrity (where checked): nothing through a shell, into a collider, or non-finite.
    if (f.contains("integrity")) REQUIRE(f["integrity"]["ok"].get<bool>());
  }
  // Mass is conserved (fill sources) or only grows (emitters).
  double prev = 0;
  for (const auto& f : stats["frames"]) {
    REQUIRE(f["mass"].get<double>() >= prev * (1 - 1e-6));
    prev = f["mass"].get<double>();
  }
}
}  // namespace

TEST_CASE("README: the test command is the one .ci/run runs, the run command names a scene",
          "[readme]") {
  const std::string readme = read_text(kRoot + "/README.md");
  const auto blocks = fenced_sh_lines(readme);
  REQUIRE(blocks.size() >= 2);
  // The first two code blocks are the two commands, one line each.
  REQUIRE(std::count(blocks[0].begin(), blocks[0].end(), '\n') == 1);
  REQUIRE(std::count(blocks[1].begin(), blocks[1].end(), '\n') == 1);
  const std::string ci = read_text(kRoot + "/.ci/run");
  REQUIRE(ci.find(blocks[1]) != std::string::npos);
  std::smatch m;
  REQUIRE(std::regex_search(blocks[0], m, std::regex("shellmpm run (scenes/[a-z_]+\\.yaml)")));
  REQUIRE(std::filesystem::exists(kRoot + "/" + m[1].str()));
  // No placeholders left behind.
  REQUIRE(readme.find("PLACEHOLDER") == std::string::npos);
}

TEST_CASE("every example scene passes check and runs its first frames", "[scenes]") {
  const auto scenes = example_scenes();
  REQUIRE(scenes.size() >= 5);
  for (const std::string& s : scenes) {
    const CmdResult c = run_shellmpm("check " + s);
    INFO(s << "\n" << c.output);
    REQUIRE(c.code == 0);
    REQUIRE(c.output.find("stages: ") != std::string::npos);
    REQUIRE(c.output.find("(none") == std::string::npos);
    // A scene that check estimates above 5 s a frame (can_on_sand: a steel can's
    // half-microsecond steps, 100 s a frame here) runs its first frame at the draft preset;
    // the [slow] test below runs it as written.
    const std::string key = "estimated time per frame at the peak: ";
    const std::size_t at = c.output.find(key);
    const bool heavy = at != std::string::npos && std::stod(c.output.substr(at + key.size())) > 5;
    if (heavy)
      run_scene_frames(s, "1-2", " --quality draft");
    else
      run_scene_frames(s, "1-3");
  }
}

TEST_CASE("every example scene runs to its last frame", "[scenes][slow]") {
  for (const std::string& s : example_scenes()) run_scene_frames(s, "");
}
