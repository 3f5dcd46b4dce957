// The causes of the time step (sim/solver/step_limits.h): each names its object and
// value, and the smallest equals Solver::stable_dt(), on scenes of every kind.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "sim/shell/procedural_mesh.h"
#include "sim/solver/solver.h"
#include "sim/solver/step_limits.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

Scene base_scene(double dx) {
  Scene s;
  s.path = "test";
  s.shot.dx = dx;
  s.shot.fps = 24;
  s.shot.domain_min = Vec3d(-1, -1, -1);
  s.shot.domain_max = Vec3d(1, 1, 1);
  return s;
}

void add_block(Scene& s, const MaterialDesc& m, const Vec3d& velocity, bool emit = false) {
  s.materials.push_back(m);
  SourceDesc src;
  src.name = m.name + "_source";
  src.material = static_cast<int>(s.materials.size()) - 1;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d(-0.1, 0.2, -0.1);
  src.shape.max = Vec3d(0.1, 0.4, 0.1);
  src.velocity = velocity;
  src.emit = emit;
  src.emit_start = 2;
  src.emit_end = 3;
  s.sources.push_back(src);
}

MaterialDesc jelly() {
  MaterialDesc m;
  m.name = "jelly";
  m.youngs_modulus = 2e4;
  m.density = 1000;
  return m;
}

MaterialDesc steel() {
  MaterialDesc m;
  m.name = "steel";
  m.youngs_modulus = 2e11;
  m.poisson_ratio = 0.3;
  m.density = 7850;
  return m;
}

/// A 0.4 m sheet of 8 x 8 quads (0.05 m edges) whose vertex 40 (the middle) is moved to
/// 0.17 mm from vertex 41, as a mesh shell.
ShellDesc sheet_with_short_edge(const std::string& name) {
  ShellMesh m = make_sheet(0.4, 0.4, 8, 8);
  m.vertices[40] = m.vertices[41] - Vec3d(0.17e-3, 0, 0);
  ShellDesc d;
  d.name = name;
  d.kind = ShellDesc::Kind::Mesh;
  d.mesh = std::make_shared<ShellMesh>(m);
  return d;
}

ShellDesc sheet(const std::string& name, const Vec3d& at) {
  ShellDesc d;
  d.name = name;
  d.kind = ShellDesc::Kind::Sheet;
  d.size[0] = d.size[1] = 0.4;
  d.resolution[0] = d.resolution[1] = 8;
  d.translate = at;
  return d;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

double min_dt(const std::vector<StepLimit>& limits) {
  REQUIRE(!limits.empty());
  double dt = limits.front().dt;
  for (const StepLimit& l : limits) dt = std::min(dt, l.dt);
  return dt;
}

void require_matches_solver(const Solver& solver) {
  const std::vector<StepLimit> limits = step_limits(solver);
  for (std::size_t i = 1; i < limits.size(); ++i) REQUIRE(limits[i - 1].dt <= limits[i].dt);
  for (const StepLimit& l : limits) REQUIRE(!l.upcoming);
  INFO("limited by " << limits.front().detail);
  REQUIRE(min_dt(limits) == Approx(solver.stable_dt()).epsilon(1e-12));
  REQUIRE(limits.front().dt == min_dt(limits));
}

}  // namespace

TEST_CASE("step limits: one very short mesh edge is named with its vertices and position",
          "[step_limits]") {
  Scene s = base_scene(0.02);
  s.shell_materials.push_back(test::cloth_material());
  s.shells.push_back(sheet_with_short_edge("film"));
  Solver solver(s);
  REQUIRE(solver.shells()[0]->min_edge() == Approx(0.17e-3).epsilon(1e-6));
  const std::vector<StepLimit> limits = step_limits(solver);
  const StepLimit& l = limits.front();
  INFO(l.detail);
  REQUIRE(l.kind == StepLimitKind::ShellElastic);
  REQUIRE(l.dt == solver.stable_dt());
  REQUIRE(l.dt < s.shot.dt_min);
  REQUIRE(has(l.detail, "shell 'film'"));
  REQUIRE(has(l.detail, "0.17 mm"));
  REQUIRE(
      (has(l.detail, "between vertices 40 and 41") || has(l.detail, "between vertices 41 and 40")));
  // The edge's midpoint: vertex 41 is at (0.05, 0, 0).
  REQUIRE(has(l.detail, "at (0.0499, 0, 0)"));
  REQUIRE(has(l.hint, "merge the vertices of that edge"));
  // The run stops at once with the same cause.
  try {
    solver.advance_to(1.0 / 24);
    FAIL("no SimulationError");
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    INFO(msg);
    REQUIRE(msg.rfind("at t = 0 s the stable step ", 0) == 0);
    REQUIRE(has(msg, "is below shot.dt_min"));
    REQUIRE(has(msg, "shell 'film'"));
    REQUIRE(has(msg, "0.17 mm"));
    REQUIRE(has(msg, "merge the vertices"));
    REQUIRE(has(msg, "shot.integrator: auto"));  // the way out that keeps the mesh
  }
}

TEST_CASE("step limits: a steel material at the default CFL is named with its wave speed",
          "[step_limits]") {
  Scene s = base_scene(0.01);
  add_block(s, steel(), Vec3d(0, -1, 0));
  Solver solver(s);
  const std::vector<StepLimit> limits = step_limits(solver);
  const StepLimit& l = limits.front();
  INFO(l.detail);
  REQUIRE(l.kind == StepLimitKind::Material);
  // c = sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu)) / rho) = 5856 m/s; dt = 0.3 dx / c.
  const double c = std::sqrt(2e11 * 0.7 / (1.3 * 0.4) / 7850);
  REQUIRE(l.dt == Approx(0.3 * 0.01 / c).epsilon(1e-5));
  REQUIRE(l.dt < s.shot.dt_min);
  REQUIRE(has(l.detail, "material 'steel'"));
  REQUIRE(has(l.detail, "wave speed 5856 m/s"));
  REQUIRE(has(l.hint, "softer material"));
  // The particles' speed is a limit of its own, far behind.
  bool speed = false;
  for (const StepLimit& o : limits)
    if (o.kind == StepLimitKind::ParticleSpeed) {
      speed = true;
      REQUIRE(has(o.detail, "max speed 1 m/s"));
    }
  REQUIRE(speed);
  try {
    solver.advance_to(1.0 / 24);
    FAIL("no SimulationError");
  } catch (const SimulationError& e) {
    INFO(e.what());
    REQUIRE(has(e.what(), "material 'steel'"));
  }
}

TEST_CASE("step limits: contact stiffness and a moving collider are causes of their own",
          "[step_limits]") {
  Scene s = base_scene(0.02);
  ShellMaterialDesc m = test::cloth_material();
  m.contact_stiffness = 2e11;
  s.shell_materials.push_back(m);
  s.shells.push_back(sheet("film", Vec3d(0, 0, 0)));
  ColliderDesc blade;
  blade.name = "blade";
  blade.shape.kind = ShapeDesc::Kind::Sphere;
  blade.shape.radius = 0.1;
  blade.shape.center = Vec3d(0, 0.5, 0);
  Keyframe k0, k1;
  k1.time = 0.1;
  k1.translate = Vec3d(1, 0, 0);  // 10 m/s
  blade.keyframes = {k0, k1};
  s.colliders.push_back(blade);
  Solver solver(s);
  REQUIRE(solver.shell_on_grid(0));
  const std::vector<StepLimit> limits = step_limits(solver);
  INFO(limits.front().detail);
  REQUIRE(limits.front().kind == StepLimitKind::ShellContact);
  REQUIRE(
      has(limits.front().detail, "shell 'film': contact stiffness k_c 2e+11 Pa over density 300"));
  REQUIRE(has(limits.front().hint, "contact_stiffness"));
  bool collider = false;
  for (const StepLimit& l : limits)
    if (l.kind == StepLimitKind::ColliderSpeed) {
      collider = true;
      INFO(l.detail);
      REQUIRE(has(l.detail, "collider 'blade': speed 10 m/s"));
      REQUIRE(l.dt == Approx(0.3 * 0.02 / 10).epsilon(1e-3));
    }
  REQUIRE(collider);
  require_matches_solver(solver);
}

TEST_CASE("step limits: the smallest equals Solver::stable_dt, before and after steps",
          "[step_limits]") {
  SECTION("a jelly block with a velocity") {
    Scene s = base_scene(0.05);
    add_block(s, jelly(), Vec3d(0.5, 1.0, 0));
    Solver solver(s);
    require_matches_solver(solver);
    solver.advance_to(0.05);
    require_matches_solver(solver);
  }
  SECTION("a fast block whose speed sets the step") {
    Scene s = base_scene(0.05);
    add_block(s, jelly(), Vec3d(0, -40, 0));
    Solver solver(s);
    REQUIRE(step_limits(solver).front().kind == StepLimitKind::ParticleSpeed);
    require_matches_solver(solver);
  }
  SECTION("cloth sheets in contact with jelly and a moving collider") {
    Scene s = base_scene(0.05);
    s.shell_materials.push_back(test::cloth_material());
    s.shells.push_back(sheet("a", Vec3d(0, 0, 0)));
    s.shells.push_back(sheet("b", Vec3d(0, 0.1, 0)));
    s.shells[1].velocity = Vec3d(0, -3, 0);
    add_block(s, jelly(), Vec3d(0, -1, 0));
    ColliderDesc roller;
    roller.name = "roller";
    roller.shape.kind = ShapeDesc::Kind::Sphere;
    roller.shape.radius = 0.1;
    roller.shape.center = Vec3d(0, -0.5, 0);
    Keyframe k0, k1;
    k1.time = 1;
    k1.translate = Vec3d(0.5, 0, 0);
    roller.keyframes = {k0, k1};
    s.colliders.push_back(roller);
    Solver solver(s);
    require_matches_solver(solver);
    solver.advance_to(0.02);
    require_matches_solver(solver);
  }
  SECTION("a shell without contact, with stiffness damping") {
    Scene s = base_scene(0.02);
    ShellMaterialDesc m = test::cloth_material();
    m.stiffness_damping = 1e-4;
    s.shell_materials.push_back(m);
    s.shells.push_back(sheet("cloth", Vec3d(0, 0, 0)));
    Solver solver(s);
    REQUIRE(!solver.shell_on_grid(0));
    require_matches_solver(solver);
  }
  SECTION("the short-edge mesh and the steel block") {
    Scene s = base_scene(0.01);
    s.shell_materials.push_back(test::cloth_material());
    s.shells.push_back(sheet_with_short_edge("film"));
    add_block(s, steel(), Vec3d(0, 0, 0));
    Solver solver(s);
    require_matches_solver(solver);
  }
  SECTION("nothing to simulate: shot.dt_max") {
    Scene s = base_scene(0.05);
    Solver solver(s);
    const std::vector<StepLimit> limits = step_limits(solver);
    REQUIRE(limits.size() == 1);
    REQUIRE(limits.front().kind == StepLimitKind::DtMax);
    require_matches_solver(solver);
  }
}

TEST_CASE("step limits: sources still to emit are upcoming causes", "[step_limits]") {
  Scene s = base_scene(0.01);
  add_block(s, steel(), Vec3d(0, -2, 0), /*emit=*/true);
  Solver solver(s);
  REQUIRE(solver.particles().size() == 0);
  require_matches_solver(solver);
  const std::vector<StepLimit> limits = step_limits(solver, /*upcoming=*/true);
  const StepLimit& l = limits.front();
  INFO(l.detail);
  REQUIRE(l.upcoming);
  REQUIRE(l.kind == StepLimitKind::Material);
  REQUIRE(has(l.detail, "material 'steel' (emitted by source 'steel_source')"));
  bool source = false;
  for (const StepLimit& o : limits)
    if (o.kind == StepLimitKind::SourceSpeed) {
      source = true;
      REQUIRE(o.upcoming);
      REQUIRE(has(o.detail, "source 'steel_source': emission speed 2 m/s"));
    }
  REQUIRE(source);
}

TEST_CASE("step limits: the description names every cause below dt_min", "[step_limits]") {
  std::vector<StepLimit> limits(3);
  limits[0] = {StepLimitKind::ShellElastic, 1e-8, "shell 'a': short edge", "remesh", false};
  limits[1] = {StepLimitKind::Material, 1e-7, "material 'steel': stiff", "softer", false};
  limits[2] = {StepLimitKind::DtMax, 1e-2, "shot.dt_max = 0.01 s", "larger", false};
  const std::string d = describe_step_limits(limits, 1e-6);
  INFO(d);
  REQUIRE(d.rfind("limited by shell 'a': short edge (1e-08 s); to raise it: remesh", 0) == 0);
  REQUIRE(has(d, "; also material 'steel': stiff (1e-07 s); to raise it: softer"));
  REQUIRE(!has(d, "dt_max"));
  REQUIRE(!has(describe_step_limits(limits, 5e-8), "steel"));
  // A stiffness sets the step: the implicit integrator is named; a speed: it is not.
  REQUIRE(has(d, "shot.integrator: auto"));
  std::vector<StepLimit> fast = {
      {StepLimitKind::ColliderSpeed, 1e-8, "collider 'bat': speed", "slower", false}};
  REQUIRE(!has(describe_step_limits(fast, 1e-6), "integrator"));
}
