// The grid update (sim/solver/stages/grid_update.cpp): node momentum to velocity, plus
// gravity, for every node with mass, however small that mass is.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <limits>

#include "sim/mpm/apic_stencil.h"
#include "sim/solver/solver.h"
#include "sim/solver/stages/grid_update.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

// Mass-weighted centroid of a shell's control points.
Vec3d centroid(const ShellObject& sh) {
  Vec3d c = Vec3d::Zero();
  double m = 0;
  for (std::size_t j = 0; j < sh.size(); ++j) {
    c += double(sh.mass[j]) * sh.x[j].cast<double>();
    m += sh.mass[j];
  }
  return c / m;
}

// The sheet of the drape divergence: 0.3 m square, 15 x 15 quads (spacing 0.02 = dx) at
// y = 0.15, self-contact on, in a box whose lower corner is at (lo, lo, lo) and upper
// corner at 0.3: with lo a multiple of dx, every control point sits on a cell-centre plane
// of all three axes.
Scene falling_sheet(double lo) {
  Scene s = test::contact_test_scene(0.02);
  s.shot.fps = 24;
  s.shot.domain_min = Vec3d(lo, lo, lo);
  s.shot.domain_max = Vec3d(0.3, 0.3, 0.3);
  ShellMaterialDesc m = test::cloth_material();
  m.youngs_modulus = 5e5;
  s.shell_materials.push_back(m);
  ShellDesc d;
  d.name = "cloth";
  d.kind = ShellDesc::Kind::Sheet;
  d.size = {0.3, 0.3};
  d.resolution = {15, 15};
  d.translate = Vec3d(0, 0.15, 0);
  d.contact = ShellDesc::Contact::On;
  s.shells.push_back(d);
  return s;
}

}  // namespace

TEST_CASE("the grid update gives a node of subnormal mass a finite velocity",
          "[grid_update][solver]") {
  // One point one ulp below the half-cell position 7.5 on every axis: its stencil starts at
  // node 6, whose weight per axis is (1.5 - fx)^2 / 2 with 1.5 - fx one ulp of 7.5, so
  // the corner node (6, 6, 6) gets the product of three such tips. The point's mass is
  // chosen so that this corner mass is a quarter of the smallest normal number (in float
  // builds the mass is a couple of kg; in double builds tiny, the same situation): its
  // reciprocal overflows, p / m does not.
  StepContext c;
  c.dt = 1e-3;
  c.domain_cells = Vec3i(16, 16, 16);
  c.grid.setup(1.0, Vec3d::Zero());
  const Real below = std::nextafter(Real(7.5), Real(0));
  const Vec3 x(below, below, below);
  const QuadraticWeights W(c.grid.grid_coord(x));
  REQUIRE(W.base[0] == 6);
  const double tip = double(W.w[0][0]) * double(W.w[1][0]) * double(W.w[2][0]);
  REQUIRE(tip > 0);
  const Real m = static_cast<Real>(0.25 * double(std::numeric_limits<Real>::min()) / tip);
  const Vec3 v0(Real(0.3), Real(-0.2), Real(0.1));
  c.grid.bin(std::vector<Vec3>{x}, true);
  REQUIRE(c.grid.num_particle_blocks() == 1);
  std::array<GridNode, kPadNodes> pad;
  for (GridNode& nd : pad) nd = GridNode{0, {0, 0, 0}};
  const Vec3i bc = unpack_block(c.grid.pblock_key[0]) * kBlockSize;
  apic_scatter<false>(pad.data(), W, bc, m, m * v0, Mat3::Zero(), Mat3::Zero());
  c.grid.add_pad_to_grid(0, pad.data());
  int subnormal = 0;
  for (std::size_t b = 0; b < c.grid.num_grid_blocks(); ++b)
    c.grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i&) {
      if (!std::isnormal(nd.m)) ++subnormal;
    });
  REQUIRE(subnormal > 0);  // the premise: the stencil's corner node has a subnormal mass

  c.opt.serial = true;
  GridUpdateStage().run(c);
  const Vec3 expect = v0 + Real(c.dt) * c.scene.shot.gravity.cast<Real>();
  int nodes = 0;
  for (std::size_t b = 0; b < c.grid.num_grid_blocks(); ++b)
    c.grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
      ++nodes;
      const Vec3 v(nd.v[0], nd.v[1], nd.v[2]);
      INFO("node " << n.transpose() << " mass " << nd.m << " v " << v.transpose());
      REQUIRE(v.allFinite());
      // Every node of one point moving uniformly has the point's velocity; a subnormal mass
      // and momentum keep fewer digits (here about 20 bits in float), hence 1e-4 relative.
      REQUIRE((v - expect).norm() <= 1e-4 * expect.norm());
    });
  REQUIRE(nodes == 27);
}

TEST_CASE("a self-contact sheet on cell-centre planes falls freely at any domain offset",
          "[grid_update][solver][contact]") {
  // The drape divergence: with the box's lower corner at -0.30 or -0.28 the sheet's
  // corners sit within one float ulp below a half-cell position on x and z, the fall moves
  // them below it on y, and the node at the far tip of their stencils on all three axes
  // got a subnormal mass, an infinite velocity and stopped the run in its second step.
  // Offsets -0.32 and -0.34 put them exactly on the half-cell (zero tip weight), -0.31
  // off it.
  for (const double lo : {-0.30, -0.28, -0.32, -0.34, -0.31}) {
    INFO("domain min " << lo);
    Solver solver(falling_sheet(lo));
    REQUIRE(solver.shell_on_grid(0));
    const ShellObject& sh = *solver.shells()[0];
    const Vec3d c0 = centroid(sh);
    const double g = 9.81;
    double dt_max = 0;
    for (int k = 1; k <= 10; ++k) {
      const FrameStats fs = solver.advance_to(0.01 * k);
      dt_max = std::max(dt_max, fs.dt_max);
      const double t = solver.time();
      for (std::size_t j = 0; j < sh.size(); ++j) {
        REQUIRE(sh.x[j].allFinite());
        REQUIRE(sh.v[j].allFinite());
      }
      const Vec3d c = centroid(sh);
      // Free fall with nothing touched: symplectic Euler (v += dt g, then x += dt v) puts
      // the centroid g t dt / 2 below y0 - g t^2 / 2 at most (dt varies: bounded by the
      // largest step), and float round-off of positions near 0.15 m (ulp ~1e-8 m) over a
      // few hundred steps adds well under 1e-5 m.
      const double tol = 0.5 * g * t * dt_max + 1e-5;
      INFO("t " << t << " centroid " << c.transpose() << " dt_max " << dt_max);
      REQUIRE(std::abs(c[1] - (c0[1] - 0.5 * g * t * t)) < tol);
      REQUIRE(std::abs(c[0] - c0[0]) < 1e-5);
      REQUIRE(std::abs(c[2] - c0[2]) < 1e-5);
      // Uniform motion: the sheet stays flat (no control point leaves the centroid's plane
      // by more than round-off).
      for (std::size_t j = 0; j < sh.size(); ++j)
        REQUIRE(std::abs(double(sh.x[j][1]) - c[1]) < 1e-5);
    }
  }
}
