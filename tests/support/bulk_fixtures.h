// Bulk materials shared by the solver tests.
#pragma once
#include "sim/scene/scene.h"

namespace shellmpm::test {

/// Drucker-Prager sand named "sand": density 1600, nu 0.3, Young's modulus E [Pa] and
/// friction angle [degrees].
inline MaterialDesc sand_material(double youngs_modulus, double friction_angle_deg) {
  MaterialDesc sand;
  sand.name = "sand";
  sand.kind = MaterialKind::Sand;
  sand.youngs_modulus = youngs_modulus;
  sand.poisson_ratio = 0.3;
  sand.density = 1600;
  sand.friction_angle_deg = friction_angle_deg;
  return sand;
}

}  // namespace shellmpm::test
