// The soft elastic material of the bulk benchmarks' cubes, and the cube of
// bench/mpm_throughput (also the scene of tests/sim/solver/test_peak_memory.cpp).
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

/// An elastic cube of `cells_per_side` cells of spacing dx, 8 particles per cell, centred
/// in the unit domain and moving at (0.3, -0.5, 0.2) m/s, at a fixed step of 1e-4 s.
inline shellmpm::Scene cube_scene(double cells_per_side, double dx, shellmpm::Transfer transfer) {
  using namespace shellmpm;
  Scene s;
  s.path = "bench";
  s.shot.dx = dx;
  s.shot.domain_min = Vec3d(0, 0, 0);
  s.shot.domain_max = Vec3d(1, 1, 1);
  s.shot.cfl = 0.9;
  s.shot.dt_max = 1e-4;  // fixed step: the cube is soft enough that CFL never binds
  s.shot.transfer = transfer;
  s.materials.push_back(jelly());
  SourceDesc src;
  src.material = 0;
  src.shape.kind = ShapeDesc::Kind::Box;
  const double side = cells_per_side * dx;
  src.shape.min = Vec3d(0.5 - side / 2, 0.5 - side / 2, 0.5 - side / 2);
  src.shape.max = src.shape.min + Vec3d::Constant(side);
  src.particles_per_cell = 8;
  src.velocity = Vec3d(0.3, -0.5, 0.2);
  s.sources.push_back(src);
  return s;
}

}  // namespace shellmpm_bench
