// The heap peak of a bulk run, per particle, through operator new
// (tests/support/heap_counter.h): the cube of bench/mpm_throughput (262,144 particles,
// 8 per cell, dx 1/128, float), from the first step through two frame reorders.
#include <catch2/catch.hpp>

#include "bench/bench_material.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"
#include "tests/support/heap_counter.h"

using namespace shellmpm;

TEST_CASE("a bulk run peaks at most 110 bytes per particle, reorders included", "[memory]") {
  for (const Transfer transfer : {Transfer::Apic, Transfer::Mls})
    for (const int threads : {1, 2}) {
      ThreadLimit limit(threads);
      const std::size_t base = shellmpm_test::heap_current();
      Solver solver(shellmpm_bench::cube_scene(32, 1.0 / 128, transfer));
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
