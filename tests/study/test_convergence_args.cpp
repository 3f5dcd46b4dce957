// `converge` argument parsing: --vary lists, spacings inferred from values, quantities
// checked against the scene.
#include <catch2/catch.hpp>

#include "io/scene_reader.h"
#include "io/user_error.h"
#include "study/convergence.h"
#include "study/quantity.h"

using namespace shellmpm;

TEST_CASE("parse_vary splits values at top-level commas only", "[study]") {
  const VarySpec a = parse_vary("shot.dx=0.04,0.02,0.01");
  CHECK(a.key == "shot.dx");
  CHECK(a.values == std::vector<std::string>{"0.04", "0.02", "0.01"});
  const VarySpec b = parse_vary("shells[0].geometry.resolution=[10,10],[20, 20]");
  CHECK(b.key == "shells[0].geometry.resolution");
  CHECK(b.values == std::vector<std::string>{"[10,10]", "[20, 20]"});
  CHECK_THROWS_AS(parse_vary("shot.dx"), UserError);
  CHECK_THROWS_AS(parse_vary("shot.dx=0.1"), UserError);
  CHECK_THROWS_AS(parse_vary("shot.dx=0.1,,0.2"), UserError);
  CHECK_THROWS_WITH(parse_vary("=1,2"), Catch::Contains("--vary =1,2"));
}

TEST_CASE("spacing_of_value: reals are spacings, integers are counts", "[study]") {
  CHECK(*spacing_of_value("0.02") == Approx(0.02));
  CHECK(*spacing_of_value("1e-2") == Approx(0.01));
  CHECK(*spacing_of_value("40") == Approx(1.0 / 40));
  CHECK(*spacing_of_value("[20, 10]") == Approx(1.0 / 20));
  CHECK_FALSE(spacing_of_value("apic"));
  CHECK_FALSE(spacing_of_value("-1"));
}

namespace {

Scene drape_scene() {
  return parse_scene(R"(version: 1
shot: {dx: 0.05, domain: {min: [-1, -1, -1], max: [1, 1, 1]}}
shell_materials: [{name: cotton}]
shells: [{name: cloth, material: cotton, geometry: {type: sheet, size: [1, 1], resolution: [4, 4]}}]
)",
                     "drape.yaml");
}

}  // namespace

TEST_CASE("quantities are checked against the scene", "[study]") {
  const Scene s = drape_scene();
  const Quantity a = parse_quantity("shell.cloth.lowest", s, "--measure");
  CHECK(a.source == Quantity::Source::Shell);
  CHECK(a.what == Quantity::What::Lowest);
  const Quantity b = parse_quantity("shell.cloth.vertex.12.z", s, "--measure");
  CHECK(b.vertex == 12);
  CHECK(b.axis == 2);
  const Quantity c = parse_quantity("max:stats.integrity.max_collider_depth", s, "--measure");
  CHECK(c.over == Quantity::Over::MaxOverFrames);
  CHECK(c.stats_path == std::vector<std::string>{"integrity", "max_collider_depth"});
  CHECK_THROWS_WITH(parse_quantity("shell.flag.lowest", s, "--measure"),
                    Catch::Contains("no shell 'flag'") && Catch::Contains("cloth"));
  CHECK_THROWS_WITH(parse_quantity("bulk.max.x", s, "--measure"),
                    Catch::Contains("no bulk sources"));
  CHECK_THROWS_AS(parse_quantity("shell.cloth.centroid.w", s, "--measure"), UserError);
  CHECK_THROWS_AS(parse_quantity("shell.cloth.vertex.-1.x", s, "--measure"), UserError);
  CHECK_THROWS_AS(parse_quantity("volume", s, "--measure"), UserError);
}
