// The energy audit (sim/integrity/energy_audit.h): its balance on known numbers, the
// colliders' work it counts (a paddle that pushes a block supplies the energy the block
// gains, explicit and implicit), and a frame that gains energy nothing supplied, which
// it reports as a failure naming the body.
#include <catch2/catch.hpp>

#include "sim/integrity/energy_audit.h"
#include "sim/solver/body_energies.h"
#include "sim/solver/solver.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

BodyEnergy body(const std::string& name, double kinetic, double stored, double potential) {
  BodyEnergy b;
  b.name = name;
  b.kinetic = kinetic;
  b.stored = stored;
  b.potential = potential;
  b.mass = 1;
  return b;
}

/// A jelly block (0.2 m cube) at rest, without gravity, and a separating paddle that
/// comes from -x at `speed` and pushes it along +x.
Scene paddle_scene(double speed, Integrator integrator) {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.04;
  s.shot.domain_min = Vec3d(-0.6, -0.4, -0.4);
  s.shot.domain_max = Vec3d(1.0, 0.4, 0.4);
  s.shot.fps = 24;
  s.shot.gravity = Vec3d::Zero();
  s.shot.integrator = integrator;
  s.shot.dt_max = 1.0 / 240;
  MaterialDesc m;
  m.name = "jelly";
  m.youngs_modulus = 2e4;
  m.density = 1000;
  s.materials.push_back(m);
  SourceDesc src;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d(-0.1, -0.1, -0.1);
  src.shape.max = Vec3d(0.1, 0.1, 0.1);
  s.sources.push_back(src);
  ColliderDesc c;
  c.name = "paddle";
  c.shape.kind = ShapeDesc::Kind::Box;
  c.shape.min = Vec3d(-0.3, -0.2, -0.2);
  c.shape.max = Vec3d(-0.14, 0.2, 0.2);
  c.boundary = BoundaryKind::Separate;
  Keyframe k0, k1;
  k1.time = 1.0;
  k1.translate = Vec3d(speed, 0, 0);
  c.keyframes = {k0, k1};
  s.colliders.push_back(c);
  return s;
}

/// A cloth sheet (0.3 m square, 10 x 10 quads, in the xz plane) alone in a 0.8 m wide
/// domain spanning y in [ylo, yhi], with or without grid contact, steps of at most
/// 1/240 s.
Scene cloth_sheet_scene(bool grid, Integrator integrator, double ylo, double yhi,
                        const ShellMaterialDesc& m) {
  Scene s;
  s.path = "test";
  s.shot.fps = 24;
  s.shot.dx = 0.04;
  s.shot.domain_min = Vec3d(-0.4, ylo, -0.4);
  s.shot.domain_max = Vec3d(0.4, yhi, 0.4);
  s.shot.integrator = integrator;
  s.shot.dt_max = 1.0 / 240;
  s.shell_materials.push_back(m);
  ShellDesc d;
  d.name = "cloth";
  d.kind = ShellDesc::Kind::Sheet;
  d.size = {0.3, 0.3};
  d.resolution = {10, 10};
  d.contact = grid ? ShellDesc::Contact::On : ShellDesc::Contact::Off;
  s.shells.push_back(d);
  return s;
}

/// Frames first..last of a solver, each judged and sound (no energy gain, no failed
/// integrity check); the supply and dissipation summed over them, and the last frame.
struct Frames {
  double supplied = 0, dissipated = 0;
  FrameStats last;
};
Frames sound_frames(Solver& solver, int first, int last) {
  Frames out;
  for (int f = first; f <= last; ++f) {
    out.last = solver.advance_to(f / 24.0);
    const FrameStats& fs = out.last;
    CAPTURE(f, fs.energy.excess, fs.energy.tolerance, fs.energy.supplied, fs.energy.reason);
    REQUIRE(fs.energy.judged);
    REQUIRE_FALSE(fs.energy.failed());
    REQUIRE_FALSE(fs.integrity.energy_gain);
    CHECK_FALSE(fs.integrity.failed());
    out.supplied += fs.energy.supplied;
    out.dissipated += fs.energy.dissipated;
  }
  return out;
}

}  // namespace

TEST_CASE("the energy audit balances the bodies' energy, dissipation and supply",
          "[integrity][energy]") {
  const std::vector<BodyEnergy> start = {body("sand", 1.0, 2.0, -3.0), body("can", 0.5, 0.5, 0.0)};
  // Sand falls: 1 J of potential energy into kinetic; the can dents, 0.4 J of its stored
  // energy dissipated. Nothing supplied: no excess.
  std::vector<BodyEnergy> end = {body("sand", 2.0, 2.0, -4.0), body("can", 0.5, 0.1, 0.0)};
  EnergyAudit a = audit_energy(start, end, {0.0, 0.4}, 0.0, 1e-6);
  REQUIRE(a.judged);
  CHECK(a.start == Approx(1.0));
  CHECK(a.end == Approx(0.6));
  CHECK(a.dissipated == Approx(0.4));
  CHECK(std::abs(a.excess) < 1e-12);
  CHECK_FALSE(a.failed());
  // The can dissipates 40 J more than it had: energy from nowhere, and the can named.
  EnergyAudit b = audit_energy(start, end, {0.0, 40.4}, 0.0, 1e-6);
  CHECK(b.excess == Approx(40.0));
  CHECK(b.failed());
  CHECK(b.object == "can");
  CHECK(b.object_gain == Approx(40.0));
  // The same with 40 J supplied (a collider pressed the can): balanced.
  EnergyAudit c = audit_energy(start, end, {0.0, 40.4}, 40.0, 1e-6);
  CHECK(std::abs(c.excess) < 1e-9);
  CHECK_FALSE(c.failed());
  // Within the tolerance: a small excess passes, one beyond it fails.
  end[0].kinetic += 0.1;
  CHECK_FALSE(audit_energy(start, end, {0.0, 0.4}, 0.0, 1e-6).failed());
  end[0].kinetic += 10;
  CHECK(audit_energy(start, end, {0.0, 0.4}, 0.0, 1e-6).failed());
  // Bodies that do not match are not judged.
  end.pop_back();
  CHECK_FALSE(audit_energy(start, end, {0.0}, 0.0, 1e-6).judged);
}

TEST_CASE("a paddle pushing a block supplies the energy the block gains", "[integrity][energy]") {
  const double speed = 0.5;
  for (const Integrator integ : {Integrator::Explicit, Integrator::Implicit}) {
    CAPTURE(integ == Integrator::Implicit);
    Solver solver(paddle_scene(speed, integ));
    const Frames run = sound_frames(solver, 1, 8);
    const FrameStats& fs = run.last;
    const double supplied = run.supplied, dissipated = run.dissipated;
    REQUIRE(fs.bodies.size() == 1);
    const double mass = fs.bodies[0].mass, gained = fs.bodies[0].total();
    // The block has been struck and moves at about the paddle's speed or faster.
    CHECK(fs.kinetic_energy > 0.5 * mass * speed * speed);
    // All of its energy came from the paddle, and the paddle's work is not overstated
    // by more than what the transfers and the contact dissipate (a third here).
    CHECK(supplied >= gained);
    CHECK(supplied < 1.5 * gained + 1e-9);
    CHECK(dissipated == 0);
  }
}

TEST_CASE("energy that nothing supplied fails the frame and names the body",
          "[integrity][energy]") {
  Solver solver(paddle_scene(0.0, Integrator::Explicit));  // a paddle that stays put
  FrameStats fs = solver.advance_to(1 / 24.0);
  REQUIRE(fs.energy.judged);
  CHECK_FALSE(fs.integrity.failed());
  // Between frames the block is set moving at 2 m/s: the next frame's start is the last
  // one's end, so the frame gains that kinetic energy with nothing to account for it.
  for (Vec3& v : solver.particles().v) v = Vec3(0, 2, 0);
  fs = solver.advance_to(2 / 24.0);
  REQUIRE(fs.energy.judged);
  CHECK(fs.energy.failed());
  CHECK(fs.energy.excess > 0.9 * 0.5 * fs.bodies[0].mass * 4);
  CHECK(fs.energy.object == "jelly");
  // A warning by default (shot.on_energy_gain: warn), not a failed integrity check.
  CHECK(fs.integrity.energy_gain);
  CHECK_FALSE(fs.integrity.failed());
  REQUIRE(fs.integrity.events.size() == 1);
  CHECK(fs.integrity.events.front().kind == IntegrityEvent::Kind::EnergyGain);
  CHECK(fs.integrity.events.front().object == "jelly");
  const std::vector<std::string> lines = describe_integrity(fs.integrity, 2, 0.04);
  REQUIRE(!lines.empty());
  INFO("the warning: " << lines.front());
  CHECK(lines.front().find("frame 2: the bodies gained") == 0);
  CHECK(lines.front().find("'jelly'") != std::string::npos);
  // The frame after is sound again.
  fs = solver.advance_to(3 / 24.0);
  CHECK_FALSE(fs.energy.failed());
  CHECK_FALSE(fs.integrity.energy_gain);
  // With shot.on_energy_gain: ignore the balance is kept but nothing is reported.
  Scene quiet = paddle_scene(0.0, Integrator::Explicit);
  quiet.shot.on_energy_gain = ShotSettings::OnEnergyGain::Ignore;
  Solver q(quiet);
  q.advance_to(1 / 24.0);
  for (Vec3& v : q.particles().v) v = Vec3(0, 2, 0);
  fs = q.advance_to(2 / 24.0);
  CHECK(fs.energy.failed());
  CHECK_FALSE(fs.integrity.energy_gain);
  CHECK(fs.integrity.events.empty());
}

TEST_CASE("a pressure or a point load supplies the energy the sheet gains", "[integrity][energy]") {
  // A free cloth sheet (0.3 m square, no gravity) pushed along its normal by 1 Pa, or by
  // 0.09 N (the same total) at its middle control point: the load's work is the
  // kinetic and elastic energy the sheet gains.
  for (const bool point : {false, true})
    for (const Integrator integ : {Integrator::Explicit, Integrator::Implicit})
      for (const bool grid : {false, true}) {
        CAPTURE(point, integ == Integrator::Implicit, grid);
        Scene s = cloth_sheet_scene(grid, integ, -0.2, 0.5, test::cloth_material());
        s.shot.gravity = Vec3d::Zero();
        ShellDesc& d = s.shells.back();
        if (point) {
          PointLoadDesc pl;
          pl.index = 60;  // the middle of the 11 x 11 vertices
          pl.force = Vec3d(0, 0.09, 0);
          d.point_loads.push_back(pl);
        } else {
          d.pressure = 1.0;
        }
        Solver solver(s);
        const double start = solver.advance_to(1 / 24.0).bodies.at(0).total();
        const Frames run = sound_frames(solver, 2, 5);
        const FrameStats& fs = run.last;
        const double supplied = run.supplied;
        const double gained = fs.bodies.at(0).total() - start;
        CAPTURE(supplied, gained, fs.bodies.at(0).kinetic);
        // Pushed for 4 frames from about 0.14 m/s to about 0.6 m/s: most of the gain is
        // kinetic, and the work pays for all of it (without the loads counted, nothing
        // does; symplectic Euler's energy drifts by 0.03% here), within what the steps'
        // damping and transfers take.
        CHECK(fs.bodies.at(0).kinetic > 0.5 * 0.027 * 0.5 * 0.5 / 2);
        CHECK(supplied > 0.99 * gained);
        CHECK(supplied < 1.3 * gained);
      }
}

namespace {

/// A cloth sheet (0.3 m square) hanging in the yz plane from a pin along its top edge,
/// which rests for a frame, then lifts it 0.2 m at 1.2 m/s and holds.
Scene lifted_cloth(bool grid, Integrator integrator) {
  ShellMaterialDesc m = test::cloth_material();
  m.damping = 0.5;
  Scene s = cloth_sheet_scene(grid, integrator, -0.5, 0.6, m);
  ShellDesc& d = s.shells.back();
  d.rotate_deg = Vec3d(0, 0, 90);  // x -> y: the sheet hangs
  PinDesc pin;
  pin.has_box = true;
  pin.box_min = Vec3d(-0.01, 0.14, -0.2);
  pin.box_max = Vec3d(0.01, 0.16, 0.2);
  Keyframe k0, k1, k2;
  k1.time = 1 / 24.0;
  k2.time = 1 / 24.0 + 0.2 / 1.2;
  k2.translate = Vec3d(0, 0.2, 0);
  pin.keyframes = {k0, k1, k2};
  d.pins.push_back(pin);
  return s;
}

}  // namespace

TEST_CASE("a pin that lifts a cloth supplies the energy the cloth gains", "[integrity][energy]") {
  for (const Integrator integ : {Integrator::Explicit, Integrator::Implicit})
    for (const bool grid : {false, true}) {
      CAPTURE(integ == Integrator::Implicit, grid);
      Solver solver(lifted_cloth(grid, integ));
      const double start = solver.advance_to(1 / 24.0).bodies.at(0).total();
      const Frames run = sound_frames(solver, 2, 8);
      const FrameStats& fs = run.last;
      const double supplied = run.supplied, dissipated = run.dissipated;
      const BodyEnergy& cloth = fs.bodies.at(0);
      const double lift = 0.2 * 9.81 * cloth.mass;  // the potential energy of the lift
      CAPTURE(supplied, dissipated, cloth.total() - start, lift);
      // The cloth hangs from the pin 0.2 m higher (explicitly, stretched and still
      // bouncing from the stop; backward Euler damps that): it gained at least the lift,
      // all of it supplied by the pin (without the pin's work counted, nothing is). What
      // the pin did beyond the gain is lost where the lift starts and stops with a jerk,
      // at most m v^2 / 2 each for the cloth's mass m at the pin's speed v (backward Euler
      // loses about that), and to the damping (0.5/s for 0.17 s).
      const double gained = cloth.total() - start;
      const double jerks = cloth.mass * 1.2 * 1.2;
      CAPTURE(jerks);
      CHECK(gained > 0.8 * lift);
      CHECK(supplied >= gained + dissipated);
      CHECK(supplied - gained < 1.25 * jerks);
    }
}
