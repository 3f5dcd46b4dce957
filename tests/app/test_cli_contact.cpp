// The command line on contact scenes: `check` reports contact parameters and warns when
// the control mesh spacing is far from dx; runs are thread-count independent and resumable.
#include <catch2/catch.hpp>

#include "tests/app/cli_harness.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm_test;

TEST_CASE("CLI: check reports contact and warns when the mesh spacing is far from dx", "[cli]") {
  const std::string scene = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/cloth_drape.yaml";
  const CmdResult ok = run_shellmpm("check " + scene);
  INFO(ok.output);
  CHECK(ok.code == 0);
  CHECK(ok.output.find("contact: 3200 contact particles") != std::string::npos);
  // Cloth 1 mm, contact at the surfaces: the guard's gap is the contact layer less a fifth of it.
  CHECK(ok.output.find("shell guard: gap 0.0008 m (the thinnest contact layer less a fifth") !=
        std::string::npos);
  CHECK(ok.output.find("warning") == std::string::npos);
  // At the stencils, dx 0.025: 0.05 dx.
  const CmdResult stencil = run_shellmpm("check " + scene + " --set shot.contact_at=stencil");
  INFO(stencil.output);
  CHECK(stencil.output.find("shell guard: gap 0.00125 m (0.05 dx") != std::string::npos);
  const CmdResult fine = run_shellmpm("check " + scene + " --set shot.dx=0.01");
  INFO(fine.output);
  CHECK(fine.code == 0);
  CHECK(fine.output.find("warning: shell cloth: its mesh spacing") != std::string::npos);
  CHECK(fine.output.find("much coarser") != std::string::npos);
}

namespace {

/// Runs `scene` (a path plus any --set options) over frames 1-6 on 1 and 2 threads and as
/// 1-3 then --resume to 6 in directories a, b and c of d; returns frame 6's cloth mesh of
/// each run and frame 5's of the first (the comparison must be able to fail).
struct ThreeRuns {
  std::string a, b, c, a5, stats;
};
ThreeRuns three_runs(const TempDir& d, const std::string& scene) {
  const std::string common = " --frames 1-6 --set output.checkpoint_every=3 -q -o ";
  REQUIRE(run_shellmpm("run " + scene + common + d.file("a") + " --threads 1").code == 0);
  REQUIRE(run_shellmpm("run " + scene + common + d.file("b") + " --threads 2").code == 0);
  REQUIRE(run_shellmpm("run " + scene + " --frames 1-3 --set output.checkpoint_every=3 -q -o " +
                       d.file("c"))
              .code == 0);
  REQUIRE(run_shellmpm("run " + scene + common + d.file("c") + " --resume").code == 0);
  return {read_text(d.file("a/cloth.0006.ply")), read_text(d.file("b/cloth.0006.ply")),
          read_text(d.file("c/cloth.0006.ply")), read_text(d.file("a/cloth.0005.ply")),
          read_text(d.file("a/stats.json"))};
}

}  // namespace

TEST_CASE("CLI: a contact scene gives the same meshes on 1 and 2 threads and after --resume",
          "[cli]") {
  TempDir d("contact");
  // The cloth reaches the ball at about t = 0.17 s (frame 5): frame 6 is in contact.
  const ThreeRuns r = three_runs(d, std::string(SHELLMPM_SOURCE_DIR) + "/scenes/cloth_drape.yaml");
  CHECK(r.a.size() > 1000);
  CHECK(r.a == r.b);
  CHECK(r.a == r.c);
  CHECK(r.a != r.a5);  // the comparison can fail
  CHECK(r.stats.find("\"contact_compressed\"") != std::string::npos);
}

TEST_CASE(
    "CLI: an implicit contact scene gives the same meshes on 1 and 2 threads and after "
    "--resume",
    "[cli][implicit]") {
  TempDir d("contact_implicit");
  // cloth_drape coarsened (16 x 16 elements, dx 0.05), stepped implicitly: the shells'
  // terms are in the grid solve.
  const ThreeRuns r = three_runs(
      d, std::string(SHELLMPM_SOURCE_DIR) +
             "/scenes/cloth_drape.yaml --set shot.integrator=implicit --set shot.dx=0.05 --set "
             "\"shells[0].geometry.resolution=[16, 16]\"");
  CHECK(r.a.size() > 1000);
  CHECK(r.a == r.b);
  CHECK(r.a == r.c);
  CHECK(r.a != r.a5);
  CHECK(r.stats.find("\"newton_iterations\"") != std::string::npos);
}

TEST_CASE("CLI: the shell guard's impulses are the same on 1 and 2 threads and after --resume",
          "[cli][shell_guard]") {
  TempDir d("guard");
  const std::string scene = std::string(SHELLMPM_SOURCE_DIR) + "/tests/data/scenes/guard_pair.yaml";
  const std::string common = " --frames 1-4 --set output.checkpoint_every=2 -q -o ";
  // The guard acts from frame 2 (its gap is the sheets' starting distance).
  REQUIRE(run_shellmpm("run " + scene + common + d.file("a") + " --threads 1").code == 0);
  REQUIRE(run_shellmpm("run " + scene + common + d.file("b") + " --threads 2").code == 0);
  REQUIRE(run_shellmpm("run " + scene + " --frames 1-3 --set output.checkpoint_every=2 -q -o " +
                       d.file("c"))
              .code == 0);
  REQUIRE(run_shellmpm("run " + scene + common + d.file("c") + " --resume").code == 0);
  const std::string stats = read_text(d.file("a/stats.json"));
  CHECK(stats.find("\"guard_impulses\": 0,") != std::string::npos);  // frame 1
  CHECK(stats.find("\"guard_impulses\": 1") != std::string::npos);   // and then some
  for (const char* f : {"upper.0003.ply", "upper.0004.ply", "lower.0004.ply"}) {
    const std::string a = read_text(d.file(std::string("a/") + f));
    CHECK(a.size() > 500);
    CHECK(a == read_text(d.file(std::string("b/") + f)));
    CHECK(a == read_text(d.file(std::string("c/") + f)));
  }
  // The comparison can fail: without the guard the meshes differ.
  REQUIRE(
      run_shellmpm("run " + scene + common + d.file("e") + " --set shot.shell_guard=false").code ==
      0);
  CHECK(read_text(d.file("a/upper.0004.ply")) != read_text(d.file("e/upper.0004.ply")));
}
