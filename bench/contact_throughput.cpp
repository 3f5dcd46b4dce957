// bench/contact_throughput: a cloth of about 100k control points dropped on a sphere,
// with contact on the MPM grid (dx matched to the mesh spacing). Runs the cloth until
// it lies on the sphere, then times substeps there. Prints ms per step, steps per frame,
// ms per frame at 24 fps, and the split by stage (transfers, shell forces, contact
// forces, friction plasticity) at 1 and 2 threads.
//
//   contact_throughput [--vertices N] [--steps S] [--threads 1,2]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "bench/bench_args.h"
#include "bench/timed_advance.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

int main(int argc, char** argv) {
  shellmpm_bench::SheetArgs args;
  // 100 steps: the shell guard rebuilds its candidate lists every few dozen steps here
  // (about 0.1 s each), so a shorter window may leave them out.
  args.steps = 100;
  if (!shellmpm_bench::parse_sheet_args(argc, argv, args)) return 2;
  const int steps = args.steps;
  const int n = args.quads_per_side();
  const double size = 2.0, h = size / n;
  Scene s;
  s.path = "bench";
  s.shot.dx = h;  // mesh spacing = grid spacing
  s.shot.cfl = 0.5;
  s.shot.fps = 24;
  s.shot.domain_min = Vec3d(-1.3, -0.2, -1.3);
  s.shot.domain_max = Vec3d(1.3, 1.5, 1.3);
  s.shot.contact_at = args.contact_at == "stencil" ? ContactAt::Stencil : ContactAt::Surface;
  ShellMaterialDesc m;
  m.name = "cotton";
  m.youngs_modulus = 5e5;
  m.density = 300;
  m.thickness = 1e-3;
  m.damping = 0.5;
  s.shell_materials.push_back(m);
  ShellDesc sh;
  sh.name = "cloth";
  sh.kind = ShellDesc::Kind::Sheet;
  sh.size[0] = sh.size[1] = size;
  sh.resolution[0] = sh.resolution[1] = n;
  sh.translate = Vec3d(0, 0.75 + 2 * h, 0);
  sh.velocity = Vec3d(0, -1.5, 0);  // lands on the sphere within a few ms
  s.shells.push_back(sh);
  ColliderDesc ball;
  ball.name = "ball";
  ball.shape.kind = ShapeDesc::Kind::Sphere;
  ball.shape.center = Vec3d(0, 0.4, 0);
  ball.shape.radius = 0.35;
  ball.friction = 0.5;
  s.colliders.push_back(ball);
  std::printf(
      "contact_throughput: cloth %dx%d quads (%d control points, %d contact particles), "
      "dx = %.4g m, %s, contact at the %ss\n",
      n, n, (n + 1) * (n + 1), 2 * n * n, h, sizeof(Real) == 4 ? "float" : "double",
      args.contact_at.c_str());
  double base = 0;
  for (int t : args.threads) {
    ThreadLimit limit(t);
    Solver solver(s);
    const double dt = solver.stable_dt();
    // Fall until the cloth touches the ball (2 h at 1.5 m/s), then time.
    solver.advance_to(3 * h / 1.5);
    const shellmpm_bench::TimedAdvance run = shellmpm_bench::timed_advance(solver, steps * dt);
    const FrameStats& fs = run.stats;
    // Per-frame work (the reorder, the integrity monitor's first and frame-end checks, the
    // frame's statistics) runs once in the timed advance but once in ~900 steps of a real
    // frame: counted apart.
    const double frame_sec = shellmpm_bench::per_frame_seconds(fs);
    const double sec = run.seconds - frame_sec;
    const double per_step = sec / fs.substeps;
    const double steps_per_frame = std::ceil(1.0 / (s.shot.fps * dt));
    if (base == 0) base = per_step;
    std::printf(
        "threads %d: %.1f ms per step, %.0f steps per frame -> %.1f s per frame "
        "(%.0f ms, and %.0f ms of per-frame checks, statistics and reorder); speed-up %.2fx; in "
        "contact "
        "%zu, sliding %zu\n",
        t, 1e3 * per_step, steps_per_frame, per_step * steps_per_frame,
        1e3 * per_step * steps_per_frame, 1e3 * frame_sec, base / per_step, fs.contact_compressed,
        fs.contact_sliding);
    std::map<std::string, double> groups;
    for (const auto& [name, v] : fs.stage_seconds) {
      if (shellmpm_bench::per_frame_stage(name)) continue;
      std::string g = name;
      if (name == "bin" || name == "p2g" || name == "g2p" || name == "grid") g = "transfers+grid";
      if (name == "contact" || name == "contact_grid") g = "contact forces";
      if (name == "friction") g = "friction plasticity";
      groups[g] += v;
    }
    std::printf("  per step:");
    for (const auto& [g, v] : groups) std::printf("  %s %.1f ms", g.c_str(), 1e3 * v / fs.substeps);
    std::printf("\n  stages:");
    for (const auto& [name, v] : fs.stage_seconds)
      if (!shellmpm_bench::per_frame_stage(name) && v > 0)
        std::printf("  %s %.1f", name.c_str(), 1e3 * v / fs.substeps);
    std::printf("\n");
  }
  return 0;
}
