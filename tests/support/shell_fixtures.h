// Shared shell test fixtures.
#pragma once
#include "sim/scene/scene.h"

namespace shellmpm::test {

/// A light cotton-like cloth: E 2e5 Pa, nu 0.3, 300 kg/m^3, 1 mm.
inline ShellMaterialDesc cloth_material() {
  ShellMaterialDesc m;
  m.name = "cloth";
  m.youngs_modulus = 2e5;
  m.poisson_ratio = 0.3;
  m.density = 300;
  m.thickness = 1e-3;
  return m;
}

/// A scene for contact tests: grid spacing dx, CFL 0.5, 48 fps, the domain [-1, 1]^3.
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
