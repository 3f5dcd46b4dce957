// The pre-roll method key: default, values, and the error for an unknown method.
#include <catch2/catch.hpp>

#include <string>

#include "io/scene_reader.h"

using namespace shellmpm;

TEST_CASE("scene preroll.method: static by default, dynamic on request", "[scene]") {
  const std::string head =
      "version: 1\n"
      "shot:\n"
      "  domain: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
      "  dx: 0.1\n";
  CHECK(parse_scene(head, "s.yaml").preroll.method == PrerollSettings::Method::Static);
  CHECK(
      parse_scene(head + "preroll: {enabled: true, method: dynamic}\n", "s.yaml").preroll.method ==
      PrerollSettings::Method::Dynamic);
  CHECK(parse_scene(head + "preroll: {method: static}\n", "s.yaml").preroll.method ==
        PrerollSettings::Method::Static);
  try {
    parse_scene(head + "preroll: {method: implicit}\n", "s.yaml");
    FAIL("expected a UserError");
  } catch (const UserError& e) {
    const std::string what = e.what();
    CAPTURE(what);
    CHECK(e.line == 5);
    CHECK(e.key == "preroll.method");
    CHECK(what.find("expected one of static, dynamic") != std::string::npos);
  }
}
