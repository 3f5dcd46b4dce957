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

}  // namespace shellmpm::test
