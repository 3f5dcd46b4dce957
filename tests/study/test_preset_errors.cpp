// `shellmpm check --quality` reads the study's results.json for the preset's measured
// errors (study/preset_errors.cpp).
#include <catch2/catch.hpp>
#include <string>

#include "study/preset_errors.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;
using shellmpm_test::TempDir;

namespace {

const char* kResults = R"({"problems": [
  {"name": "plate_simply_supported", "error_kind": "relative", "unit": "m", "runs": [
    {"sweep": "grid spacing", "label": "quality=preview", "status": "ok", "error": 0.5, "cost": 9},
    {"sweep": "quality preset", "label": "quality=draft", "status": "ok", "error": -0.0555, "cost": 0.5},
    {"sweep": "quality preset", "label": "quality=preview", "status": "ok", "error": -0.0429, "cost": 1.5},
    {"sweep": "quality preset", "label": "quality=production", "status": "ok", "error": -0.0316, "cost": 2.0},
    {"sweep": "quality preset", "label": "quality=final", "status": "failed", "cost": 3.0}]},
  {"name": "drape_sphere", "error_kind": "absolute", "unit": "m", "runs": [
    {"sweep": "quality preset", "label": "quality=preview", "status": "ok", "error": 0.00013}]}
]})";

}  // namespace

TEST_CASE("check reads a preset's measured error and relative cost from the study's results",
          "[study]") {
  TempDir dir("preset_errors");
  const std::string path = dir.write("results.json", kResults);
  const std::vector<std::string> problems = {"plate_simply_supported", "drape_sphere",
                                             "bar_impact"};
  const std::vector<PresetMeasurement> m = preset_measurements(path, Quality::Preview, problems);
  REQUIRE(m.size() == 2);
  CHECK(m[0].problem == "plate_simply_supported");
  CHECK(m[0].error == "-4.29%");
  CHECK(m[0].cost_vs_production == Approx(0.75));
  CHECK(m[1].problem == "drape_sphere");
  CHECK(m[1].error == "+0.00013 m");
  CHECK(m[1].cost_vs_production == 0);  // no production run: unknown
  // A failed run has no error; a missing file or a damaged one gives nothing.
  CHECK(preset_measurements(path, Quality::Final, problems).empty());
  CHECK(preset_measurements(dir.file("missing.json"), Quality::Preview, problems).empty());
  CHECK(
      preset_measurements(dir.write("bad.json", "{\"problems\": [1, "), Quality::Preview, problems)
          .empty());
  CHECK(preset_measurements(dir.write("odd.json", "[1, 2]"), Quality::Preview, problems).empty());
  CHECK(preset_measurements(
            dir.write("odd2.json", R"({"problems": [1, {"name": "drape_sphere", "runs": [2]}]})"),
            Quality::Preview, problems)
            .empty());
}
