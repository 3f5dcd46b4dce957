// shot.quality: the presets scale dx and sheet resolutions and fill the knobs the scene
// leaves out; what the scene sets itself wins.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/scene_quality.h"
#include "io/scene_reader.h"
#include "io/user_error.h"
#include "sim/scene/scene_words.h"

using namespace shellmpm;

namespace {

std::string scene_text(const std::string& shot_extra, const std::string& material_extra) {
  return R"(version: 1
shot: {dx: 0.02, domain: {min: [-1, -1, -1], max: [1, 1, 1]})" +
         shot_extra + R"(}
materials: [{name: sand, type: sand}]
sources: [{material: sand, shape: {type: box, min: [-0.2, 0, -0.2], max: [0.2, 0.2, 0.2]}}]
shell_materials: [{name: cotton)" +
         material_extra + R"(}]
shells:
  - {name: cloth, material: cotton, geometry: {type: sheet, size: [1, 0.5], resolution: [20, 10]}}
  - {name: tube, material: cotton, geometry: {type: cylinder, radius: 0.2, height: 0.4, resolution: [6, 4]}}
)";
}

}  // namespace

TEST_CASE("no quality: the scene as written", "[scene][quality]") {
  const Scene s = parse_scene(scene_text("", ""), "q.yaml");
  CHECK_FALSE(s.shot.quality);
  CHECK(s.shot.dx == 0.02);
  CHECK(s.shells[0].resolution == std::array<int, 2>{20, 10});
  CHECK(s.shot.cfl == 0.3);
}

TEST_CASE("quality presets scale dx and sheet resolution and fill unset knobs",
          "[scene][quality]") {
  for (Quality q : {Quality::Draft, Quality::Preview, Quality::Production, Quality::Final}) {
    const QualityPreset p = quality_preset(q);
    const Scene s =
        parse_scene(scene_text("", ""), "q.yaml", {"shot.quality=" + std::string(word_of(q))});
    CAPTURE(word_of(q));
    REQUIRE(s.shot.quality == q);
    CHECK(s.shot.dx == Approx(0.02 * p.dx_factor));
    CHECK(s.shells[0].resolution[0] == std::lround(20 / p.dx_factor));
    CHECK(s.shells[0].resolution[1] == std::lround(10 / p.dx_factor));
    CHECK(s.shells[1].resolution[0] == std::max(3L, std::lround(6 / p.dx_factor)));
    CHECK(s.shot.cfl == Approx(p.cfl));
    CHECK(s.shell_materials[0].quadrature_inplane == p.quadrature_inplane);
    CHECK(s.shell_materials[0].quadrature_thickness == p.quadrature_thickness);
    CHECK(s.shell_materials[0].contact_samples == p.contact_samples);
    CHECK(s.sources[0].particles_per_cell == p.particles_per_cell);
  }
  // The presets are ordered: each is finer than the one before.
  CHECK(quality_preset(Quality::Draft).dx_factor > quality_preset(Quality::Preview).dx_factor);
  CHECK(quality_preset(Quality::Preview).dx_factor > quality_preset(Quality::Production).dx_factor);
  CHECK(quality_preset(Quality::Production).dx_factor > quality_preset(Quality::Final).dx_factor);
}

TEST_CASE("keys the scene or --set gives win over the preset", "[scene][quality]") {
  const Scene s =
      parse_scene(scene_text(", cfl: 0.25, quality: draft", ", quadrature_thickness: 4"), "q.yaml",
                  {"sources[0].particles_per_cell=27"});
  CHECK(s.shot.cfl == 0.25);
  CHECK(s.shell_materials[0].quadrature_thickness == 4);
  CHECK(s.sources[0].particles_per_cell == 27);
  CHECK(s.shot.dx == Approx(0.04));  // relative knobs always follow the preset
  CHECK(s.shell_materials[0].contact_samples == 1);
}

TEST_CASE("a bad quality word is refused at its key", "[scene][quality]") {
  CHECK_THROWS_WITH(parse_scene(scene_text(", quality: ultra", ""), "q.yaml"),
                    Catch::Contains("q.yaml:2: shot.quality") && Catch::Contains("draft"));
}
