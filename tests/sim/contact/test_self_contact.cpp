// Self-contact of one shell: two layers of the same cloth on either side of a grid node
// get two velocity fields (sim/contact/shell_folds.cpp), so a fold slides over the rest of
// its cloth at Coulomb's law with the shell's c_F instead of sharing its velocity.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/shell/procedural_mesh.h"
#include "sim/solver/solver.h"
#include "tests/support/least_squares.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

constexpr int kBaseCells = 40;  // the cloth's pinned part: 0.8 m, 40 x 40 quads
constexpr int kBasePoints = (kBaseCells + 1) * (kBaseCells + 1);

// One shell of two parts on a slope of th_deg: a pinned 0.8 m cloth and a free 0.16 m
// piece of it gap0 above, wound the same way (a stacked layer, as in a rolled sheet) or
// the other way (a layer folded over, its normal facing the cloth).
// How far above the cloth the free piece starts [m]: low enough that it lands and settles
// before the fit starts at 0.1 s, above where contact holds it (some two cells with contact
// at the stencils, a thickness at the surfaces).
double drop_gap(ContactAt at) {
  return at == ContactAt::Surface ? 0.03 : 0.07;
}

Scene fold_on_slope(double th_deg, double mu, bool folded, bool fold_fields = true,
                    double gap0 = -1, ContactAt at = ShotSettings{}.contact_at) {
  Scene s = test::contact_test_scene(0.02);
  s.shot.fold_fields = fold_fields;
  s.shot.contact_at = at;
  if (gap0 < 0) gap0 = drop_gap(at);
  ShellMaterialDesc m = test::cloth_material();
  m.friction = mu;
  s.shell_materials.push_back(m);
  ShellMesh mesh = make_sheet(0.8, 0.8, kBaseCells, kBaseCells);
  const ShellMesh top = make_sheet(0.16, 0.16, 8, 8);
  const int off = static_cast<int>(mesh.vertices.size());
  for (std::size_t k = 0; k < top.vertices.size(); ++k) {
    mesh.vertices.push_back(top.vertices[k] + Vec3d(-0.2, gap0, 0));
    mesh.uvs.push_back(top.uvs[k]);
  }
  for (Eigen::Vector3i t : top.triangles) {
    if (folded) std::swap(t[1], t[2]);
    mesh.triangles.push_back(t + Eigen::Vector3i::Constant(off));
    mesh.uv_triangles.push_back(t + Eigen::Vector3i::Constant(off));  // one UV per vertex
  }
  ShellDesc d;
  d.name = "cloth";
  d.kind = ShellDesc::Kind::Mesh;
  d.mesh = std::make_shared<ShellMesh>(std::move(mesh));
  d.rotate_deg = Vec3d(0, 0, -th_deg);
  d.contact = ShellDesc::Contact::On;
  PinDesc base;
  for (int i = 0; i < kBasePoints; ++i) base.indices.push_back(i);
  d.pins.push_back(base);
  s.shells.push_back(d);
  return s;
}

struct Slide {
  double a;          ///< fitted acceleration of the free part down the slope [m/s^2]
  double travelled;  ///< from t = 0.1 s to 0.4 s [m]
  double a_ref;      ///< Coulomb: g (sin - c_F cos) (negative: it should stick)
};

Slide run_fold(double th_deg, double mu, bool folded, bool fold_fields = true,
               ContactAt at = ShotSettings{}.contact_at) {
  const Scene s = fold_on_slope(th_deg, mu, folded, fold_fields, -1, at);
  Solver solver(s);
  REQUIRE(solver.shell_on_grid(0));
  const double th = th_deg * M_PI / 180;
  const Vec3d t(std::cos(th), -std::sin(th), 0);
  std::vector<double> times, d;
  for (int k = 0; k <= 30; ++k) times.push_back(0.1 + 0.01 * k);
  for (double tt : times) {
    solver.advance_to(tt);
    const ShellObject& sh = *solver.shells()[0];
    Vec3d c = Vec3d::Zero();
    double m = 0;
    for (std::size_t j = kBasePoints; j < sh.size(); ++j) {
      c += sh.mass[j] * sh.x[j].cast<double>();
      m += sh.mass[j];
    }
    d.push_back((c / m).dot(t));
  }
  return {test::fit_acceleration(times, d), d.back() - d.front(),
          9.81 * (std::sin(th) - mu * std::cos(th))};
}

}  // namespace

TEST_CASE("a fold slides over its own pinned cloth at g (sin - c_F cos), stacked or folded over",
          "[contact]") {
  // With one velocity per node for the whole shell (shot.fold_fields off) it drags.
  const Slide one = run_fold(30, 0.3, true, false);
  INFO("one velocity: acceleration " << one.a << " m/s^2, Coulomb " << one.a_ref);
  CHECK(one.a < 0.5 * one.a_ref);
  for (bool folded : {false, true}) {
    const Slide r = run_fold(30, 0.3, folded);
    INFO((folded ? "folded over" : "stacked") << ": acceleration " << r.a << " m/s^2, Coulomb "
                                              << r.a_ref << ", travelled " << r.travelled << " m");
    CHECK(r.a == Approx(r.a_ref).epsilon(0.05));
  }
}

TEST_CASE("a fold of one cloth sticks below the friction angle and slides freely without friction",
          "[contact][slow]") {
  const Slide stick = run_fold(10, 0.3, true);
  INFO("10 deg, c_F 0.3: acceleration " << stick.a << ", travelled " << stick.travelled << " m");
  CHECK(std::abs(stick.travelled) < 0.01);
  const double g_sin = 9.81 * std::sin(30 * M_PI / 180);
  const Slide free = run_fold(30, 0.0, true);
  INFO("30 deg, c_F 0: acceleration " << free.a << " m/s^2, g sin " << g_sin);
  CHECK(free.a == Approx(g_sin).epsilon(0.05));
}

TEST_CASE("a fold slides over its own cloth at Coulomb's law with contact at either place",
          "[contact][slow]") {
  // The default suite's fold test runs with the default contact mode; this one with both.
  for (ContactAt at : {ContactAt::Surface, ContactAt::Stencil})
    for (bool folded : {false, true}) {
      const Slide r = run_fold(30, 0.3, folded, true, at);
      INFO((at == ContactAt::Surface ? "surfaces, " : "stencils, ")
           << (folded ? "folded over" : "stacked") << ": acceleration " << r.a << " m/s^2, Coulomb "
           << r.a_ref << ", travelled " << r.travelled << " m");
      CHECK(r.a == Approx(r.a_ref).epsilon(0.05));
    }
}

TEST_CASE("one folding shell alone (mass and heights only off its folds) moves as with full fields",
          "[contact]") {
  // Alone, the cloth's field sums only mass and heights outside its fold blocks
  // (ShellFields::heights_only_); with a second shell far away every node gets the full
  // sums. Nothing can differ: away from the folds a node holds one body either way.
  const Scene alone = fold_on_slope(30, 0.3, true, true, 0.03);  // layers 1.5 dx apart: folds
  Scene two = alone;
  ShellDesc far;
  far.name = "far";
  far.kind = ShellDesc::Kind::Sheet;
  far.size[0] = far.size[1] = 0.16;
  far.resolution[0] = far.resolution[1] = 8;
  far.translate = Vec3d(0.7, 0.7, 0.7);
  far.contact = ShellDesc::Contact::On;
  PinDesc all;
  for (int i = 0; i < 81; ++i) all.indices.push_back(i);
  far.pins.push_back(all);
  two.shells.push_back(far);
  Solver a(alone), b(two);
  REQUIRE(a.shell_on_grid(0));
  REQUIRE(b.shell_on_grid(1));
  REQUIRE(a.stable_dt() == b.stable_dt());
  a.advance_to(0.05);
  b.advance_to(0.05);
  const ShellObject &sa = *a.shells()[0], &sb = *b.shells()[0];
  REQUIRE(sa.size() == sb.size());
  // The fold piece has moved down the slope, on the cloth (not through it).
  double moved = 0;
  for (std::size_t j = kBasePoints; j < sa.size(); ++j)
    moved = std::max(moved, double((sa.x[j] - sa.rest[j].cast<Real>()).norm()));
  CHECK(moved > 2e-3);
  std::size_t differ = 0;
  for (std::size_t j = 0; j < sa.size(); ++j)
    if (sa.x[j] != sb.x[j] || sa.v[j] != sb.v[j]) ++differ;
  CHECK(differ == 0);
}
