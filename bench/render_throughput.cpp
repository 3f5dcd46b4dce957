// Seconds per preview frame: a 100k-triangle shell plus 1M particles (and a sphere
// collider and the ground) at 1280x720, raster (OSMesa) and ray traced (Embree), at 1 and
// 2 threads. Each configuration runs in its own process, because llvmpipe reads its thread
// count once per process.
//
//   render_throughput [--renderer raster,raytrace] [--threads 1,2] [--frames 3]
//                     [--size 1280x720] [--particles 1000000] [--samples 4] [--ao 2] [--no-cull]
//
// The timed part of a frame is what `shellmpm render` does after reading the caches:
// hidden-particle culling (render/particle_culling; --no-cull draws every particle) and
// the render itself (upload or BVH build, drawing or tracing, read-back).
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench/bench_args.h"
#include "render/particle_culling.h"
#include "render/renderer.h"
#include "render/tessellate.h"
#include "sim/core/parallel.h"

extern char** environ;

using namespace shellmpm;

namespace {

struct Args {
  std::vector<std::string> renderers{"raster", "raytrace"};
  std::vector<int> threads{1, 2};
  int frames = 3;
  int width = 1280, height = 720;
  long particles = 1000000;
  int samples = 4, ao = 2;
  bool child = false;
  bool cull = true;
};

/// A draped cloth: a 224 x 224 quad sheet (100,352 triangles) with a wave, smooth normals.
RenderMesh wavy_sheet(float phase) {
  const int n = 224;
  RenderMesh m = tessellate_square(Vec3d(0, 0.7, 0), Vec3d(0, 1, 0), 0.8, n);
  for (Vec3f& p : m.positions)
    p.y() += 0.12f * std::sin(6.0f * p.x() + phase) * std::cos(5.0f * p.z());
  m.normals = vertex_normals(m.positions, m.triangles);
  m.kind = SurfaceKind::Shell;
  m.front = Vec3f(0.8f, 0.3f, 0.2f);
  m.back = Vec3f(0.2f, 0.42f, 0.8f);
  return m;
}

PreviewScene bench_scene(const Args& a, int frame) {
  PreviewScene s;
  s.meshes.push_back(wavy_sheet(0.3f * frame));
  RenderMesh ball = tessellate_sphere(Vec3d(0.5, 0.25, -0.3), 0.25);
  ball.kind = SurfaceKind::Collider;
  ball.front = ball.back = Vec3f(0.45f, 0.45f, 0.48f);
  s.meshes.push_back(ball);
  RenderMesh g = tessellate_square(Vec3d(0, 0, 0), Vec3d(0, 1, 0), 4.0, 16);
  g.kind = SurfaceKind::Ground;
  g.front = g.back = Vec3f(0.5f, 0.5f, 0.48f);
  s.meshes.push_back(g);
  s.ground.center = Vec3f(0, 0, 0);
  s.ground.radius = 4.0f;
  s.ground.tile = 0.1f;
  // A sand pile of particles: a cone of radius 0.6 and height 0.45 on a jittered lattice.
  const double volume = M_PI * 0.36 * 0.45 / 3.0;
  const double h = std::cbrt(volume / static_cast<double>(a.particles));
  std::uint32_t state = 12345u + static_cast<std::uint32_t>(frame);
  auto rnd = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) * (1.0f / 16777216.0f);
  };
  for (double y = 0.5 * h;
       y < 0.45 && static_cast<long>(s.particles.positions.size()) < a.particles; y += h) {
    const double r = 0.6 * (1.0 - y / 0.45);
    for (double x = -r; x <= r; x += h)
      for (double z = -r; z <= r; z += h)
        if (x * x + z * z <= r * r && static_cast<long>(s.particles.positions.size()) < a.particles)
          s.particles.positions.emplace_back(static_cast<float>(x - 0.4 + 0.3 * h * rnd()),
                                             static_cast<float>(y + 0.3 * h * rnd()),
                                             static_cast<float>(z + 0.3 + 0.3 * h * rnd()));
  }
  s.particles.radius = static_cast<float>(0.5 * h);
  s.particles.color = Vec3f(0.76f, 0.6f, 0.38f);
  s.bounds_lo = Vec3f(-1.0f, 0.0f, -0.8f);
  s.bounds_hi = Vec3f(0.8f, 0.9f, 0.9f);
  s.lights.key_dir = Vec3f(-0.4f, 1.0f, 0.5f).normalized();
  s.lights.fill_dir = Vec3f(0.7f, 0.35f, 0.6f).normalized();
  s.lights.key = 0.8f;
  s.lights.fill = 0.25f;
  s.lights.ambient = 0.3f;
  s.ao_distance = 0.15f;
  s.samples = a.samples;
  s.ao_samples = a.ao;
  return s;
}

int child(const Args& a) {
  const std::string kind = a.renderers.front();
  const int threads = a.threads.front();
  ThreadLimit limit(threads);
  Camera cam;
  cam.eye = Vec3d(1.2, 1.4, 2.6);
  cam.target = Vec3d(-0.1, 0.35, 0.05);
  cam.fov_deg = 38;
  cam.width = a.width;
  cam.height = a.height;
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  std::unique_ptr<Renderer> r =
      make_renderer(kind == "raytrace" ? RendererKind::Raytrace : RendererKind::Raster, threads);
  const double setup = std::chrono::duration<double>(clock::now() - t0).count();
  std::vector<double> secs;
  std::size_t tris = 0, pts = 0, drawn = 0;
  for (int f = 0; f < a.frames; ++f) {
    PreviewScene s = bench_scene(a, f);  // building the scene is not timed
    tris = s.meshes.front().triangles.size();
    pts = s.particles.positions.size();
    t0 = clock::now();
    if (a.cull) drawn = pts - cull_hidden_particles(s.particles);  // as render/scene_assembler does
    const Image im = r->render(s, cam);
    secs.push_back(std::chrono::duration<double>(clock::now() - t0).count());
    if (im.width != a.width) return 1;
  }
  double steady = 0;
  for (std::size_t i = 1; i < secs.size(); ++i) steady += secs[i];
  steady = secs.size() > 1 ? steady / static_cast<double>(secs.size() - 1) : secs[0];
  if (!a.cull) drawn = pts;
  std::printf("| %-8s | %d | %zu | %zu (%zu drawn) | %dx%d | %.2f | %.3f | %.3f |\n", kind.c_str(),
              threads, tris, pts, drawn, a.width, a.height, setup, secs[0], steady);
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", k.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (k == "--renderer") {
      a.renderers.clear();
      std::string v = next();
      for (std::size_t p = 0, q; p <= v.size(); p = q + 1) {
        q = v.find(',', p);
        if (q == std::string::npos) q = v.size();
        a.renderers.push_back(v.substr(p, q - p));
      }
    } else if (k == "--threads") {
      a.threads = shellmpm_bench::parse_int_list(next());
    } else if (k == "--frames") {
      a.frames = std::max(1, std::atoi(next().c_str()));
    } else if (k == "--size") {
      if (std::sscanf(next().c_str(), "%dx%d", &a.width, &a.height) != 2) return 2;
    } else if (k == "--particles") {
      a.particles = std::atol(next().c_str());
    } else if (k == "--samples") {
      a.samples = std::atoi(next().c_str());
    } else if (k == "--ao") {
      a.ao = std::atoi(next().c_str());
    } else if (k == "--no-cull") {
      a.cull = false;
    } else if (k == "--child") {
      a.child = true;
    } else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return 2;
    }
  }
  if (a.child) return child(a);
  std::printf(
      "render_throughput: 100k-triangle shell + %ld particles + sphere + ground, %d frames "
      "(ray traced: %d samples/pixel, %d AO rays/sample)\n",
      a.particles, a.frames, a.samples, a.ao);
  std::printf(
      "| renderer | threads | triangles | particles | size | setup s | first frame s | s/frame "
      "|\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  for (const std::string& r : a.renderers)
    for (int t : a.threads) {
      std::vector<std::string> args = {
          "/proc/self/exe", "--child",
          "--renderer",     r,
          "--threads",      std::to_string(t),
          "--frames",       std::to_string(a.frames),
          "--size",         std::to_string(a.width) + "x" + std::to_string(a.height),
          "--particles",    std::to_string(a.particles),
          "--samples",      std::to_string(a.samples),
          "--ao",           std::to_string(a.ao)};
      if (!a.cull) args.push_back("--no-cull");
      std::vector<char*> argv2;
      for (std::string& s : args) argv2.push_back(s.data());
      argv2.push_back(nullptr);
      pid_t pid;
      int status = 0;
      if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv2.data(), environ) != 0 ||
          waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "configuration %s / %d threads failed\n", r.c_str(), t);
        return 1;
      }
    }
  return 0;
}
