// bench/shell_throughput: Kirchhoff-Love shell forces on a sheet of about 100k control
// points (grid-free explicit steps). Prints quadrature-point evaluations per second
// (per in-plane point with all thickness layers, and per layer) and ms per step at 1
// and 2 threads, with the split between force evaluation and the update.
//
//   shell_throughput [--vertices N] [--steps S] [--threads 1,2]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/bench_args.h"
#include "bench/timed_advance.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

int main(int argc, char** argv) {
  shellmpm_bench::SheetArgs args;
  if (!shellmpm_bench::parse_sheet_args(argc, argv, args)) return 2;
  const int steps = args.steps;
  const int n = args.quads_per_side();
  Scene s;
  s.path = "bench";
  s.shot.dx = 0.01;
  s.shot.domain_min = Vec3d(-5, -5, -5);
  s.shot.domain_max = Vec3d(5, 5, 5);
  ShellMaterialDesc m;
  m.name = "cloth";
  m.youngs_modulus = 1e6;
  m.density = 300;
  m.thickness = 1e-3;
  s.shell_materials.push_back(m);
  ShellDesc sh;
  sh.name = "sheet";
  sh.kind = ShellDesc::Kind::Sheet;
  sh.size[0] = sh.size[1] = 2.0;
  sh.resolution[0] = sh.resolution[1] = n;
  PinDesc pin;
  pin.indices = {0, n};
  sh.pins.push_back(pin);
  s.shells.push_back(sh);
  const auto t_setup = std::chrono::steady_clock::now();
  Solver probe(s);
  const double setup =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_setup).count();
  const auto& kl = probe.shells()[0]->kl();
  const double qp = static_cast<double>(kl.num_quadrature_points());
  const int layers = kl.num_layers();
  std::printf(
      "shell_throughput: sheet %dx%d quads, %zu control points, %.0f in-plane quadrature "
      "points x %d layers, %s, setup %.2f s\n",
      n, n, probe.shells()[0]->size(), qp, layers, sizeof(Real) == 4 ? "float" : "double", setup);
  double base = 0;
  for (int t : args.threads) {
    ThreadLimit limit(t);
    Solver solver(s);
    const double dt = solver.stable_dt();
    solver.advance_to(2 * dt);  // warm up
    const shellmpm_bench::TimedAdvance run = shellmpm_bench::timed_advance(solver, steps * dt);
    const FrameStats& fs = run.stats;
    const double sec = run.seconds;
    double forces = 0;
    for (const auto& [name, v] : fs.stage_seconds)
      if (name == "shell_forces") forces = v;
    const double per_step = sec / fs.substeps;
    const double qps = qp * fs.substeps / forces;
    if (base == 0) base = per_step;
    std::printf(
        "threads %d: %.2f ms per step (forces %.2f ms), %.2f M quadrature points/s "
        "(%.2f M layer evaluations/s, %.2f M per thread), speed-up %.2fx\n",
        t, 1e3 * per_step, 1e3 * forces / fs.substeps, qps / 1e6, qps * layers / 1e6,
        qps * layers / 1e6 / t, base / per_step);
  }
  return 0;
}
