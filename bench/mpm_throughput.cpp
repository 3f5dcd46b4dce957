// bench/mpm_throughput: an elastic cube (8 particles per cell, quadratic APIC, float)
// falling under gravity. Prints particle-steps per second at 1 and 2 threads (and
// more if the machine has them), the split by stage, and bytes per particle.
//
//   mpm_throughput [--particles N] [--steps S] [--transfer apic|mls] [--threads a,b,...]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "bench/bench_args.h"
#include "bench/bench_material.h"
#include "bench/timed_advance.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

namespace {

struct Result {
  double pss = 0;  // particle-steps per second
  std::map<std::string, double> stage;
  double total = 0;  // per-step work [s]
  double frame = 0;  // per-frame work [s]
  std::size_t particles = 0;
  double particle_bytes = 0, grid_bytes = 0;
};

Result run(const Scene& scene, int threads, int steps) {
  ThreadLimit limit(threads);
  Solver solver(scene);
  solver.advance_to(2e-4);  // warm up: allocate the grid, touch memory
  const shellmpm_bench::TimedAdvance run = shellmpm_bench::timed_advance(solver, steps * 1e-4);
  const FrameStats& fs = run.stats;
  // Per-frame work (the reorder, the frame's statistics) runs once in these few dozen
  // steps but once in about 400 of a production frame (dt 1e-4 at 24 fps): counted apart.
  const double frame = shellmpm_bench::per_frame_seconds(fs);
  const double sec = run.seconds - frame;
  Result r;
  r.particles = solver.particles().size();
  r.pss = static_cast<double>(r.particles) * fs.substeps / sec;
  r.total = sec;
  r.frame = frame;
  for (const auto& [n, s] : fs.stage_seconds)
    if (!shellmpm_bench::per_frame_stage(n)) r.stage[n] = s;
  r.particle_bytes = static_cast<double>(solver.particles().bytes()) / r.particles;
  r.grid_bytes = static_cast<double>(solver.grid().bytes()) / r.particles;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  double target = 512000;
  int steps = 40;
  std::string transfer = "apic";
  std::vector<int> threads = {1, 2};
  double dx = 1.0 / 128;
  using shellmpm_bench::parse_int_list;
  if (!shellmpm_bench::parse_options(
          argc, argv,
          {{"--particles", [&](const char* v) { target = std::atof(v); }},
           {"--steps", [&](const char* v) { steps = std::atoi(v); }},
           {"--transfer", [&](const char* v) { transfer = v; }},
           {"--dx", [&](const char* v) { dx = std::atof(v); }},
           {"--threads", [&](const char* v) { threads = parse_int_list(v); }}}))
    return 2;
  const double cells = std::round(std::cbrt(target / 8.0));
  const Scene scene =
      shellmpm_bench::cube_scene(cells, dx, transfer == "mls" ? Transfer::Mls : Transfer::Apic);
  std::printf(
      "mpm_throughput: elastic cube %gx%gx%g cells, 8 particles/cell, dx %g, %s, %s, %d steps\n",
      cells, cells, cells, dx, transfer.c_str(), sizeof(Real) == 4 ? "float" : "double", steps);
  double base = 0;
  for (int t : threads) {
    const Result r = run(scene, t, steps);
    if (base == 0) base = r.pss;
    std::printf(
        "threads %d: %zu particles, %.3f s, %.2f M particle-steps/s (%.2f M per thread), speed-up "
        "%.2fx; and %.3f s of per-frame reorder and statistics\n",
        t, r.particles, r.total, r.pss / 1e6, r.pss / 1e6 / t, r.pss / base, r.frame);
    std::printf("  stages:");
    for (const auto& [n, s] : r.stage) std::printf(" %s %.1f%%", n.c_str(), 100.0 * s / r.total);
    std::printf("\n  bytes per particle: %.1f in particle arrays, %.1f in the grid and bins\n",
                r.particle_bytes, r.grid_bytes);
  }
  return 0;
}
