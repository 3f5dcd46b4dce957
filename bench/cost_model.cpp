// bench/cost_model: does the cost of a bulk particle-step stay flat as a shot grows, and
// as its material spreads thinly over a large domain? (issue 15: no hidden O(n log n) or
// dense-domain cost.)
//
// Two sweeps of the elastic cube of mpm_throughput (8 particles per cell, dx 1/128,
// quadratic APIC, float), timed at each thread count:
//   size:     one cube of 64k, 256k, 1M and 4M particles in a 1 m domain;
//   sparsity: about 256k particles as 1, 8 or 64 cubes spread over domains of 1, 2 and 4 m
//             a side (128^3 .. 512^3 cells), from a dense block to under 0.2% of the domain.
// Prints nanoseconds per particle-step, the speed-up from the first thread count, and bytes
// per particle (particle arrays; grid and bins).
//
//   cost_model [--threads 1,2] [--max-particles N] [--work W]
//   (W: particle-steps per timed run, default 8e6; each run takes at least 4 steps)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/bench_args.h"
#include "bench/bench_material.h"
#include "bench/timed_advance.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

namespace {

constexpr double kDx = 1.0 / 128;
constexpr double kDt = 1e-4;

/// `count` cubes of `cells` cells a side on a regular lattice over a cubic domain of side
/// `domain` m.
Scene cubes_scene(int count, double cells, double domain) {
  Scene s;
  s.path = "bench";
  s.shot.dx = kDx;
  s.shot.domain_min = Vec3d(0, 0, 0);
  s.shot.domain_max = Vec3d::Constant(domain);
  s.shot.cfl = 0.9;
  s.shot.dt_max = kDt;
  s.shot.gravity = Vec3d::Zero();  // nothing leaves its place during the timed steps
  s.materials.push_back(shellmpm_bench::jelly());
  const int per_side = static_cast<int>(std::lround(std::cbrt(static_cast<double>(count))));
  const double side = cells * kDx, pitch = domain / per_side;
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j)
      for (int k = 0; k < per_side; ++k) {
        SourceDesc src;
        src.material = 0;
        src.shape.kind = ShapeDesc::Kind::Box;
        const Vec3d centre = pitch * (Vec3d(i, j, k) + Vec3d::Constant(0.5));
        src.shape.min = centre - Vec3d::Constant(side / 2);
        src.shape.max = centre + Vec3d::Constant(side / 2);
        src.particles_per_cell = 8;
        src.velocity = Vec3d(0.3, -0.5, 0.2);
        s.sources.push_back(src);
      }
  return s;
}

struct Timing {
  std::size_t particles = 0;
  double ns_per_particle_step = 0;
  double particle_bytes = 0, grid_bytes = 0;
};

Timing time_scene(const Scene& scene, int threads, double work) {
  ThreadLimit limit(threads);
  Solver solver(scene);
  solver.advance_to(2 * kDt);  // allocate the grid, touch memory
  Timing t;
  t.particles = solver.particles().size();
  const int steps = std::max(4, static_cast<int>(work / static_cast<double>(t.particles)));
  const shellmpm_bench::TimedAdvance r = shellmpm_bench::timed_advance(solver, steps * kDt);
  t.ns_per_particle_step = 1e9 * r.seconds / (static_cast<double>(t.particles) * r.stats.substeps);
  t.particle_bytes = static_cast<double>(solver.particles().bytes()) / t.particles;
  t.grid_bytes = static_cast<double>(solver.grid().bytes()) / t.particles;
  return t;
}

void row(const char* sweep, const Scene& scene, double domain, const std::vector<int>& threads,
         double work) {
  const double domain_cells = std::pow(domain / kDx, 3);
  std::vector<Timing> ts;
  for (int n : threads) ts.push_back(time_scene(scene, n, work));
  const Timing& a = ts.front();
  // Each particle fills 1/8 of a cell.
  std::printf("%-9s %5zu %9zu %8.0fk %8.3f%%", sweep, scene.sources.size(), a.particles,
              domain_cells / 1e3, 100.0 * a.particles / 8.0 / domain_cells);
  for (const Timing& t : ts) std::printf(" %9.1f", t.ns_per_particle_step);
  for (std::size_t i = 1; i < ts.size(); ++i)
    std::printf(" %6.2fx", a.ns_per_particle_step / ts[i].ns_per_particle_step);
  std::printf(" %7.1f %6.1f\n", a.particle_bytes, a.grid_bytes);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> threads = {1, 2};
  double max_particles = 4.2e6, work = 8e6;
  using shellmpm_bench::parse_int_list;
  if (!shellmpm_bench::parse_options(
          argc, argv,
          {{"--threads", [&](const char* v) { threads = parse_int_list(v); }},
           {"--max-particles", [&](const char* v) { max_particles = std::atof(v); }},
           {"--work", [&](const char* v) { work = std::atof(v); }}}))
    return 2;
  if (threads.empty() || work <= 0) {
    std::fprintf(stderr, "cost_model: --threads needs a list, --work a positive number\n");
    return 2;
  }
  std::printf("cost_model: elastic cubes, 8 particles/cell, dx 1/128, apic, %s, dt %g s\n",
              sizeof(Real) == 4 ? "float" : "double", kDt);
  std::printf("%-9s %5s %9s %9s %9s", "sweep", "cubes", "particles", "domain", "active");
  for (int n : threads) std::printf(" %6s ns", (std::to_string(n) + "t").c_str());
  for (std::size_t i = 1; i < threads.size(); ++i)
    std::printf(" %7s",
                (std::to_string(threads[i]) + "t/" + std::to_string(threads[0]) + "t").c_str());
  std::printf(" %7s %6s\n", "B/part", "B/grid");
  // Size: one cube, 64k .. 4M particles (cells a side: cbrt(N / 8)).
  for (double n : {65536.0, 262144.0, 1048576.0, 4194304.0}) {
    if (n > max_particles) break;
    const double cells = std::round(std::cbrt(n / 8));
    row("size", cubes_scene(1, cells, 1.0), 1.0, threads, work);
  }
  // Sparsity: ~256k particles as 1, 8 or 64 cubes over 1, 2 and 4 m domains.
  for (double domain : {1.0, 2.0, 4.0})
    for (int count : {1, 8, 64}) {
      const double cells = std::round(std::cbrt(262144.0 / 8 / count));
      row("sparsity", cubes_scene(count, cells, domain), domain, threads, work);
    }
  return 0;
}
