// Shells on the MPM grid (METHOD.md, "Time step"): control points are APIC particles
// (mass, momentum and their Kirchhoff-Love forces splatted with w_ij, motion read back
// from the grid), contact particles are massless sites whose normal forces go straight
// to the grid with the kernel gradient and whose a3E is advected with the grid velocity
// gradient (supplement sec. 2).
//
// Massless nodes: a contact particle's 27 stencil nodes need not all carry mass (a node
// can be reached by the site but by no control point). Forces on such nodes would be
// lost, and their velocity (zero) would corrupt the site's velocity gradient. Both
// passes therefore use the gradient restricted to the nodes with mass and made to sum
// to zero, grad~w_i = grad w_i - w_i c / W (W, c: sums of w and grad w over those
// nodes). This is the gradient of the interpolation that gives massless nodes the
// weighted mean velocity of the others; force and velocity gradient stay consistent
// (the force is minus the energy gradient for that motion) and the force sums to zero,
// so momentum is conserved exactly.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/contact/shell_contact.h"
#include "sim/mpm/bspline.h"
#include "sim/mpm/sparse_grid.h"
#include "sim/shell/shell_object.h"

namespace shellmpm {

/// One shell whose control points live on the grid.
struct GridShell {
  ShellObject* shell = nullptr;
  ShellContact* contact = nullptr;
  std::vector<Vec3> force;          ///< control-point forces this step (no gravity) [N]
  std::vector<std::uint8_t> held;   ///< per control point: components prescribed by pins
};

/// The shell points binned in front of the bulk particles: all control points of all
/// grid shells, then all their contact particles. Built once (counts never change).
class ShellPointTable {
 public:
  void build(const std::vector<GridShell>& shells);
  std::size_t size() const { return shell_.size(); }
  std::uint32_t num_control_points() const { return num_ctrl_; }
  /// Current positions in binning order (control points, then contact particles).
  void positions(const std::vector<GridShell>& shells, std::vector<Vec3>& out) const;
  std::uint16_t shell(std::uint32_t i) const { return shell_[i]; }
  std::uint32_t local(std::uint32_t i) const { return local_[i]; }

 private:
  std::vector<std::uint16_t> shell_;
  std::vector<std::uint32_t> local_;
  std::uint32_t num_ctrl_ = 0;
};

/// Sets the velocity of pinned components to the pin's motion over [t, t + dt] and
/// records them in `held` (released pins hold nothing).
void prescribe_pins(ShellObject& sh, double t, double dt, std::vector<std::uint8_t>& held);

/// P2G of the control points binned in particle block b into its buffer: mass, APIC
/// momentum and dt * force, with weights w_ij.
void shell_p2g_block(const SparseGrid& grid, const ShellPointTable& table,
                     const std::vector<GridShell>& shells, Real dt, std::size_t b, GridNode* buf);

/// G2P for block b: control points get v, C and x += dt v (held components keep their
/// prescribed velocity); contact particles a3E <- (I + dt grad~v) a3E.
void shell_g2p_block(const SparseGrid& grid, const ShellPointTable& table,
                     std::vector<GridShell>& shells, Real dt, std::size_t b, const GridNode* buf);

/// Normal part of the contact forces, after the grid velocity update: node velocities
/// gain dt f_i / m_i with f_i = -V (grad~w_ip . a3E) dpsi/da3E (uses ShellContact::G3).
void contact_normal_forces(SparseGrid& grid, const ShellPointTable& table,
                           const std::vector<GridShell>& shells, Real dt, bool serial);

/// The 27 stencil nodes of a point with the mass-restricted, zero-sum kernel gradient
/// (world units) described above; `massive[k]` false for nodes without mass.
struct SiteStencil {
  int base[3];
  Real w[27];
  Vec3 grad[27];
  bool massive[27];
  bool any = false;  ///< false: no stencil node has mass
};
/// mass(i, j, k): mass of the node with global grid index (i, j, k).
template <class MassFn>
SiteStencil site_stencil(const SparseGrid& grid, const Vec3& x, MassFn mass) {
  SiteStencil st;
  const QuadraticWeights W(grid.grid_coord(x));
  const Real inv_dx = static_cast<Real>(1.0 / grid.dx());
  for (int a = 0; a < 3; ++a) st.base[a] = W.base[a];
  Real wsum = 0;
  Vec3 gsum = Vec3::Zero();
  int n = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k, ++n) {
        st.w[n] = W.w[0][i] * W.w[1][j] * W.w[2][k];
        st.grad[n] = inv_dx * Vec3(W.dw[0][i] * W.w[1][j] * W.w[2][k],
                                   W.w[0][i] * W.dw[1][j] * W.w[2][k],
                                   W.w[0][i] * W.w[1][j] * W.dw[2][k]);
        st.massive[n] = mass(W.base[0] + i, W.base[1] + j, W.base[2] + k) > 0;
        if (st.massive[n]) {
          wsum += st.w[n];
          gsum += st.grad[n];
        }
      }
  st.any = wsum > 0;
  if (!st.any) return st;
  const Vec3 c = gsum / wsum;
  for (n = 0; n < 27; ++n) {
    if (st.massive[n])
      st.grad[n] -= st.w[n] * c;
    else
      st.grad[n].setZero();
  }
  return st;
}

}  // namespace shellmpm
