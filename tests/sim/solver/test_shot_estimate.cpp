// The shot estimate (sim/solver/shot_estimate.h): the step and substeps agree with the
// step limits, and each stage's seconds scale with what it works on (particles, layers,
// contact points) and inversely with the threads.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/solver/shot_estimate.h"
#include "sim/solver/solver.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

Scene jelly_and_cloth(int quadrature_inplane, ShellDesc::Contact contact) {
  Scene s = test::contact_test_scene(0.05);
  MaterialDesc jelly;
  jelly.name = "jelly";
  jelly.youngs_modulus = 2e4;
  s.materials.push_back(jelly);
  SourceDesc src;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d(-0.2, 0.3, -0.2);
  src.shape.max = Vec3d(0.2, 0.5, 0.2);
  s.sources.push_back(src);
  ShellMaterialDesc cloth = test::cloth_material();
  cloth.quadrature_inplane = quadrature_inplane;
  s.shell_materials.push_back(cloth);
  ShellDesc sheet;
  sheet.name = "sheet";
  sheet.size = {0.8, 0.8};
  sheet.resolution = {16, 16};
  sheet.contact = contact;
  s.shells.push_back(sheet);
  return s;
}

}  // namespace

TEST_CASE("shot estimate: step, substeps and the cost of each stage", "[estimate]") {
  const Scene s = jelly_and_cloth(3, ShellDesc::Contact::Auto);
  const Solver solver(s);
  const ShotEstimate one = estimate_shot(solver, 1e5, 1);
  CHECK(one.dt == Approx(step_limits(solver, true).front().dt));
  CHECK(one.substeps_per_frame == std::ceil(1.0 / (s.shot.fps * one.dt)));
  CHECK(one.snow_step_shrink == 1.0);  // no snow
  // Bulk: particles x substeps at the per-thread rate.
  CHECK(one.bulk_seconds == Approx(one.substeps_per_frame * 1e5 * kBulkParticleStepSeconds));
  // Shells: 512 triangles x 3 x 3 layers a step.
  CHECK(one.shell_seconds == Approx(one.substeps_per_frame * 512 * 9 * kShellLayerSeconds));
  CHECK(one.contact_seconds > 0);  // bulk material switches contact on
  CHECK(one.seconds_per_frame() ==
        Approx(one.bulk_seconds + one.shell_seconds + one.contact_seconds));

  SECTION("twice the particles cost twice the bulk time; two threads half of everything") {
    const ShotEstimate twice = estimate_shot(solver, 2e5, 1);
    CHECK(twice.bulk_seconds == Approx(2 * one.bulk_seconds));
    CHECK(twice.shell_seconds == Approx(one.shell_seconds));
    const ShotEstimate two = estimate_shot(solver, 1e5, 2);
    CHECK(two.seconds_per_frame() == Approx(one.seconds_per_frame() / 2));
  }
  SECTION("seven in-plane points cost 7/3 the shell forces") {
    const Solver seven(jelly_and_cloth(7, ShellDesc::Contact::Auto));
    CHECK(estimate_shot(seven, 1e5, 1).shell_seconds / one.substeps_per_frame ==
          Approx(7.0 / 3.0 * one.shell_seconds / one.substeps_per_frame));
  }
  SECTION("a shell without contact costs no contact time") {
    const Solver off(jelly_and_cloth(3, ShellDesc::Contact::Off));
    CHECK(estimate_shot(off, 1e5, 1).contact_seconds == 0.0);
  }
}
