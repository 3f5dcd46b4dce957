// The shell guard (sim/contact/shell_guard.h) on driven states with known answers: two
// sheets driven through each other, bulk particles fired at a sheet, a pinned sheet (and
// the work its pin does), and the claim that the candidate lists never change a result.
// Each step stands in for G2P: velocities are set to the drive, x += dt v, then the guard
// runs.
#include <catch2/catch.hpp>

#include <algorithm>

#include "sim/contact/shell_guard.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

constexpr double kDt = 1e-3;
constexpr double kGap = 2e-3;

std::unique_ptr<ShellObject> sheet(double size, int res, double y, double density = 300) {
  ShellDesc d;
  d.name = "sheet";
  d.kind = ShellDesc::Kind::Sheet;
  d.size[0] = d.size[1] = size;
  d.resolution[0] = d.resolution[1] = res;
  d.translate = Vec3d(0, y, 0);
  ShellMaterialDesc m = test::cloth_material();
  m.density = density;
  return std::make_unique<ShellObject>(d, m, build_shell_rest_mesh(d));
}

std::vector<GridShell> grid_shells(const std::vector<std::unique_ptr<ShellObject>>& sh) {
  std::vector<GridShell> g(sh.size());
  for (std::size_t i = 0; i < sh.size(); ++i) g[i].shell = sh[i].get();
  return g;
}

/// Limit mesh (refine 0) positions of a shell.
std::vector<Vec3d> limit_positions(const ShellObject& s) {
  std::vector<Vec3> p, n;
  LimitMesh(s.basis(), s.triangles(), {}, 0).evaluate(s.x.data(), p, n);
  std::vector<Vec3d> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = p[i].cast<double>();
  return out;
}

/// Smallest distance of a's limit vertices to b's limit triangles.
double min_distance(const ShellObject& a, const ShellObject& b) {
  const std::vector<Vec3d> pa = limit_positions(a), pb = limit_positions(b);
  const LimitMesh lb(b.basis(), b.triangles(), {}, 0);
  double d = 1e300;
  for (const Vec3d& p : pa)
    for (const Eigen::Vector3i& t : lb.triangles()) {
      const Vec3d w = closest_point_barycentric(p, pb[t[0]], pb[t[1]], pb[t[2]]);
      d = std::min(d, (p - (w[0] * pb[t[0]] + w[1] * pb[t[1]] + w[2] * pb[t[2]])).norm());
    }
  return d;
}

/// Mean height of a shell's control points.
double mean_y(const ShellObject& s) {
  double y = 0;
  for (const Vec3& x : s.x) y += x.y();
  return y / static_cast<double>(s.size());
}

struct Totals {
  Vec3d momentum = Vec3d::Zero();
  double kinetic = 0;
};
/// One shell's momentum and kinetic energy.
Totals totals(const std::unique_ptr<ShellObject>& s) {
  Totals t;
  for (std::size_t j = 0; j < s->size(); ++j) {
    const Vec3d v = s->v[j].cast<double>();
    t.momentum += static_cast<double>(s->mass[j]) * v;
    t.kinetic += 0.5 * static_cast<double>(s->mass[j]) * v.squaredNorm();
  }
  return t;
}
Totals totals(const std::vector<std::unique_ptr<ShellObject>>& sh, const ParticleSet* ps,
              double density) {
  Totals t;
  for (const auto& s : sh) {
    const Totals ts = totals(s);
    t.momentum += ts.momentum;
    t.kinetic += ts.kinetic;
  }
  if (ps)
    for (std::size_t p = 0; p < ps->size(); ++p) {
      const double m = static_cast<double>(ps->volume_of(p)) * density;
      const Vec3d v = ps->v[p].cast<double>();
      t.momentum += m * v;
      t.kinetic += 0.5 * m * v.squaredNorm();
    }
  return t;
}

/// One stand-in G2P step: every control point gets the drive of its shell.
void drive(std::vector<std::unique_ptr<ShellObject>>& sh, const std::vector<Vec3>& speed) {
  for (std::size_t i = 0; i < sh.size(); ++i)
    for (std::size_t j = 0; j < sh[i]->size(); ++j) {
      sh[i]->v[j] = speed[i];
      sh[i]->x[j] += static_cast<Real>(kDt) * sh[i]->v[j];
    }
}

}  // namespace

TEST_CASE("shell guard: two sheets driven through each other stop at the gap", "[shell_guard]") {
  for (const bool guarded : {false, true}) {
    std::vector<std::unique_ptr<ShellObject>> sh;
    sh.push_back(sheet(0.2, 8, 0.0));
    sh.push_back(sheet(0.16, 6, 0.012, 600));  // heavier, smaller, offset mesh
    std::vector<GridShell> gs = grid_shells(sh);
    ShellGuard guard;
    guard.setup(gs, kGap);
    std::size_t impulses = 0;
    // 2.5 m/s up against 1 m/s down: 0.07 m of closing over 20 steps, 12 mm apart.
    for (int step = 0; step < 20; ++step) {
      drive(sh, {Vec3(0, 2.5f, 0), Vec3(0.3f, -1.0f, 0)});
      if (!guarded) continue;
      std::vector<Vec3> x0a(sh[0]->size()), x0b(sh[1]->size());
      for (std::size_t j = 0; j < sh[0]->size(); ++j)
        x0a[j] = sh[0]->x[j] - Real(kDt) * sh[0]->v[j];
      const Totals before = totals(sh, nullptr, 0);
      const ShellGuardStats st = guard.apply(gs, GuardBulk{}, kDt);
      const Totals after = totals(sh, nullptr, 0);
      impulses += st.impulses;
      CHECK(st.unresolved == 0);
      // Momentum is kept, kinetic energy never grows.
      CHECK((after.momentum - before.momentum).norm() < 1e-5 * before.momentum.norm() + 1e-9);
      CHECK(after.kinetic <= before.kinetic * (1 + 1e-6));
      // x^{n+1} = x^n + dt v still holds for the corrected points.
      for (std::size_t j = 0; j < sh[0]->size(); ++j)
        CHECK(((sh[0]->x[j] - Real(kDt) * sh[0]->v[j]) - x0a[j]).norm() < 1e-6);
    }
    const double d = min_distance(*sh[1], *sh[0]);
    if (guarded) {
      CHECK(impulses > 0);
      CHECK(d > 0.9 * kGap);
      CHECK(mean_y(*sh[1]) > mean_y(*sh[0]));  // still on top
    } else {
      CHECK(mean_y(*sh[1]) < mean_y(*sh[0]));  // without it they pass through each other
    }
  }
}

TEST_CASE("shell guard: a pinned sheet holds and keeps its prescribed motion", "[shell_guard]") {
  std::vector<std::unique_ptr<ShellObject>> sh;
  sh.push_back(sheet(0.2, 8, 0.0));
  sh.push_back(sheet(0.12, 5, 0.006));
  std::vector<GridShell> gs = grid_shells(sh);
  gs[0].held.assign(sh[0]->size(), 7);  // all of sheet 0 prescribed
  ShellGuard guard;
  guard.setup(gs, kGap);
  std::size_t impulses = 0;
  for (int step = 0; step < 15; ++step) {
    drive(sh, {Vec3(0, 0.1f, 0), Vec3(0, -2.0f, 0)});
    const Totals free0 = totals(sh[1]);
    const ShellGuardStats st = guard.apply(gs, GuardBulk{}, kDt);
    impulses += st.impulses;
    for (const Vec3& v : sh[0]->v) REQUIRE(v == Vec3(0, 0.1f, 0));
    // Every impulse the free sheet took came through the pinned one, so the pins' work is
    // that momentum times the pin's velocity, and it pays for the kinetic energy gained.
    const Totals free1 = totals(sh[1]);
    const double work = (free1.momentum - free0.momentum).dot(Vec3d(0, 0.1, 0));
    CHECK(st.pin_work == Approx(work).margin(1e-9));
    CHECK(free1.kinetic - free0.kinetic <= st.pin_work + 1e-9);
  }
  CHECK(impulses > 0);
  CHECK(min_distance(*sh[1], *sh[0]) > 0.9 * kGap);
  CHECK(mean_y(*sh[1]) > mean_y(*sh[0]));
}

TEST_CASE("shell guard: fast bulk particles stay on their side of a light sheet", "[shell_guard]") {
  std::vector<std::unique_ptr<ShellObject>> sh;
  sh.push_back(sheet(0.2, 8, 0.0, 100));
  std::vector<GridShell> gs = grid_shells(sh);
  const std::vector<Real> densities{2000};
  ParticleSet ps;
  for (int i = -3; i <= 3; ++i)
    for (int k = -3; k <= 3; ++k)
      ps.push_back(Vec3(0.013f * i, 0.008f, 0.011f * k), Vec3(0, -6, 0), Real(1e-6), 0, 1);
  ShellGuard guard;
  guard.setup(gs, kGap);
  GuardBulk bulk{&ps, &densities, 0};
  for (int step = 0; step < 12; ++step) {
    for (std::size_t p = 0; p < ps.size(); ++p) {
      ps.v[p] = Vec3(0, -6, 0);  // the drive (a heavy body behind them)
      ps.x[p] += Real(kDt) * ps.v[p];
    }
    drive(sh, {Vec3(0, 0, 0)});
    const Totals before = totals(sh, &ps, densities[0]);
    guard.apply(gs, bulk, kDt);
    const Totals after = totals(sh, &ps, densities[0]);
    CHECK((after.momentum - before.momentum).norm() < 1e-5 * before.momentum.norm());
    CHECK(after.kinetic <= before.kinetic * (1 + 1e-6));
  }
  // Every particle is above the (pushed-down) sheet by about the gap.
  const std::vector<Vec3d> pos = limit_positions(*sh[0]);
  const LimitMesh lm(sh[0]->basis(), sh[0]->triangles(), {}, 0);
  for (std::size_t p = 0; p < ps.size(); ++p) {
    const Vec3d x = ps.x[p].cast<double>();
    double best = 1e300, side = 0;
    for (const Eigen::Vector3i& t : lm.triangles()) {
      const Vec3d w = closest_point_barycentric(x, pos[t[0]], pos[t[1]], pos[t[2]]);
      const Vec3d q = w[0] * pos[t[0]] + w[1] * pos[t[1]] + w[2] * pos[t[2]];
      if ((x - q).norm() < best) {
        best = (x - q).norm();
        side = x.y() - q.y();
      }
    }
    CHECK(side > 0);
    CHECK(best > 0.9 * kGap);
  }
  CHECK(mean_y(*sh[0]) < -0.01);  // the sheet took the momentum
}

TEST_CASE("shell guard: the candidate lists never change a result", "[shell_guard]") {
  // One guard keeps its lists across steps; the other is set up afresh every step (so
  // it rebuilds them each time). Both must give the same bits.
  std::vector<std::unique_ptr<ShellObject>> a, b;
  for (auto* sh : {&a, &b}) {
    sh->push_back(sheet(0.2, 8, 0.0));
    sh->push_back(sheet(0.16, 6, 0.02, 600));
  }
  std::vector<GridShell> ga = grid_shells(a), gb = grid_shells(b);
  ShellGuard kept;
  kept.setup(ga, kGap);
  std::size_t impulses = 0;
  for (int step = 0; step < 30; ++step) {
    const Vec3 up(0, 1.5f, 0.05f * static_cast<float>(step % 3)), down(0.2f, -1.0f, 0);
    drive(a, {up, down});
    drive(b, {up, down});
    impulses += kept.apply(ga, GuardBulk{}, kDt).impulses;
    ShellGuard fresh;
    fresh.setup(gb, kGap);
    fresh.apply(gb, GuardBulk{}, kDt);
    for (std::size_t s = 0; s < 2; ++s)
      for (std::size_t j = 0; j < a[s]->size(); ++j) {
        REQUIRE(a[s]->x[j] == b[s]->x[j]);
        REQUIRE(a[s]->v[j] == b[s]->v[j]);
      }
  }
  CHECK(impulses > 0);
}

TEST_CASE("shell guard: a shell's neighbours at rest are never paired and its far parts are",
          "[shell_guard]") {
  // A sheet shrunk in its plane until features within Mesh::near of each other at rest
  // (the mean rest edge here) come closer than the gap: the guard pairs none of them (its
  // lists leave the pairs near at rest out). The same sheet folded so that one half lies
  // within the gap over the other: the guard pairs those.
  const double size = 0.1;
  const int res = 10;
  std::vector<std::unique_ptr<ShellObject>> sh;
  sh.push_back(sheet(size, res, 0.0));
  ShellObject& s = *sh[0];
  const std::vector<Vec3d> rest = limit_positions(s);
  const LimitMesh L(s.basis(), s.triangles(), {}, 0);
  double edge = 0;
  std::size_t edges = 0;
  for (const Eigen::Vector3i& t : L.triangles())
    for (int k = 0; k < 3; ++k, ++edges) edge += (rest[t[k]] - rest[t[(k + 1) % 3]]).norm();
  const double near = std::max(2 * kGap, edge / static_cast<double>(edges));
  // Shrunk by c: a pair d apart at rest is c d apart. Pairs near at rest (d < near) come
  // within the gap where d < gap / c; pairs not near stay beyond the gap (c near > gap).
  const double c = 1.05 * kGap / near;
  for (std::size_t j = 0; j < s.size(); ++j) {
    s.x[j] = (s.x[j].cast<double>() * c).cast<Real>();
    s.v[j].setZero();
  }
  // The control: some vertex and triangle not its own are within the gap, all of them
  // near at rest.
  const std::vector<Vec3d> now = limit_positions(s);
  std::size_t close = 0, close_far_at_rest = 0;
  for (std::size_t p = 0; p < now.size(); ++p)
    for (const Eigen::Vector3i& t : L.triangles()) {
      if (t[0] == int(p) || t[1] == int(p) || t[2] == int(p)) continue;
      const auto dist = [&](const std::vector<Vec3d>& x) {
        const Vec3d w = closest_point_barycentric(x[p], x[t[0]], x[t[1]], x[t[2]]);
        return (x[p] - (w[0] * x[t[0]] + w[1] * x[t[1]] + w[2] * x[t[2]])).norm();
      };
      if (dist(now) < kGap) {
        ++close;
        close_far_at_rest += dist(rest) >= near;
      }
    }
  REQUIRE(close > 0);
  REQUIRE(close_far_at_rest == 0);
  std::vector<GridShell> g = grid_shells(sh);
  ShellGuard guard;
  guard.setup(g, kGap);
  CHECK(guard.apply(g, GuardBulk{}, kDt).pairs == 0);

  // Folded: the half x > 0 turned over onto the half x < 0, kGap / 2 above it and coming
  // down at 1 m/s.
  std::vector<std::unique_ptr<ShellObject>> fold;
  fold.push_back(sheet(size, res, 0.0));
  ShellObject& f = *fold[0];
  for (std::size_t j = 0; j < f.size(); ++j) {
    if (f.x[j].x() > Real(1e-6)) {
      f.x[j] = Vec3(-f.x[j].x(), Real(0.5 * kGap), f.x[j].z());
      f.v[j] = Vec3(0, -1, 0);
    } else {
      f.v[j].setZero();
    }
  }
  // x^n = x - dt v for the guard: put x where the step took it.
  for (std::size_t j = 0; j < f.size(); ++j) f.x[j] += static_cast<Real>(kDt) * f.v[j];
  std::vector<GridShell> gf = grid_shells(fold);
  ShellGuard fold_guard;
  fold_guard.setup(gf, kGap);
  const ShellGuardStats st = fold_guard.apply(gf, GuardBulk{}, kDt);
  CHECK(st.pairs > 0);
  CHECK(st.impulses > 0);
}

TEST_CASE("segment closest points", "[shell_guard]") {
  // Crossing at right angles, 1 apart.
  Eigen::Vector2d st =
      closest_segment_params(Vec3d(-1, 0, 0), Vec3d(1, 0, 0), Vec3d(0.5, -1, 1), Vec3d(0.5, 1, 1));
  CHECK(st[0] == Approx(0.75));
  CHECK(st[1] == Approx(0.5));
  // Beyond an end: clamped.
  st = closest_segment_params(Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(2, 1, 0), Vec3d(3, 1, 0));
  CHECK(st[0] == Approx(1.0));
  CHECK(st[1] == Approx(0.0));
  // Parallel and a point.
  st = closest_segment_params(Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0.2, 1, 0), Vec3d(0.6, 1, 0));
  const Vec3d p = Vec3d(st[0], 0, 0), q = Vec3d(0.2 + 0.4 * st[1], 1, 0);
  CHECK((p - q).norm() == Approx(1.0));
  st = closest_segment_params(Vec3d(0, 0, 0), Vec3d(0, 0, 0), Vec3d(-1, 2, 0), Vec3d(1, 2, 0));
  CHECK(st[1] == Approx(0.5));
}
