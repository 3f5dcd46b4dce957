// Shared shell test fixtures.
#pragma once
#include <string>

#include "sim/contact/contact_energy.h"
#include "sim/scene/scene.h"

namespace shellmpm::test {

/// The contact material of the single-particle contact tests: k_c 2e5 Pa, gamma 5e4 Pa,
/// c_F 0.4.
inline ContactParams contact_params() {
  ContactParams p;
  p.kc = 2.0e5;
  p.gamma = 5.0e4;
  p.friction = 0.4;
  return p;
}

/// A shell material: E [Pa], nu, rho [kg/m^3], thickness h [m]; the rest the defaults.
inline ShellMaterialDesc shell_material(const std::string& name, double E, double nu, double rho,
                                        double h) {
  ShellMaterialDesc m;
  m.name = name;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.density = rho;
  m.thickness = h;
  return m;
}

/// A light cotton-like cloth: E 2e5 Pa, nu 0.3, 300 kg/m^3, 1 mm.
inline ShellMaterialDesc cloth_material() {
  return shell_material("cloth", 2e5, 0.3, 300, 1e-3);
}

/// Sheet steel: E 2e11 Pa, nu 0.3, 7850 kg/m^3, 0.5 mm (scenes/steel_dent.yaml's, without
/// its yield stress).
inline ShellMaterialDesc steel_sheet_material() {
  return shell_material("steel", 2e11, 0.3, 7850, 5e-4);
}

/// The clamped strip of scenes/study/cantilever_gravity.yaml (n = 16, contact off): free
/// length L = 0.2 m, width 0.05 m, one control row behind the clamp, which pins the rows
/// x <= h = L / 16 (the limit surface is then clamped at x = 0).
inline ShellDesc clamped_strip(const std::string& name) {
  ShellDesc sh;
  sh.name = name;
  sh.material = 0;  // the scene's first shell material
  sh.contact = ShellDesc::Contact::Off;
  sh.kind = ShellDesc::Kind::Sheet;
  sh.size[0] = 0.2125;
  sh.size[1] = 0.05;
  sh.resolution[0] = 17;
  sh.resolution[1] = 4;
  sh.translate = Vec3d(0.09375, 0, 0);
  PinDesc clamp;
  clamp.has_box = true;
  clamp.box_min = Vec3d(-1, -1, -1);
  clamp.box_max = Vec3d(0.0125001, 1, 1);
  sh.pins.push_back(clamp);
  return sh;
}

/// A square sheet without contact: side `size` [m], `resolution` elements a side.
inline ShellDesc free_sheet(const std::string& name, double size, int resolution) {
  ShellDesc sh;
  sh.name = name;
  sh.contact = ShellDesc::Contact::Off;
  sh.kind = ShellDesc::Kind::Sheet;
  sh.size[0] = sh.size[1] = size;
  sh.resolution[0] = sh.resolution[1] = resolution;
  return sh;
}

/// A still sphere collider.
inline ColliderDesc sphere_collider(const std::string& name, const Vec3d& center, double radius) {
  ColliderDesc c;
  c.name = name;
  c.shape.kind = ShapeDesc::Kind::Sphere;
  c.shape.center = center;
  c.shape.radius = radius;
  return c;
}

/// A scene for contact tests: grid spacing dx, CFL 0.5, 48 fps, the domain [-1, 1]^3.
/// A square procedural sheet `size` m across with res x res cells, lifted to `at`.
inline ShellDesc square_sheet(const std::string& name, double size, int res, const Vec3d& at) {
  ShellDesc d;
  d.name = name;
  d.kind = ShellDesc::Kind::Sheet;
  d.size[0] = d.size[1] = size;
  d.resolution[0] = d.resolution[1] = res;
  d.translate = at;
  return d;
}

inline Scene contact_test_scene(double dx) {
  Scene s;
  s.path = "test";
  s.shot.dx = dx;
  s.shot.cfl = 0.5;
  s.shot.fps = 48;
  s.shot.domain_min = Vec3d(-1, -1, -1);
  s.shot.domain_max = Vec3d(1, 1, 1);
  return s;
}

}  // namespace shellmpm::test
