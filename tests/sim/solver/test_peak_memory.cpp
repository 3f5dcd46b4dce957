// The heap peak of a bulk run, per particle, through operator new
// (tests/support/heap_counter.h): the cube of bench/mpm_throughput (262,144 particles,
// 8 per cell, dx 1/128, float), from the unsorted fill through steps and two reorders.
#include <catch2/catch.hpp>

#include "sim/core/parallel.h"
#include "sim/solver/solver.h"
#include "tests/support/heap_counter.h"

using namespace shellmpm;

namespace {

Scene bench_cube(Transfer transfer) {
  Scene s;
  s.path = "peak_memory";
  s.shot.dx = 1.0 / 128;
  s.shot.domain_min = Vec3d(0, 0, 0);
  s.shot.domain_max = Vec3d(1, 1, 1);
  s.shot.dt_max = 1e-4;
  s.shot.transfer = transfer;
  MaterialDesc jelly;
  jelly.name = "jelly";
  jelly.youngs_modulus = 1e4;
  jelly.poisson_ratio = 0.3;
  jelly.density = 1000;
  s.materials.push_back(jelly);
  SourceDesc src;
  src.material = 0;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d::Constant(0.375);
  src.shape.max = Vec3d::Constant(0.625);  // 32 cells a side
  src.particles_per_cell = 8;
  src.velocity = Vec3d(0.3, -0.5, 0.2);
  s.sources.push_back(src);
  return s;
}

}  // namespace

TEST_CASE("a bulk run peaks at most 110 bytes per particle, reorders included", "[memory]") {
  for (const Transfer transfer : {Transfer::Apic, Transfer::Mls})
    for (const int threads : {1, 2}) {
      ThreadLimit limit(threads);
      const std::size_t base = shellmpm_test::heap_current();
      Solver solver(bench_cube(transfer));
      const double n = static_cast<double>(solver.particles().size());
      REQUIRE(n == 262144);
      auto mean_y = [&] {
        double y = 0;
        for (const Vec3& x : solver.particles().x) y += static_cast<double>(x.y());
        return y / n;
      };
      const double y0 = mean_y();
      // From here: the particles, then every step's grid and the frames' reorders.
      shellmpm_test::reset_heap_peak();
      solver.advance_to(3e-4);
      solver.advance_to(6e-4);
      const double peak = static_cast<double>(shellmpm_test::heap_peak() - base) / n;
      CAPTURE(threads, static_cast<int>(transfer), peak);
      CHECK(peak <= 110);
      // The cube moved down (0.5 m/s and gravity for 0.6 ms): the steps ran.
      CHECK(mean_y() < y0 - 2e-4);
    }
}
