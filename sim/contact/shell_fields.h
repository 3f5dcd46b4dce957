// A velocity field per shell on grid nodes that several shells share, so that shells in
// contact slide past each other as Coulomb says (multi-field MPM, Bardenhagen et al.
// 2000).
//
// With one velocity per node, two sheets resting ~2 dx apart share the nodes between
// them and every transfer averages their velocities there: an inelastic, no-slip drag
// on top of the contact friction, which made a frictionless sheet slide at a third of
// g sin on another (README, "Contact"). Here each shell also transfers its control
// points to its own grid (mass and the same APIC momentum with its forces). At a node
// that only shells share, shell b reads its own velocity plus everything the grid update
// added there (gravity, the contact particles' normal forces):
//   v_b = v + (v_b^0 - v^0),
// v^0 and v the combined velocity before and after the update, v_b^0 = p_b / m_b. The
// shells then interact there only through the contact particles (normal elasticity and
// the Coulomb return mapping), which is what the method prescribes; sum m_b v_b = m v,
// so momentum is unchanged. Nodes with bulk material, colliders or walls keep one
// velocity, as does a shell in contact with itself.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/contact/shell_transfer.h"
#include "sim/mpm/sparse_grid.h"

namespace shellmpm {

class ShellFields {
 public:
  /// skip(node): true where a node must keep a single velocity (a collider acts on it, or
  /// a wall).
  using SkipFn = std::function<bool(const Vec3i& node)>;

  /// Grid geometry and the number of grid shells (fields are kept for two or more).
  void setup(const SparseGrid& grid, std::size_t num_shells);
  bool active() const { return grids_.size() >= 2; }

  /// Per shell: bins its control points and transfers mass and momentum m v + dt f +
  /// APIC to its own grid. Call after the combined P2G, before any
  /// control point moves.
  void p2g(const std::vector<GridShell>& shells, Real dt, bool serial);

  /// After the combined G2P: r_b = v_b^0 - v^0 at nodes only shells share, then each
  /// control point gets v += sum w r_b, x += dt sum w r_b and C += the matching APIC
  /// term (held components unchanged).
  void correct(const SparseGrid& combined, std::vector<GridShell>& shells, Real dt,
                      const SkipFn& skip, bool serial);

 private:
  struct Node {
    Real m;
    Real p[3];  ///< momentum; velocity after p2g()
  };
  struct Field {
    SparseGrid grid;  ///< binning of this shell's control points (its nodes unused)
    std::vector<std::array<Node, kPadNodes>> buf;
    std::vector<std::array<Node, kBlockNodes>> nodes;
    std::vector<std::array<Vec3, kBlockNodes>> r;  ///< relative velocity per node
    std::vector<Vec3> x0;                          ///< control points at p2g time
  };
  std::vector<Field> grids_;
};

}  // namespace shellmpm
