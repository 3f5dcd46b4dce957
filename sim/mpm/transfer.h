// Particle-to-grid and grid-to-particle transfers: APIC (Jiang et al. 2015) with
// quadratic B-splines, or MLS-MPM (Hu et al. 2018) where the stress enters through
// the affine matrix. Symplectic Euler: forces are applied in P2G as a momentum change.
#pragma once
#include <functional>
#include <vector>

#include "sim/core/types.h"
#include "sim/mpm/constitutive.h"
#include "sim/mpm/particles.h"
#include "sim/mpm/sparse_grid.h"

namespace shellmpm {

struct TransferParams {
  Real dt = 0;                                             ///< step [s]
  bool mls = false;                                        ///< MLS-MPM instead of APIC
  bool serial = false;                                     ///< run without threads
  bool stress = true;                                      ///< add internal forces in P2G
  const std::vector<ConstitutiveModel>* models = nullptr;  ///< per material
  const std::vector<Real>* densities = nullptr;            ///< rest density per material
  /// Binned indices below this are other points (shell control points, contact
  /// particles); bulk particle q is binned as first_bulk + q.
  std::uint32_t first_bulk = 0;
  /// Called for every particle block after its bulk particles, with the block's padded
  /// buffer, to scatter (P2G) or gather (G2P) the other points of the block. P2G passes a
  /// box for a block without bulk particles: its buffer is then all 0 on entry, and
  /// `others` grows the box to cover every node it writes (only those are added to the
  /// grid, and zeroed again). Elsewhere box is null.
  std::function<void(std::size_t block, GridNode* buf, PadBox* box)> others;
};

/// P2G: writes grid mass and momentum including dt * internal force (grid must be binned).
void particles_to_grid(const ParticleSet& p, SparseGrid& grid, const TransferParams& tp);

/// G2P: reads grid velocities; sets v and C, advects x and updates F = (I + dt grad v) F.
void grid_to_particles(ParticleSet& p, SparseGrid& grid, const TransferParams& tp);

}  // namespace shellmpm
