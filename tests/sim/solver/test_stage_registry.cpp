// The stage registry: a scene switches on exactly the stages it needs, in execution
// order, and the solver runs that list.
#include <catch2/catch.hpp>
#include <set>

#include "sim/solver/solver.h"
#include "sim/solver/stages/registry.h"
#include "sim/solver/stages/scene_rules.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;
using Names = std::vector<std::string>;

namespace {

Scene base_scene() {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.05;
  s.shot.fps = 24;
  s.shot.domain_min = Vec3d(-1, -1, -1);
  s.shot.domain_max = Vec3d(1, 1, 1);
  return s;
}

void add_sheet(Scene& s, const char* name, double y, ShellDesc::Contact contact) {
  if (s.shell_materials.empty()) s.shell_materials.push_back(test::cloth_material());
  ShellDesc d;
  d.name = name;
  d.kind = ShellDesc::Kind::Sheet;
  d.size[0] = d.size[1] = 0.4;
  d.resolution[0] = d.resolution[1] = 4;
  d.translate = Vec3d(0, y, 0);
  d.contact = contact;
  s.shells.push_back(d);
}

void add_source(Scene& s, MaterialKind kind, bool emit) {
  MaterialDesc m;
  m.name = "m" + std::to_string(s.materials.size());
  m.kind = kind;
  m.youngs_modulus = 1e4;
  m.density = 1000;
  s.materials.push_back(m);
  SourceDesc src;
  src.material = static_cast<int>(s.materials.size()) - 1;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d(-0.1, 0.3, -0.1);
  src.shape.max = Vec3d(0.1, 0.4, 0.1);
  src.emit = emit;
  src.emit_start = 0;
  src.emit_end = 1;
  s.sources.push_back(src);
}

void add_ground(Scene& s) {
  ColliderDesc g;
  g.name = "ground";
  g.shape.kind = ShapeDesc::Kind::Plane;
  g.shape.point = Vec3d(0, -0.5, 0);
  s.colliders.push_back(g);
}

// The registry's list for the scene, checked against the solver's.
Names stages_of(const Scene& s) {
  const Names n = stage_names(s);
  REQUIRE(Solver(s).stage_names() == n);
  return n;
}

}  // namespace

TEST_CASE("a lone shell without contact runs only its forces and its update", "[stages]") {
  Scene s = base_scene();
  add_sheet(s, "a", 0, ShellDesc::Contact::Auto);
  REQUIRE_FALSE(shell_has_contact(s, 0));  // nothing to touch
  REQUIRE(stages_of(s) == Names{"shell_forces", "shell_update"});
}

TEST_CASE("a shell with self-contact runs the contact pipeline on the grid", "[stages]") {
  Scene s = base_scene();
  add_sheet(s, "a", 0, ShellDesc::Contact::On);
  REQUIRE(stages_of(s) == Names{"shell_forces", "contact", "bin", "p2g", "grid", "contact_grid",
                                "g2p", "shell_guard", "friction"});
  // The shell guard is on by default and goes with shot.shell_guard: false.
  s.shot.shell_guard = false;
  REQUIRE(stages_of(s) == Names{"shell_forces", "contact", "bin", "p2g", "grid", "contact_grid",
                                "g2p", "friction"});
  s.shot.shell_guard = true;
  // A denting material adds the denting stage after the step.
  s.shell_materials[0].yield_stress = 1e6;
  REQUIRE(stages_of(s).back() == "denting");
}

TEST_CASE("two shells: auto contact goes on, a shell kept off still updates directly", "[stages]") {
  Scene s = base_scene();
  add_sheet(s, "a", 0, ShellDesc::Contact::Auto);
  add_sheet(s, "b", 0.2, ShellDesc::Contact::Off);
  REQUIRE(shell_has_contact(s, 0));
  REQUIRE_FALSE(shell_has_contact(s, 1));
  REQUIRE(stages_of(s) == Names{"shell_forces", "shell_update", "contact", "bin", "p2g", "grid",
                                "contact_grid", "g2p", "shell_guard", "friction"});
}

TEST_CASE("bulk material: elastic needs no plasticity, sand does, emission adds emit", "[stages]") {
  Scene s = base_scene();
  add_source(s, MaterialKind::Elastic, false);
  REQUIRE(stages_of(s) == Names{"bin", "p2g", "grid", "g2p"});
  add_ground(s);
  REQUIRE(stages_of(s) == Names{"bin", "p2g", "grid", "colliders", "g2p", "collider_particles"});
  add_source(s, MaterialKind::Sand, true);
  REQUIRE(stages_of(s) == Names{"bin", "p2g", "grid", "colliders", "g2p", "collider_particles",
                                "plasticity", "emit"});
}

TEST_CASE("every registered stage is reachable, once, in one execution order", "[stages]") {
  // A scene that asks for everything: shells with and without contact, denting, sand
  // emitted next to elastic bulk material, a collider.
  Scene s = base_scene();
  add_sheet(s, "a", 0, ShellDesc::Contact::On);
  add_sheet(s, "b", 0.2, ShellDesc::Contact::Off);
  s.shell_materials[0].yield_stress = 1e6;
  add_source(s, MaterialKind::Elastic, false);
  add_source(s, MaterialKind::Sand, true);
  add_ground(s);
  const Names all = stages_of(s);
  REQUIRE(all == Names{"shell_forces", "shell_update", "contact", "bin", "p2g", "grid",
                       "contact_grid", "colliders", "g2p", "collider_particles", "shell_guard",
                       "friction", "plasticity", "denting", "emit"});
  REQUIRE(std::set<std::string>(all.begin(), all.end()).size() == all.size());
  // And nothing to simulate: no stage at all.
  REQUIRE(stages_of(base_scene()).empty());
}

TEST_CASE(
    "implicit: implicit_grid takes grid's place, implicit_shells the shells' forces and "
    "update",
    "[stages][implicit]") {
  Scene lone = base_scene();
  add_sheet(lone, "a", 0, ShellDesc::Contact::Off);
  lone.shot.integrator = Integrator::Implicit;
  REQUIRE(stages_of(lone) == Names{"implicit_shells"});
  // The implicit stages with everything else an implicit scene may ask for (no shell in
  // contact: refused by the scene reader).
  Scene s = base_scene();
  add_sheet(s, "b", 0.2, ShellDesc::Contact::Off);
  s.shell_materials[0].yield_stress = 1e6;
  add_source(s, MaterialKind::Elastic, false);
  add_source(s, MaterialKind::Sand, true);
  add_ground(s);
  s.shot.integrator = Integrator::Implicit;
  REQUIRE(stages_of(s) == Names{"bin", "p2g", "implicit_grid", "implicit_shells", "colliders",
                                "g2p", "collider_particles", "plasticity", "denting", "emit"});
}
