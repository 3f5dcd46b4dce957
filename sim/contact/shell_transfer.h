// Shells on the MPM grid (METHOD.md, "Time step"): control points are APIC particles
// (mass, momentum and their Kirchhoff-Love forces splatted with w_ij, motion read back
// from the grid), contact particles are massless sites whose normal forces go straight
// to the grid with the kernel gradient and whose a3E is advected with the grid velocity
// gradient (supplement sec. 2).
//
// The velocity gradient at a contact particle (which has no mass) and the matching
// normal force use a mass-weighted least-squares gradient over the particle's 27 stencil
// nodes: with a_i = w_ip m_i, d_i = x_i - x_p, dbar = sum a_i d_i / sum a_i and
// M = sum a_i (d_i - dbar)(d_i - dbar)^T, grad v = sum_i v_i (x) g_i, g_i = a_i M^-1 (d_i - dbar).
// It is exact for linear velocity fields, equals the APIC gradient B D^-1 when all nodes
// carry equal mass, sums to zero (the force conserves momentum) and gives nodes with
// little mass little weight: the velocity change dt f_i / m_i = -dt V w_ip
// (M^-1 (d_i - dbar) . a3E) dpsi/da3E does not grow as m_i -> 0 (a plain kernel gradient
// would, when a node is reached by a light neighbour's tail only). The force is minus the
// gradient of the contact energy for the motion a3E <- (I + sum u_i (x) g_i) a3E, so the
// pair stays energy-consistent (tests/sim/test_contact_grid.cpp checks it).
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

/// The 27 stencil nodes of a point with the mass-weighted gradient weights g_i described
/// above (world units, 1/m); `massive[k]` false for nodes without mass (g = 0 there).
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
  const Real dx = static_cast<Real>(grid.dx());
  for (int a = 0; a < 3; ++a) st.base[a] = W.base[a];
  Real a[27];
  Vec3 d[27];
  Real asum = 0;
  Vec3 dsum = Vec3::Zero();
  int n = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k, ++n) {
        st.w[n] = W.w[0][i] * W.w[1][j] * W.w[2][k];
        d[n] = dx * Vec3(Real(i) - W.fx[0], Real(j) - W.fx[1], Real(k) - W.fx[2]);
        const Real m = mass(W.base[0] + i, W.base[1] + j, W.base[2] + k);
        st.massive[n] = m > 0;
        a[n] = st.massive[n] ? st.w[n] * m : Real(0);
        asum += a[n];
        dsum += a[n] * d[n];
      }
  st.any = asum > 0;
  if (!st.any) {
    for (n = 0; n < 27; ++n) st.grad[n].setZero();
    return st;
  }
  const Vec3 dbar = dsum / asum;
  // Regularised by 1e-3 of the full-stencil moment (asum dx^2 / 4) in case the nodes with
  // mass are (nearly) coplanar.
  Mat3 M = (Real(2.5e-4) * asum * dx * dx) * Mat3::Identity();
  for (n = 0; n < 27; ++n)
    if (a[n] > 0) M += a[n] * (d[n] - dbar) * (d[n] - dbar).transpose();
  const Mat3 Minv = M.inverse();
  for (n = 0; n < 27; ++n) st.grad[n] = a[n] > 0 ? Vec3(a[n] * (Minv * (d[n] - dbar))) : Vec3::Zero();
  return st;
}

}  // namespace shellmpm
