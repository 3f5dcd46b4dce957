// bench/implicit_vs_explicit: seconds per 24 fps frame of the explicit and the implicit
// integrator on stiff shells without contact, and what each computes.
//
// Cases: an aluminium strip (E 7e10, nu 0.33, rho 2700, 1 mm, 0.2 x 0.05 m, clamped at
// one end, released flat under gravity: its explicit step is about 1.4 microseconds) and a
// 0.5 mm steel sheet (E 2e11, nu 0.3, rho 7850, 0.2 x 0.2 m, clamped on two opposite
// edges, 200 Pa of pressure). For each: explicit, and implicit with at most 1, 10 and 100
// steps per frame, at 1 and 2 threads: steps and seconds per frame, Newton and CG
// iterations, and the largest deflection at the end of every frame against the static
// solution (the explicit run oscillates about it; backward Euler at frame-sized steps
// damps the oscillation and lands on it).
//
// Then the steel dent without contact: scenes/steel_dent.yaml with `contact: off` (the
// control points meet the ball through the collider projection and, implicit, the
// collider penalty) over one 24 fps frame, explicit at CFL 0.5 and 0.25 and implicit at
// up to a frame per step with the ball's speed bounding the step (cfl 0.5, 0.25, 0.125)
// and at 1e-4 s: seconds per frame and the permanent dent (issue 14's target: 20x less
// time than explicit at a dent within 5%).
//
// Then, with contact on the grid: scenes/steel_dent.yaml (the same steel, 0.3 m, clamped
// on four edges, struck by a collider ball at 10 m/s that presses 1 cm past it and
// withdraws; 240 fps), explicit at CFL 0.5 and 0.25 (how far the reference has converged
// in time) and implicit at one step per frame, at 1/2400 s and at 1e-4 s, at 1 and 2
// threads: seconds per frame, steps, Newton and CG, and the sheet's permanent dent (the
// static shape of its plastic state after the ball has left).
//
// Then cloth in contact: scenes/cloth_drape.yaml (a cloth of 1,681 control points dropped
// on a sphere collider and the ground, contact on the grid) over its first D frames
// (--drape-frames, default 12: the fall, the impact at frame 5 and the drape), explicit and
// implicit at up to a frame per step: seconds per frame, steps, Newton and CG.
//
//   implicit_vs_explicit [--frames F] [--threads 1,2] [--explicit-frames E]
//                        [--no-dent | --dent-only] [--no-grid-dent] [--no-explicit-dent]
//                        [--drape-frames D] [--no-drape | --drape-only] [--grid-dent-only]
//                        [--grid-steps N,...]  (the grid dent at 1/(240 N) s instead)
//                        [--grid-dx D]  (the grid dent's cell size instead of 2 cm)
//                        [--grid-kc K]  (the grid dent's normal contact stiffness [Pa]
//                                        instead of E; the shear stays E)
//                        [--plasticity-in-solve]  (implicit: denting inside each solve
//                                        instead of after it, shot.plasticity_in_solve)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench/bench_args.h"
#include "bench/timed_advance.h"
#include "io/scene_reader.h"
#include "sim/core/parallel.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

struct Case {
  std::string name;
  Scene scene;
};

Scene base_scene() {
  Scene s;
  s.path = "bench";
  s.shot.dx = 0.02;
  s.shot.fps = 24;
  s.shot.dt_min = 1e-9;  // the explicit steps of these sheets are below the default 1e-6
  s.shot.domain_min = Vec3d(-1, -1, -1);
  s.shot.domain_max = Vec3d(1, 1, 1);
  return s;
}

Case aluminium_strip() {
  Case c{"aluminium strip 1 mm", base_scene()};
  c.scene.shell_materials.push_back(
      shellmpm::test::shell_material("aluminium", 7e10, 0.33, 2700, 1e-3));
  const ShellDesc sh = shellmpm::test::clamped_strip("strip");
  c.scene.shells.push_back(sh);
  return c;
}

Case steel_sheet() {
  Case c{"steel sheet 0.5 mm", base_scene()};
  c.scene.shell_materials.push_back(shellmpm::test::steel_sheet_material());
  ShellDesc sh = shellmpm::test::free_sheet("sheet", 0.2, 16);
  sh.pressure = 200;
  for (const double x : {-0.1, 0.1}) {
    PinDesc edge;
    edge.has_box = true;
    edge.box_min = Vec3d(x - 1e-6, -1, -1);
    edge.box_max = Vec3d(x + 1e-6, 1, 1);
    sh.pins.push_back(edge);
  }
  c.scene.shells.push_back(sh);
  return c;
}

/// Sums over timed frames: seconds, steps, Newton and CG iterations, retries.
struct Totals {
  double seconds = 0;
  long steps = 0, newton = 0, cg = 0, retries = 0;
  void add(const shellmpm_bench::TimedAdvance& r) {
    seconds += r.seconds;
    steps += r.stats.substeps;
    newton += r.stats.implicit_stats.newton_iterations;
    cg += r.stats.implicit_stats.cg_iterations;
    retries += r.stats.implicit_stats.retries;
  }
  double per_step(long n) const { return steps ? static_cast<double>(n) / steps : 0.0; }
};

double max_deflection(const ShellObject& sh) {
  double w = 0;
  for (std::size_t i = 0; i < sh.size(); ++i)
    w = std::max(w, (sh.x[i].cast<double>() - sh.rest[i]).norm());
  return w;
}

void run(const Case& c, int steps_per_frame, int frames, int threads) {
  Scene s = c.scene;
  if (steps_per_frame > 0) {
    s.shot.integrator = Integrator::Implicit;
    s.shot.dt_max = 1.0 / (s.shot.fps * steps_per_frame);
  }
  ThreadLimit limit(threads);
  Solver solver(s);
  Totals t;
  std::string deflections;
  for (int f = 0; f < frames; ++f) {
    t.add(shellmpm_bench::timed_advance(solver, 1.0 / s.shot.fps));
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.3f", f ? " " : "",
                  1e3 * max_deflection(*solver.shells()[0]));
    deflections += buf;
  }
  const std::string what = steps_per_frame > 0
                               ? "implicit <= " + std::to_string(steps_per_frame) + "/frame"
                               : "explicit";
  std::printf(
      "  %-22s threads %d: %8.3f s/frame, %8.1f steps/frame, Newton %5.1f CG %7.1f per step, "
      "retries %ld; deflection per frame [mm]: %s\n",
      what.c_str(), threads, t.seconds / frames, static_cast<double>(t.steps) / frames,
      t.per_step(t.newton), t.per_step(t.cg), t.retries, deflections.c_str());
}

/// scenes/steel_dent.yaml with dt_max (0: explicit at CFL cfl). With contact on the grid
/// (`direct` false): its two moving 240 fps frames. Without (`direct`: the control points
/// are the unknowns and meet the ball through the collider projection and penalty): one
/// 24 fps frame, with the theta method's theta.
bool g_plasticity_in_solve = false;  // --plasticity-in-solve: true

void dent(double dt_max, double cfl, int threads, bool direct = false, double theta = 1,
          double dx = 0, double kc = 0) {
  Scene s = read_scene(std::string(SHELLMPM_SOURCE_DIR) + "/scenes/steel_dent.yaml");
  s.shot.cfl = cfl;
  s.shot.plasticity_in_solve = g_plasticity_in_solve;
  if (dx > 0) s.shot.dx = dx;
  if (kc > 0) {
    ShellMaterialDesc& m = s.shell_materials.at(0);
    m.contact_shear = m.contact_shear.value_or(m.contact_stiffness.value_or(m.youngs_modulus));
    m.contact_stiffness = kc;
  }
  s.shot.dt_min = std::min(s.shot.dt_min, 1e-8);
  if (direct) {
    s.shells[0].contact = ShellDesc::Contact::Off;
    s.shot.fps = 24;
    s.shot.implicit_theta = theta;
  }
  if (dt_max > 0) {
    s.shot.integrator = Integrator::Implicit;
    s.shot.dt_max = dt_max;
  }
  ThreadLimit limit(threads);
  Solver solver(s);
  Totals t;
  double plastic = 0;
  const int frames = direct ? 1 : 2;
  for (int f = 0; f < frames; ++f) {
    const shellmpm_bench::TimedAdvance r = shellmpm_bench::timed_advance(solver, 1.0 / s.shot.fps);
    t.add(r);
    plastic = r.stats.shell_plastic_work;
  }
  ShellObject& sh = *solver.shells()[0];
  sh.settle(Vec3d::Zero(), solver.time(), 1e-6, 2000, false);
  double low = 1e9;
  for (const Vec3& x : sh.x) low = std::min(low, static_cast<double>(x.y()));
  char what[64];
  if (dt_max > 0 && theta < 1)
    std::snprintf(what, sizeof what, "implicit dt_max %.3g s cfl %.3g theta %.2g", dt_max, cfl,
                  theta);
  else if (dt_max > 0)
    std::snprintf(what, sizeof what, "implicit dt_max %.3g s cfl %.3g", dt_max, cfl);
  else
    std::snprintf(what, sizeof what, "explicit CFL %.3g", cfl);
  if (dx > 0)
    std::snprintf(what + std::strlen(what), sizeof what - std::strlen(what), " dx %g", dx);
  if (kc > 0)
    std::snprintf(what + std::strlen(what), sizeof what - std::strlen(what), " k_c %g", kc);
  std::printf(
      "  %-26s threads %d: %8.3f s/frame, %8.1f steps/frame, Newton %5.1f CG %7.1f per step; "
      "plastic work %.3g J, permanent dent %.2f mm\n",
      what, threads, t.seconds / frames, static_cast<double>(t.steps) / frames,
      t.per_step(t.newton), t.per_step(t.cg), plastic, 1e3 * (0.1 - low));
}

/// scenes/cloth_drape.yaml to frame `frames`, explicit or implicit (dt_max one frame).
void drape(bool implicit, int frames, int threads) {
  Scene s = read_scene(std::string(SHELLMPM_SOURCE_DIR) + "/scenes/cloth_drape.yaml");
  if (implicit) {
    s.shot.integrator = Integrator::Implicit;
    s.shot.dt_max = 1.0 / s.shot.fps;
  }
  ThreadLimit limit(threads);
  Solver solver(s);
  Totals t;
  for (int f = 2; f <= frames; ++f) t.add(shellmpm_bench::timed_advance(solver, 1.0 / s.shot.fps));
  double low = 1e9;
  for (const Vec3& x : solver.shells()[0]->x) low = std::min(low, static_cast<double>(x.y()));
  std::printf(
      "  %-9s threads %d: %7.3f s/frame over frames 2-%d, %7.1f steps/frame, Newton %5.1f CG "
      "%6.1f per step, retries %ld; lowest control point %.4f m\n",
      implicit ? "implicit" : "explicit", threads, t.seconds / (frames - 1), frames,
      static_cast<double>(t.steps) / (frames - 1), t.per_step(t.newton), t.per_step(t.cg),
      t.retries, low);
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 6, explicit_frames = 2, drape_frames = 12;
  bool with_dent = true, dent_only = false, grid_dent = true, explicit_dent = true;
  bool with_drape = true, drape_only = false, grid_dent_only = false;
  // The switches take no value: taken out before the value options.
  const struct {
    const char* name;
    bool* flag;
    bool value;
  } switches[] = {{"--no-dent", &with_dent, false},
                  {"--dent-only", &dent_only, true},
                  {"--no-grid-dent", &grid_dent, false},
                  {"--no-explicit-dent", &explicit_dent, false},
                  {"--no-drape", &with_drape, false},
                  {"--drape-only", &drape_only, true},
                  {"--grid-dent-only", &grid_dent_only, true},
                  {"--plasticity-in-solve", &g_plasticity_in_solve, true}};
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    bool matched = false;
    for (const auto& s : switches)
      if (std::string(argv[i]) == s.name) {
        *s.flag = s.value;
        matched = true;
      }
    if (!matched) argv[kept++] = argv[i];
  }
  argc = kept;
  std::vector<int> threads = {1, 2};
  std::vector<int> grid_steps;  // steps per 240 fps frame of the grid dent (empty: the default)
  double grid_dx = 0;           // the grid dent's cell size (0: the scene's)
  double grid_kc = 0;           // the grid dent's normal contact stiffness (0: the scene's)
  using shellmpm_bench::parse_int_list;
  if (!shellmpm_bench::parse_options(
          argc, argv,
          {{"--frames", [&](const char* v) { frames = std::atoi(v); }},
           {"--explicit-frames", [&](const char* v) { explicit_frames = std::atoi(v); }},
           {"--drape-frames", [&](const char* v) { drape_frames = std::max(2, std::atoi(v)); }},
           {"--threads", [&](const char* v) { threads = parse_int_list(v); }},
           {"--grid-steps", [&](const char* v) { grid_steps = parse_int_list(v); }},
           {"--grid-dx", [&](const char* v) { grid_dx = std::atof(v); }},
           {"--grid-kc", [&](const char* v) { grid_kc = std::atof(v); }}}))
    return 2;
  if (drape_only) {
    with_dent = false;
    dent_only = true;
  }
  for (const Case& c : {aluminium_strip(), steel_sheet()}) {
    if (dent_only || grid_dent_only) break;
    Solver probe(c.scene);
    ShellObject& sh = *probe.shells()[0];
    std::printf("%s: %zu control points, explicit stable step %.3g s (%.0f per frame)\n",
                c.name.c_str(), sh.size(), sh.stable_dt(c.scene.shot.cfl),
                1.0 / (c.scene.shot.fps * sh.stable_dt(c.scene.shot.cfl)));
    sh.settle(c.scene.shot.gravity, 0.0, 1e-9, 2000, false);
    std::printf("  static deflection %.3f mm\n", 1e3 * max_deflection(sh));
    for (int t : threads) {
      run(c, 0, explicit_frames, t);
      for (int spf : {1, 10, 100}) run(c, spf, frames, t);
    }
  }
  if (with_drape && !grid_dent_only && (drape_only || !dent_only)) {
    std::printf("cloth_drape (scenes/cloth_drape.yaml, contact on the grid, 24 fps):\n");
    for (int t : threads)
      for (const bool implicit : {false, true}) drape(implicit, drape_frames, t);
  }
  if (!with_dent) return 0;
  if (!grid_dent_only) {
    std::printf("steel dent without contact (scenes/steel_dent.yaml, contact: off, 24 fps):\n");
    for (int t : threads) {
      if (explicit_dent)
        for (const double cfl : {0.5, 0.25}) dent(0.0, cfl, t, true);
      // Implicit at up to a frame per step: the ball's speed bounds the step while it
      // moves (cfl dx / 10 m/s), then the sheet's own motion does.
      for (const double cfl : {0.5, 0.25, 0.125}) dent(1.0 / 24, cfl, t, true);
      dent(1e-4, 0.5, t, true);
    }
  }
  if (!grid_dent) return 0;
  std::printf("steel dent (scenes/steel_dent.yaml, contact on the grid, 240 fps):\n");
  for (int t : threads) {
    // The explicit reference at its stable step and at half of it (how far it has
    // converged in time), then implicit at one step per frame down to 1e-4 s.
    if (explicit_dent)
      for (const double cfl : {0.5, 0.25}) dent(0.0, cfl, t, false, 1, grid_dx, grid_kc);
    std::vector<double> steps = {1.0 / 240, 1.0 / 2400, 1e-4};
    if (!grid_steps.empty()) steps.clear();
    for (const int n : grid_steps) steps.push_back(1.0 / (240.0 * std::max(n, 1)));
    for (const double dt : steps) dent(dt, 0.5, t, false, 1, grid_dx, grid_kc);
  }
  return 0;
}
