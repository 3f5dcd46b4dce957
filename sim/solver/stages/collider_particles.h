// Stage "collider_particles": Particle-level collider projection after advection
// (particle_projection.h): bulk particles and free control points inside a collider go to its
// surface. The control points of shells without contact (no grid) too: colliders reach
// them only here (and, implicit, through the step's penalty, collider_penalty.h).
#pragma once
#include <vector>

#include "sim/core/types.h"
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ColliderParticlesStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "collider_particles"; }
  void run(StepContext& c) override;

 private:
  std::vector<Vec3> x_before_;  ///< a shell's control points before its projection
};

}  // namespace shellmpm
