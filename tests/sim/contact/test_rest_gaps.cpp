// Contact at the bodies' real distance (shot.contact_at: surface): sheets stack at their
// thickness, cloth lies on the ground and on a sphere, jelly and sand rest on cloth, and a
// user's contact_thickness is the distance kept; `stencil` shows the paper's cushion of one
// to two cells, which the surface contact removes. Gaps are in cells (dx).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sim/integrity/integrity_report.h"
#include "sim/solver/solver.h"
#include "tests/support/bulk_fixtures.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

ShellMaterialDesc felt() {
  ShellMaterialDesc m = test::cloth_material();
  m.name = "felt";
  m.youngs_modulus = 5e5;
  m.thickness = 2e-3;
  m.friction = 0.4;
  m.damping = 0.5;
  return m;
}

ShellDesc sheet(const std::string& name, double size, int res, const Vec3d& at) {
  return test::square_sheet(name, size, res, at);
}

Scene base_scene(double dx) {
  Scene s = test::contact_test_scene(dx);
  s.shot.fps = 24;
  s.shot.domain_min = Vec3d(-0.4, -0.15, -0.4);
  s.shot.domain_max = Vec3d(0.4, 0.45, 0.4);
  s.shot.contact_at = ContactAt::Surface;
  return s;
}

void add_ground(Scene& s) {
  ColliderDesc g;
  g.name = "ground";
  g.shape.kind = ShapeDesc::Kind::Plane;
  g.shape.point = Vec3d(0, 0, 0);
  g.shape.normal = Vec3d(0, 1, 0);
  g.friction = 0.5;
  s.colliders.push_back(g);
}

/// Median height of a shell's limit vertices within r of the vertical axis.
double centre_height(const ShellObject& sh, double r = 0.06) {
  std::vector<Vec3> pos, n;
  sh.output_mesh(pos, n);
  std::vector<double> y;
  for (const Vec3& p : pos)
    if (std::hypot(double(p.x()), double(p.z())) < r) y.push_back(p.y());
  REQUIRE(!y.empty());
  std::nth_element(y.begin(), y.begin() + std::ptrdiff_t(y.size() / 2), y.end());
  return y[y.size() / 2];
}

/// Three felt sheets dropped on the ground (the ground at y = 0), settled for `frames`
/// frames: the gaps between neighbours' and the ground's contact surfaces [cells] and the
/// last frame's statistics. contact: the sheets' contact thickness (none: their thickness).
struct StackResult {
  std::vector<double> gaps;  ///< ground-bottom, then each sheet on the one below
  FrameStats last;
};
StackResult settle_stack(double dx, ContactAt at, std::optional<double> contact, int frames) {
  Scene s = base_scene(dx);
  s.shot.contact_at = at;
  add_ground(s);
  s.shell_materials.push_back(felt());
  s.shell_materials[0].contact_thickness = contact;
  const int res = static_cast<int>(std::lround(0.3 / dx));  // mesh spacing dx
  for (int k = 0; k < 3; ++k)
    s.shells.push_back(sheet("s" + std::to_string(k), 0.3, res, Vec3d(0, 0.05 + 0.07 * k, 0)));
  Solver solver(s);
  StackResult out;
  for (int f = 2; f <= frames; ++f) out.last = solver.advance_to((f - 1) / s.shot.fps);
  const double c = contact.value_or(s.shell_materials[0].thickness);
  double below = 0;  // the ground's surface
  for (int k = 0; k < 3; ++k) {
    const double y = centre_height(*solver.shells()[std::size_t(k)]);
    // The ground against the bottom sheet's lower contact surface; each sheet's lower
    // surface against the upper one of the sheet below.
    out.gaps.push_back((y - 0.5 * c - below) / dx);
    below = y + 0.5 * c;
  }
  return out;
}

}  // namespace

TEST_CASE("sheets stacked on the ground rest at their thickness, not cells apart",
          "[contact][rest_gap]") {
  const StackResult r = settle_stack(0.025, ContactAt::Surface, std::nullopt, 20);
  INFO("gaps (ground, sheet 1-2, sheet 2-3) in dx: " << r.gaps[0] << ", " << r.gaps[1] << ", "
                                                     << r.gaps[2]);
  for (double g : r.gaps) {
    CHECK(g <= 0.1);
    CHECK(g >= -0.1);  // and no sheet pressed into the one below
  }
  // Nothing crossed, and the integrity monitor reports the gaps it sees: its median over
  // the sheets' vertices against their neighbours is the same rest distance.
  CHECK_FALSE(r.last.integrity.failed());
  REQUIRE(r.last.integrity.shell_shell.count > 0);
  CHECK(std::abs(r.last.integrity.shell_shell.median) <= 0.1 * 0.025);
  CHECK(std::abs(r.last.integrity.shell_collider.median) <= 0.1 * 0.025);
}

TEST_CASE("with contact at the stencils the same stack keeps the paper's cushion",
          "[contact][rest_gap]") {
  // The behaviour before contact at the surfaces, still selectable: each sheet rests one
  // to two cells above the one below (what a render of such a pile showed).
  const StackResult r = settle_stack(0.025, ContactAt::Stencil, std::nullopt, 20);
  INFO("gaps in dx: " << r.gaps[0] << ", " << r.gaps[1] << ", " << r.gaps[2]);
  CHECK(r.gaps[1] > 1.0);
  CHECK(r.gaps[2] > 1.0);
}

// A contact layer of half a cell or a cell: the sheets' stencils no longer coincide, the
// upper sheet reads nodes the lower one does not reach, which the pair rule does not hold,
// and the shell guard (with friction, 0.05 dx under the layer) holds the last part. With
// the guard at half the layer they sank 0.13 and 0.39 dx below it.
namespace {

void check_contact_thickness(double dx) {
  for (double cells : {0.5, 1.0}) {
    const StackResult r = settle_stack(dx, ContactAt::Surface, cells * dx, 20);
    INFO("dx " << dx << ", contact thickness " << cells << " dx: gaps " << r.gaps[0] << ", "
               << r.gaps[1] << ", " << r.gaps[2]);
    for (double g : r.gaps) CHECK(std::abs(g) <= 0.1);
    CHECK_FALSE(r.last.integrity.failed());
  }
}

}  // namespace

TEST_CASE("a user's contact thickness is the distance the stack keeps", "[contact][rest_gap]") {
  check_contact_thickness(0.025);
}

TEST_CASE("at half the cell size a user's contact thickness is the distance the stack keeps",
          "[contact][rest_gap][slow]") {
  check_contact_thickness(0.0125);
}

namespace {

/// A felt cloth (mesh spacing dx) dropped on a 10 cm sphere collider, settled for 0.8 s:
/// the gap [cells] between its lower contact surface and the sphere, the median over its
/// limit vertices within 4 cm of the axis of their distance from the centre (their height
/// alone reads the cap's curvature as a gap: 8 mm lower at 4 cm from the pole).
double cloth_on_sphere(double dx) {
  const double R = 0.1;
  Scene s = base_scene(dx);
  ColliderDesc ball;
  ball.name = "ball";
  ball.shape.kind = ShapeDesc::Kind::Sphere;
  ball.shape.center = Vec3d(0, 0, 0);
  ball.shape.radius = R;
  ball.friction = 0.5;
  s.colliders.push_back(ball);
  s.shell_materials.push_back(felt());
  s.shells.push_back(
      sheet("cloth", 0.4, static_cast<int>(std::lround(0.4 / dx)), Vec3d(0, R + 0.03, 0)));
  Solver solver(s);
  FrameStats fs;
  for (int f = 2; f <= 20; ++f) fs = solver.advance_to((f - 1) / s.shot.fps);
  CHECK_FALSE(fs.integrity.failed());
  std::vector<Vec3> pos, nrm;
  solver.shells()[0]->output_mesh(pos, nrm);
  std::vector<double> r;
  for (const Vec3& p : pos)
    if (std::hypot(double(p.x()), double(p.z())) < 0.04) r.push_back(p.cast<double>().norm());
  REQUIRE(r.size() > 8);
  std::nth_element(r.begin(), r.begin() + std::ptrdiff_t(r.size() / 2), r.end());
  const double gap = (r[r.size() / 2] - 0.5 * felt().thickness - R) / dx;
  UNSCOPED_INFO("dx " << dx << ": cloth over the cap at " << r[r.size() / 2]
                      << " m from the centre: gap " << gap
                      << " dx; the monitor's median shell-collider "
                      << "gap " << fs.integrity.shell_collider.median / dx << " dx");
  return gap;
}

}  // namespace

TEST_CASE("a cloth dropped on a sphere rests on it at half its thickness", "[contact][rest_gap]") {
  CHECK(std::abs(cloth_on_sphere(0.025)) <= 0.1);
}

TEST_CASE("at half the cell size a cloth rests on a sphere at half its thickness",
          "[contact][rest_gap][slow]") {
  CHECK(std::abs(cloth_on_sphere(0.0125)) <= 0.1);
}

namespace {
/// The gap [cells] between a cloth's upper contact surface (1 mm thick) and the lowest
/// particles of the bulk material over its centre, less half their spacing.
double block_gap(const Solver& solver, double dx) {
  const double cloth_top = centre_height(*solver.shells()[0], 0.05) + 0.5e-3;
  // The lowest layer of particles over the centre: the lowest 5% of those within 5 cm.
  std::vector<double> y;
  for (const Vec3& p : solver.particles().x)
    if (std::hypot(double(p.x()), double(p.z())) < 0.05) y.push_back(p.y());
  REQUIRE(y.size() > 40);
  std::sort(y.begin(), y.end());
  double low = 0;
  const std::size_t n = y.size() / 20;
  for (std::size_t i = 0; i < n; ++i) low += y[i] / double(n);
  const double gap = (low - 0.25 * dx - cloth_top) / dx;
  UNSCOPED_INFO("  cloth top " << cloth_top << ", lowest particles " << low << ", gap " << gap
                               << " dx");
  return gap;
}

/// A block of bulk material (15 cm, 8 particles per cell) dropped onto a 1 mm cloth lying
/// on the ground; returns the gap [cells] between the cloth's upper contact surface and
/// the block's lower surface (its lowest particles less half their spacing), at the
/// centre: the median over frames frames - 7 .. frames, since an elastic block with no
/// damping keeps bouncing on the cloth (a cycle of about four frames at 24 fps), and a
/// single frame may catch it in the air. The cloth's mesh spacing is dx.
double bulk_on_cloth(const MaterialDesc& mat, int frames, double dx = 0.025) {
  Scene s = base_scene(dx);
  add_ground(s);
  s.shell_materials.push_back(test::cloth_material());
  s.shell_materials[0].damping = 0.5;
  s.shell_materials[0].friction = 0.4;
  s.shells.push_back(
      sheet("cloth", 0.4, static_cast<int>(std::lround(0.4 / dx)), Vec3d(0, 0.01, 0)));
  s.materials.push_back(mat);
  SourceDesc src;
  src.name = "block";
  src.material = 0;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d(-0.075, 0.05, -0.075);
  src.shape.max = Vec3d(0.075, 0.2, 0.075);
  s.sources.push_back(src);
  Solver solver(s);
  std::vector<double> gaps;
  for (int f = 2; f <= frames; ++f) {
    const FrameStats fs = solver.advance_to((f - 1) / s.shot.fps);
    std::string events;
    for (const std::string& line : describe_integrity(fs.integrity, f, dx)) events += line + "\n";
    INFO(events);
    CHECK_FALSE(fs.integrity.failed());
    if (f > frames - 8) gaps.push_back(block_gap(solver, dx));
  }
  std::nth_element(gaps.begin(), gaps.begin() + std::ptrdiff_t(gaps.size() / 2), gaps.end());
  const double gap = gaps[gaps.size() / 2];
  UNSCOPED_INFO(mat.name << " at dx " << dx << ": median gap over the last 8 frames " << gap
                         << " dx");
  return gap;
}

MaterialDesc jelly() {
  MaterialDesc m;
  m.name = "jelly";
  m.youngs_modulus = 2e4;
  m.density = 1000;
  return m;
}
}  // namespace

TEST_CASE("a jelly block rests on a cloth on the ground within a quarter cell",
          "[contact][rest_gap]") {
  CHECK(std::abs(bulk_on_cloth(jelly(), 16)) <= 0.25);
}

TEST_CASE("sand rests on a cloth on the ground within a quarter cell", "[contact][rest_gap]") {
  CHECK(std::abs(bulk_on_cloth(test::sand_material(3e5, 30), 16)) <= 0.25);
}

TEST_CASE("at half the cell size jelly and sand rest on a cloth within a quarter cell",
          "[contact][rest_gap][slow]") {
  CHECK(std::abs(bulk_on_cloth(jelly(), 16, 0.0125)) <= 0.25);
  CHECK(std::abs(bulk_on_cloth(test::sand_material(3e5, 30), 16, 0.0125)) <= 0.25);
}

TEST_CASE("at half the cell size the stack still rests at its thickness",
          "[contact][rest_gap][slow]") {
  const StackResult r = settle_stack(0.0125, ContactAt::Surface, std::nullopt, 20);
  INFO("gaps in dx/2 cells: " << r.gaps[0] << ", " << r.gaps[1] << ", " << r.gaps[2]);
  for (double g : r.gaps) CHECK(std::abs(g) <= 0.1);
}
