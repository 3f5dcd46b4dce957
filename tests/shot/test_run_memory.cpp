// shot/run_memory: the writers' transient against the heap they take (counted through
// operator new), and the peak as the sum of its phases.
#include <catch2/catch.hpp>

#include "io/density_vdb.h"
#include "io/particle_cache.h"
#include "io/scene_reader.h"
#include "shot/run_memory.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"
#include "tests/support/heap_counter.h"
#include "tests/support/temp_dir.h"

using namespace shellmpm;
using shellmpm_test::heap_current;
using shellmpm_test::heap_peak;
using shellmpm_test::reset_heap_peak;

namespace {

Scene bulk_scene(const std::string& output) {
  return parse_scene(
      "version: 1\n"
      "shot:\n"
      "  dx: 0.02\n"
      "  domain: {min: [-1, -0.5, -1], max: [1, 1.5, 1]}\n"
      "materials:\n"
      "  - {name: jelly, type: elastic}\n"
      "sources:\n"
      "  - {material: jelly, shape: {type: box, min: [-0.4, 0, -0.3], max: "
      "[0.4, 0.5, 0.3]}}\n"
      "output:\n" +
          output,
      "scenes/run_memory.yaml");
}

}  // namespace

TEST_CASE("run memory: the density VDB writer's transient", "[memory_estimate]") {
  ThreadLimit one(1);
  shellmpm_test::TempDir d("run_memory");
  for (const bool velocity : {false, true}) {
    CAPTURE(velocity);
    const Scene s = bulk_scene(std::string("  velocity: ") + (velocity ? "true" : "false") + "\n");
    const RunMemory est = estimate_run_memory(s, 0);
    REQUIRE(est.writer == "density VDB");
    SolverOptions so;
    so.serial = true;
    Solver solver(s, so);
    const ParticleSet& p = solver.particles();
    DensityInput in{p.x.data(), p.v.data(), p.kind_volume.data(), p.size(), p.kind.data()};
    VdbOptions vo;
    vo.voxel_size = s.shot.dx;
    vo.velocity = velocity;
    const std::size_t base = heap_current();
    reset_heap_peak();
    write_density_vdb(d.file("density.vdb"), in, vo);
    const double measured = static_cast<double>(heap_peak() - base);
    CHECK(est.writers == Approx(measured).epsilon(0.25));
    // The peak: the process, then the larger of building and holding plus a transient.
    CHECK(est.peak - 8.0 * 1024 * 1024 ==
          Approx(std::max(est.solver.construction_bytes,
                          est.solver.held_bytes + std::max(est.solver.step_scratch, est.writers))));
  }
}

TEST_CASE("run memory: particle cache and checkpoint transients", "[memory_estimate]") {
  ThreadLimit one(1);
  shellmpm_test::TempDir d("run_memory_cache");
  const Scene s = bulk_scene("  density: false\n  particles: true\n");
  const RunMemory est = estimate_run_memory(s, 1e8);
  REQUIRE(est.writer == "particle cache");
  SolverOptions so;
  so.serial = true;
  Solver solver(s, so);
  const std::size_t base = heap_current();
  reset_heap_peak();
  write_particle_ply(d.file("p.ply"), solver.particles());
  CHECK(est.writers == Approx(static_cast<double>(heap_peak() - base)).epsilon(0.25));
  CHECK(est.baseline == 1e8);
  // With checkpoints the copy of the particles is the largest transient.
  const Scene c = bulk_scene("  density: false\n  checkpoint_every: 1\n");
  const RunMemory ck = estimate_run_memory(c, 0);
  CHECK(ck.writer == "checkpoint");
  CHECK(ck.writers == Approx(ck.solver.bytes_per_particle * ck.solver.counts.peak_particles()));
}
