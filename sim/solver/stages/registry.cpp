#include "sim/solver/stages/registry.h"

#include "sim/solver/stages/bin.h"
#include "sim/solver/stages/bulk_plasticity.h"
#include "sim/solver/stages/collider_particles.h"
#include "sim/solver/stages/colliders.h"
#include "sim/solver/stages/contact_forces.h"
#include "sim/solver/stages/contact_grid.h"
#include "sim/solver/stages/denting.h"
#include "sim/solver/stages/emit.h"
#include "sim/solver/stages/friction.h"
#include "sim/solver/stages/g2p.h"
#include "sim/solver/stages/grid_update.h"
#include "sim/solver/stages/implicit_grid.h"
#include "sim/solver/stages/implicit_shells.h"
#include "sim/solver/stages/p2g.h"
#include "sim/solver/stages/shell_forces.h"
#include "sim/solver/stages/shell_guard.h"
#include "sim/solver/stages/shell_update.h"

namespace shellmpm {
namespace {

struct Entry {
  bool (*needed)(const Scene&);
  std::unique_ptr<Stage> (*make)();
};

template <class S>
Entry entry() {
  return {&S::needed, []() -> std::unique_ptr<Stage> { return std::make_unique<S>(); }};
}

// Execution order. Shell forces come first (the transfer carries them), the grid stages
// in the order of one MPM step (the shell guard last, after G2P has moved the control
// points and the colliders have projected points out: a projection after it moved
// control points through the layers the guard had just held apart), then the shells' denting and
// the emission of new particles for the next step.
const std::vector<Entry>& registry() {
  static const std::vector<Entry> table = {
      entry<ShellForcesStage>(),
      entry<ShellUpdateStage>(),
      entry<ContactForcesStage>(),
      entry<BinStage>(),
      entry<P2gStage>(),
      entry<GridUpdateStage>(),
      entry<ImplicitGridStage>(),
      entry<ImplicitShellsStage>(),
      entry<ContactGridStage>(),
      entry<CollidersStage>(),
      entry<G2pStage>(),
      entry<ColliderParticlesStage>(),
      entry<ShellGuardStage>(),
      entry<FrictionStage>(),
      entry<BulkPlasticityStage>(),
      entry<DentingStage>(),
      entry<EmitStage>(),
  };
  return table;
}

}  // namespace

std::vector<std::unique_ptr<Stage>> make_stages(const Scene& s) {
  std::vector<std::unique_ptr<Stage>> out;
  for (const Entry& e : registry())
    if (e.needed(s)) out.push_back(e.make());
  return out;
}

std::vector<std::string> stage_names(const Scene& s) {
  std::vector<std::string> out;
  for (const auto& st : make_stages(s)) out.emplace_back(st->name());
  return out;
}

}  // namespace shellmpm
