// A step below shot.dt_min: `check` warns before anything runs and names the cause (the
// short mesh edge, the stiff material) with a fix; `run` stops with exit 1 and the same.
#include <catch2/catch.hpp>
#include <sstream>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

/// A flat 0.3 m square of 3 x 3 quads (0.1 m edges) in the XZ plane, split along the
/// same diagonal, whose vertex at (0.1, 0, 0.1) is moved to 0.17 mm from (0.2, 0, 0.1).
std::string film_obj() {
  std::ostringstream os;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      double x = 0.1 * i;
      if (i == 1 && j == 1) x = 0.2 - 0.17e-3;
      os << "v " << x << " 0 " << 0.1 * j << "\n";
    }
  auto id = [](int i, int j) { return j * 4 + i + 1; };
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      // Counter-clockwise seen from +Y.
      os << "f " << id(i, j) << " " << id(i + 1, j + 1) << " " << id(i + 1, j) << "\n";
      os << "f " << id(i, j) << " " << id(i, j + 1) << " " << id(i + 1, j + 1) << "\n";
    }
  return os.str();
}

std::string scene(const TempDir& d, const std::string& body) {
  return d.write("scene.yaml",
                 "version: 1\n"
                 "shot:\n"
                 "  frames: [1, 2]\n"
                 "  dx: 0.05\n"
                 "  domain: {min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5]}\n" +
                     body + "output:\n  directory: " + d.file("out") + "\n");
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("CLI: check warns when one short mesh edge sets the step, and run names it",
          "[cli][step_limits]") {
  TempDir d("cli_short_edge");
  d.write("film.obj", film_obj());
  const std::string s =
      scene(d,
            "shell_materials:\n"
            "  - {name: paper, youngs_modulus: 3.0e9, density: 800, thickness: 1.0e-4}\n"
            "shells:\n"
            "  - name: film\n"
            "    material: paper\n"
            "    geometry: {type: mesh, path: film.obj}\n");
  const CmdResult c = run_shellmpm("check " + s);
  INFO(c.output);
  REQUIRE(c.code == 0);
  REQUIRE(has(c.output, "time step limited by: shell 'film': membrane/bending stiffness"));
  REQUIRE(has(c.output, "shortest control-mesh edge, 0.17 mm between vertices "));
  REQUIRE(has(c.output, " at (0.2, 0, 0.1)"));
  REQUIRE(has(c.output, "warning: the stable step "));
  REQUIRE(has(c.output, "is below shot.dt_min = 1e-06 s, so `shellmpm run` will stop at t = 0"));
  REQUIRE(has(c.output, "merge the vertices of that edge"));

  const CmdResult r = run_shellmpm("run " + s + " --quiet");
  INFO(r.output);
  REQUIRE(r.code == 1);
  REQUIRE(has(r.output, "at t = 0 s the stable step "));
  REQUIRE(has(r.output, "is below shot.dt_min = 1e-06 s"));
  REQUIRE(has(r.output, "shell 'film'"));
  REQUIRE(has(r.output, "0.17 mm between vertices "));
  REQUIRE(has(r.output, "merge the vertices of that edge"));
}

TEST_CASE("CLI: check warns when a steel material sets the step, and run names it",
          "[cli][step_limits]") {
  TempDir d("cli_steel");
  const std::string s = scene(d,
                              "materials:\n"
                              "  - {name: steel, type: elastic, youngs_modulus: 2.0e11, "
                              "poisson_ratio: 0.3, density: 7850}\n"
                              "sources:\n"
                              "  - {material: steel, shape: {type: box, min: [-0.1, 0, -0.1], "
                              "max: [0.1, 0.2, 0.1]}}\n");
  // At dx = 0.05 the wave speed (5856 m/s) allows 2.6e-6 s: fine for the default dt_min.
  const CmdResult ok = run_shellmpm("check " + s);
  INFO(ok.output);
  REQUIRE(ok.code == 0);
  REQUIRE(has(ok.output, "time step limited by: material 'steel': elastic wave speed 5856 m/s"));
  REQUIRE(!has(ok.output, "warning: the stable step"));

  const std::string finer = " --set shot.dx=0.02";  // 1.0e-6 s
  const CmdResult c = run_shellmpm("check " + s + finer + " --set shot.dt_min=2e-6");
  INFO(c.output);
  REQUIRE(c.code == 0);
  REQUIRE(has(c.output, "warning: the stable step 1e-06 s is below shot.dt_min = 2e-06 s"));
  REQUIRE(has(c.output, "limited by material 'steel': elastic wave speed 5856 m/s"));
  REQUIRE(has(c.output, "a softer material (smaller materials[].youngs_modulus"));
  REQUIRE(!has(c.output, "raise shot.dt_min"));

  const CmdResult r = run_shellmpm("run " + s + finer + " --set shot.dt_min=2e-6 --quiet");
  INFO(r.output);
  REQUIRE(r.code == 1);
  REQUIRE(has(r.output, "simulation stopped: at t = 0 s the stable step "));
  REQUIRE(has(r.output, "limited by material 'steel': elastic wave speed 5856 m/s"));
}
