// Shells as whole objects: procedural meshes, rigid motion, denting below and beyond
// yield, odd valences, pre-roll and output meshes, a pull to 3x the length.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/shell/mesh_check.h"
#include "sim/shell/procedural_mesh.h"
#include "sim/solver/solver.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

double signed_volume(const ShellMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  return v;
}

Scene shell_scene(const ShellMaterialDesc& mat, const ShellDesc& sh) {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.05;
  s.shot.cfl = 0.5;
  s.shot.dt_max = 1e-2;
  s.shot.domain_min = Vec3d(-5, -5, -5);
  s.shot.domain_max = Vec3d(5, 5, 5);
  s.shell_materials.push_back(mat);
  s.shells.push_back(sh);
  return s;
}

ShellMaterialDesc cloth() {
  ShellMaterialDesc m = test::cloth_material();
  return m;
}

/// A disc whose centre vertex has the given valence, with two rings around it.
ShellMesh valence_disc(int k) {
  ShellMesh m;
  m.vertices.emplace_back(0, 0, 0);
  for (int i = 0; i < k; ++i) {
    const double a = 2 * M_PI * i / k;
    m.vertices.emplace_back(0.1 * std::cos(a), 0, -0.1 * std::sin(a));
  }
  for (int i = 0; i < 2 * k; ++i) {
    const double a = 2 * M_PI * i / (2 * k);
    m.vertices.emplace_back(0.2 * std::cos(a), 0, -0.2 * std::sin(a));
  }
  auto r1 = [&](int i) { return 1 + (i % k); };
  auto r2 = [&](int i) { return 1 + k + (i % (2 * k)); };
  for (int i = 0; i < k; ++i) {
    m.triangles.emplace_back(0, r1(i), r1(i + 1));
    m.triangles.emplace_back(r1(i), r2(2 * i), r2(2 * i + 1));
    m.triangles.emplace_back(r1(i), r2(2 * i + 1), r1(i + 1));
    m.triangles.emplace_back(r1(i + 1), r2(2 * i + 1), r2(2 * i + 2));
  }
  return m;
}

}  // namespace

TEST_CASE("procedural shell meshes: counts, orientation, no mesh problems", "[shell]") {
  const ShellMesh sheet = make_sheet(1, 2, 4, 6);
  REQUIRE(sheet.vertices.size() == 35);
  REQUIRE(sheet.triangles.size() == 48);
  for (const auto& t : sheet.triangles)
    REQUIRE((sheet.vertices[t[1]] - sheet.vertices[t[0]])
                .cross(sheet.vertices[t[2]] - sheet.vertices[t[0]])
                .y() > 0);
  const ShellMesh sphere = make_sphere(0.5, 2);
  REQUIRE(sphere.vertices.size() == 162);
  REQUIRE(signed_volume(sphere) == Approx(4.0 / 3.0 * M_PI * 0.125).epsilon(0.05));
  const ShellMesh tube = make_cylinder(0.3, 1.0, 360, 16, 8);
  REQUIRE(tube.vertices.size() == 16 * 9);
  const ShellMesh patch = make_cylinder(0.3, 1.0, 90, 8, 4);
  REQUIRE(patch.vertices.size() == 9 * 5);
  for (const ShellMesh* m : {&sheet, &sphere, &tube, &patch})
    REQUIRE(check_shell_mesh(m->vertices, m->triangles).empty());
  // Outward normals on the tube: each face normal points away from the axis.
  for (const auto& t : tube.triangles) {
    const Vec3d n = (tube.vertices[t[1]] - tube.vertices[t[0]])
                        .cross(tube.vertices[t[2]] - tube.vertices[t[0]]);
    Vec3d c = (tube.vertices[t[0]] + tube.vertices[t[1]] + tube.vertices[t[2]]) / 3;
    c.y() = 0;
    REQUIRE(n.dot(c) > 0);
  }
}

TEST_CASE("a free shell falls with g and stays unstressed, and so does a curved one", "[shell]") {
  for (int kind = 0; kind < 2; ++kind) {
    ShellDesc sh;
    sh.name = "s";
    if (kind == 0) {
      sh.kind = ShellDesc::Kind::Sheet;
      sh.resolution[0] = sh.resolution[1] = 8;
    } else {
      sh.kind = ShellDesc::Kind::Sphere;
      sh.radius = 0.3;
      sh.subdivisions = 2;
    }
    sh.velocity = Vec3d(0.3, 1, 0);
    Scene s = shell_scene(cloth(), sh);
    Solver solver(s);
    REQUIRE(solver.stage_names() == std::vector<std::string>{"shell_forces", "shell_update"});
    const ShellObject& o = *solver.shells()[0];
    double m = 0;
    Vec3d c0 = Vec3d::Zero();
    for (std::size_t i = 0; i < o.size(); ++i) {
      m += o.mass[i];
      c0 += o.mass[i] * o.x[i].cast<double>();
    }
    c0 /= m;
    // Lumped masses add up to density * area * thickness.
    const double area = kind == 0 ? 1.0 : 4 * M_PI * 0.09;
    // Lumped masses add up to rho t times the limit surface's area, which is a little
    // smaller than the control mesh's (a Loop surface lies inside its control net).
    REQUIRE(m == Approx(300 * o.kl().rest_area() * 1e-3).epsilon(1e-5));
    REQUIRE(o.kl().rest_area() == Approx(area).epsilon(kind == 0 ? 0.01 : 0.06));
    FrameStats fs;
    for (int f = 1; f <= 6; ++f) fs = solver.advance_to(f / 24.0);
    Vec3d c = Vec3d::Zero();
    for (std::size_t i = 0; i < o.size(); ++i) c += o.mass[i] * o.x[i].cast<double>();
    c /= m;
    const double t = solver.time();
    const Vec3d expect = c0 + sh.velocity * t + 0.5 * s.shot.gravity * t * t;
    REQUIRE((c - expect).norm() < 0.5 * 9.81 * t * fs.dt_max + 1e-5);
    REQUIRE(fs.shell_membrane_energy + fs.shell_bending_energy < 1e-9);
    REQUIRE(fs.shell_points == o.size());
  }
}

TEST_CASE("denting: below yield returns flat, beyond yield keeps a bend", "[shell][denting]") {
  auto run = [](double lift) {
    ShellMaterialDesc mat;
    mat.name = "al";
    mat.youngs_modulus = 7e7;  // soft aluminium-like (fast test), same yield strain ratio
    mat.poisson_ratio = 0.33;
    mat.density = 2700;
    mat.thickness = 0.002;
    mat.yield_stress = 1e5;
    mat.damping = 30;
    ShellDesc sh;
    sh.name = "strip";
    sh.kind = ShellDesc::Kind::Sheet;
    sh.size[0] = 0.2;
    sh.size[1] = 0.05;
    sh.resolution[0] = 16;
    sh.resolution[1] = 4;
    PinDesc clamp;
    clamp.has_box = true;
    clamp.box_min = Vec3d(-0.11, -1, -1);
    clamp.box_max = Vec3d(-0.0874, 1, 1);
    sh.pins.push_back(clamp);
    PinDesc push;
    push.has_box = true;
    push.box_min = Vec3d(0.099, -1, -1);
    push.box_max = Vec3d(0.11, 1, 1);
    push.components[0] = push.components[2] = false;
    // Lift the free end, hold it, then let go: the strip springs back, fully below
    // yield, partly beyond it.
    push.keyframes.resize(3);
    push.keyframes[0].time = 0;
    push.keyframes[1].time = 0.25;
    push.keyframes[1].translate = Vec3d(0, lift, 0);
    push.keyframes[2].time = 0.35;
    push.keyframes[2].translate = Vec3d(0, lift, 0);
    push.release_time = 0.35;
    sh.pins.push_back(push);
    Scene s = shell_scene(mat, sh);
    s.shot.gravity = Vec3d::Zero();
    Solver solver(s);
    FrameStats fs;
    for (int f = 1; f <= 36; ++f) fs = solver.advance_to(f / 24.0);
    // The free end: how far it stays off the flat line after release and settling.
    const ShellObject& o = *solver.shells()[0];
    double tip = 0;
    for (std::size_t i = 0; i < o.size(); ++i)
      if (o.rest[i].x() > 0.099) tip = std::max(tip, std::abs(double(o.x[i].y())));
    REQUIRE(fs.shell_kinetic_energy < 1e-6);  // settled
    return std::make_pair(tip, fs.shell_plastic_work);
  };
  const auto below = run(0.002);
  const auto beyond = run(0.06);
  INFO("below: offset " << below.first << " plastic work " << below.second);
  INFO("beyond: offset " << beyond.first << " plastic work " << beyond.second);
  REQUIRE(below.second == 0);
  REQUIRE(below.first < 1e-4);
  REQUIRE(beyond.second > 0);
  REQUIRE(beyond.first > 0.1 * 0.06);  // keeps more than a tenth of the lift
}

TEST_CASE("meshes with valence 3 to 12 and open boundaries run without NaN", "[shell]") {
  for (int k : {3, 4, 5, 7, 8, 12}) {
    ShellDesc sh;
    sh.name = "disc";
    sh.kind = ShellDesc::Kind::Mesh;
    sh.mesh = std::make_shared<ShellMesh>(valence_disc(k));
    sh.velocity = Vec3d(0, 0, 0);
    PinDesc pin;
    pin.indices = {0};
    sh.pins.push_back(pin);
    Scene s = shell_scene(cloth(), sh);
    Solver solver(s);
    FrameStats fs;
    double emax = 0;
    for (int f = 1; f <= 12; ++f) {
      fs = solver.advance_to(f / 24.0);
      double pe = 0;
      const ShellObject& o = *solver.shells()[0];
      for (std::size_t i = 0; i < o.size(); ++i) {
        REQUIRE(std::isfinite(o.x[i].norm()));
        pe += o.mass[i] * 9.81 * o.x[i].y();
      }
      emax = std::max(
          emax, fs.shell_kinetic_energy + fs.shell_membrane_energy + fs.shell_bending_energy + pe);
    }
    INFO("valence " << k);
    REQUIRE(emax < 1e-3);  // starts at 0 total energy; nothing is created
  }
}

TEST_CASE("pre-roll settles a pinned sheet and output meshes keep their layout", "[shell]") {
  ShellDesc sh;
  sh.name = "drape";
  sh.kind = ShellDesc::Kind::Sheet;
  sh.resolution[0] = sh.resolution[1] = 8;
  sh.output_refine = 2;
  PinDesc pin;
  pin.indices = {0, 8, 72, 80};
  sh.pins.push_back(pin);
  Scene s = shell_scene(cloth(), sh);
  Solver solver(s);
  PrerollSettings pr;
  pr.enabled = true;
  pr.tolerance = 1e-3;
  const int steps = solver.preroll(pr);
  REQUIRE(steps > 1);
  FrameStats fs;
  solver.measure(fs);
  REQUIRE(fs.shell_kinetic_energy == 0);
  // Sagged: the centre hangs below the pinned corners.
  REQUIRE(solver.shells()[0]->x[40].y() < -1e-3);
  // Refinement 2: 16 sub-triangles per control triangle, shared vertices made once.
  const LimitMesh& lm = solver.shells()[0]->limit_mesh();
  REQUIRE(lm.triangles().size() == 128 * 16);
  REQUIRE(lm.num_vertices() == 33 * 33);
  REQUIRE(lm.uvs().size() == lm.num_vertices());
}

TEST_CASE("Rayleigh stiffness damping removes energy, and without it energy is kept", "[shell]") {
  auto final_energy = [](double beta) {
    ShellMaterialDesc m = cloth();
    m.stiffness_damping = beta;
    ShellDesc sh;
    sh.name = "sheet";
    sh.kind = ShellDesc::Kind::Sheet;
    sh.resolution[0] = sh.resolution[1] = 8;
    PinDesc pin;
    pin.indices = {0, 8};
    sh.pins.push_back(pin);
    Scene s = shell_scene(m, sh);
    Solver solver(s);
    auto total = [&] {
      FrameStats fs;
      solver.measure(fs);
      double pe = 0;
      const ShellObject& o = *solver.shells()[0];
      for (std::size_t i = 0; i < o.size(); ++i) pe += o.mass[i] * 9.81 * o.x[i].y();
      return fs.shell_kinetic_energy + fs.shell_membrane_energy + fs.shell_bending_energy + pe;
    };
    const double e0 = total();
    for (int f = 1; f <= 12; ++f) solver.advance_to(f / 24.0);
    return std::make_pair(e0, total());
  };
  const auto undamped = final_energy(0.0);
  const auto damped = final_energy(2e-3);
  // The sheet falls from rest (e0 = 0): without damping the total stays near 0; with
  // stiffness damping clearly below (energy is dissipated, never created).
  const double scale = 300 * 1.0 * 1e-3 * 9.81 * 0.5;  // weight times half the sheet size
  INFO("undamped " << undamped.second << " damped " << damped.second);
  REQUIRE(std::abs(undamped.second - undamped.first) < 0.02 * scale);
  REQUIRE(damped.second < damped.first - 0.02 * scale);
}

TEST_CASE("a sheet pulled to 3x its length by a keyframed pin stays finite, without a neck",
          "[shell][membrane_stretch]") {
  // A 0.2 m x 0.1 m cloth strip, shell-only (no grid). Its left edge is clamped; a pin on
  // its right edge moves +0.4 m in 0.5 s (to three times the length), then holds. Plain
  // Hencky (whose force falls past s = e) necks here: max strain 3.19, a local stretch of
  // 24x; with the large-stretch term (kirchhoff_love.h) it stays near a uniform log 3.
  ShellMaterialDesc mat = cloth();
  mat.damping = 5;
  ShellDesc sh;
  sh.name = "strip";
  sh.kind = ShellDesc::Kind::Sheet;
  sh.size[0] = 0.2;
  sh.size[1] = 0.1;
  sh.resolution[0] = 16;
  sh.resolution[1] = 8;
  PinDesc clamp;
  clamp.has_box = true;
  clamp.box_min = Vec3d(-0.11, -1, -1);
  clamp.box_max = Vec3d(-0.09, 1, 1);
  sh.pins.push_back(clamp);
  PinDesc pull = clamp;
  pull.box_min = Vec3d(0.09, -1, -1);
  pull.box_max = Vec3d(0.11, 1, 1);
  pull.keyframes.resize(3);
  pull.keyframes[0].time = 0;
  pull.keyframes[1].time = 0.5;
  pull.keyframes[1].translate = Vec3d(0.4, 0, 0);
  pull.keyframes[2].time = 0.75;
  pull.keyframes[2].translate = Vec3d(0.4, 0, 0);
  sh.pins.push_back(pull);
  Scene s = shell_scene(mat, sh);
  s.shot.gravity = Vec3d::Zero();
  Solver solver(s);
  std::string error;
  double strain = 0;
  int frames = 0;
  try {
    for (int f = 1; f <= 18; ++f) {
      solver.advance_to(f / 24.0);
      strain = std::max(strain, solver.shells()[0]->max_strain());
      frames = f;
    }
  } catch (const SimulationError& e) {
    error = e.what();
  }
  const ShellObject& o = *solver.shells()[0];
  double x_max = -1e9;
  bool finite = true;
  for (std::size_t i = 0; i < o.size(); ++i) {
    finite = finite && std::isfinite(double(o.x[i].norm()));
    x_max = std::max(x_max, double(o.x[i].x()));
  }
  INFO("frames " << frames << " error '" << error << "' max strain " << strain);
  REQUIRE(error.empty());
  REQUIRE(finite);
  REQUIRE(x_max == Approx(0.5).margin(0.02));  // the right edge followed the pin
  REQUIRE(strain < std::log(4.0));             // a uniform pull is log 3 = 1.10
}
