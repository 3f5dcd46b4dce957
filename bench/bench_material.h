// The soft elastic material of the bulk benchmarks' cubes.
#pragma once
#include "sim/scene/scene.h"

namespace shellmpm_bench {

/// Fixed corotated jelly, E 10 kPa, nu 0.3, 1000 kg/m^3: soft enough that at dt 1e-4 s and
/// dx 1/128 the CFL bound never binds, so every benchmark step is one fixed step.
inline shellmpm::MaterialDesc jelly() {
  shellmpm::MaterialDesc m;
  m.name = "jelly";
  m.youngs_modulus = 1e4;
  m.poisson_ratio = 0.3;
  m.density = 1000;
  return m;
}

}  // namespace shellmpm_bench
