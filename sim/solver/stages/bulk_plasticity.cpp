#include "sim/solver/stages/bulk_plasticity.h"

#include "sim/core/parallel.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool BulkPlasticityStage::needed(const Scene& s) {
  return grid_needed(s) && any_plastic_material(s);
}

void BulkPlasticityStage::run(StepContext& c) {
  ParticleSet& p = c.particles;
  parallel_for(
      p.size(), kParticleGrain,
      [&](std::size_t b, std::size_t e) {
        std::size_t i = b;
        while (i < e) {
          const auto mat = p.material_of(i);
          std::size_t j = i + 1;
          while (j < e && p.material_of(j) == mat) ++j;
          const ConstitutiveModel& m = c.models[mat];
          if (m.has_plasticity()) m.project_batch(p.F.data() + i, p.plastic.data() + i, j - i);
          i = j;
        }
      },
      c.opt.serial);
}

}  // namespace shellmpm
