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
// pair stays energy-consistent (tests/sim/contact/test_contact_grid.cpp checks it).
#pragma once
#include <cstdint>
#include <cstring>
#include <vector>

#include "sim/contact/shell_contact.h"
#include "sim/mpm/apic_stencil.h"
#include "sim/mpm/bspline.h"
#include "sim/mpm/sparse_grid.h"
#include "sim/shell/shell_object.h"

namespace shellmpm {

/// One shell whose control points live on the grid.
struct GridShell {
  ShellObject* shell = nullptr;
  ShellContact* contact = nullptr;
  std::vector<Vec3> force;         ///< control-point forces this step (no gravity) [N]
  std::vector<std::uint8_t> held;  ///< per control point: components prescribed by pins
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
  /// Velocities in binning order: the control points', zero for contact particles (they
  /// move with them).
  void velocities(const std::vector<GridShell>& shells, std::vector<Vec3>& out) const;
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

/// The moments behind the gradient weights of a point's 27 stencil nodes (node
/// n = 9 i + 3 j + k): a[n] = w_n m_n (0 for nodes without mass), the centred offsets per
/// axis e[axis][o] = dx (o - fx) - dbar (world units, so d_n - dbar = (e[0][i], e[1][j],
/// e[2][k])) and Minv = M^-1; g_n = a[n] Minv (d_n - dbar). M is built from the marginal
/// sums of a over the stencil (the offsets are separable), which is the same sum as the
/// 27 outer products up to round-off.
struct SiteMoments {
  int base[3];
  Real a[28];  ///< a[27]: scratch (the rows are written four scalars at a time)
  Real e[3][3];
  Mat3 Minv;
  bool any = false;  ///< false: no stencil node has mass (e and Minv unset)
  /// (d_n - dbar) . (Minv^T u) for all 27 nodes (g_n . u without the factor a[n]).
  void offsets_dot(const Vec3& u, Real out[27]) const {
    const Vec3 q = Minv.transpose() * u;
    int n = 0;
    for (int i = 0; i < 3; ++i) {
      const Real si = e[0][i] * q[0];
      for (int j = 0; j < 3; ++j) {
        const Real sij = si + e[1][j] * q[1];
        for (int k = 0; k < 3; ++k, ++n) out[n] = sij + e[2][k] * q[2];
      }
    }
  }
  /// g_n . u for all 27 nodes: a[n] (d_n - dbar) . (Minv^T u).
  void dot(const Vec3& u, Real out[27]) const {
    offsets_dot(u, out);
    for (int n = 0; n < 27; ++n) out[n] = a[n] * out[n];
  }
};
/// The moments of the point with weights W on a grid of spacing dx [m]. The stencil is
/// walked with for_each_stencil_node(W, block_corner, ...) (sim/mpm/apic_stencil.h);
/// mass(const StencilNode&) gives the mass of a node (>= 0). The sums run on the stencil's
/// nine rows along z as short vectors: a row's a = (wx wy) (wz m), its marginals added
/// row by row.
template <class MassFn>
SiteMoments site_moments(const QuadraticWeights& W, Real dx, const Vec3i& block_corner,
                         MassFn mass) {
  typedef Real R4 __attribute__((vector_size(4 * sizeof(Real))));
  SiteMoments sm;
  for (int a = 0; a < 3; ++a) sm.base[a] = W.base[a];
  Real m[28];
  m[27] = 0;
  int n = 0;
  for_each_stencil_node(W, block_corner, [&](const StencilNode& nd) { m[n++] = mass(nd); });
  const R4 wz = {W.w[2][0], W.w[2][1], W.w[2][2], Real(0)};
  // Two-axis marginals of a: Aij = sum_k a, Aik = sum_j a, Ajk = sum_i a (rows over k).
  Real Aij[3][3];
  R4 Aik[3] = {}, Ajk[3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      R4 mr;
      std::memcpy(&mr, &m[9 * i + 3 * j], sizeof mr);
      mr[3] = 0;
      const R4 ar = (W.w[0][i] * W.w[1][j]) * (wz * mr);
      std::memcpy(&sm.a[9 * i + 3 * j], &ar, sizeof ar);
      Aij[i][j] = (ar[0] + ar[1]) + ar[2];
      Aik[i] += ar;
      Ajk[j] += ar;
    }
  Real A[3][3];  // one-axis marginals A[axis][o]
  const R4 Az = (Aik[0] + Aik[1]) + Aik[2];
  for (int o = 0; o < 3; ++o) {
    A[0][o] = Aij[o][0] + Aij[o][1] + Aij[o][2];
    A[1][o] = Aij[0][o] + Aij[1][o] + Aij[2][o];
    A[2][o] = Az[o];
  }
  const Real asum = A[0][0] + A[0][1] + A[0][2];
  sm.any = asum > 0;
  if (!sm.any) return sm;
  for (int ax = 0; ax < 3; ++ax) {
    Real d[3];
    for (int o = 0; o < 3; ++o) d[o] = dx * (Real(o) - W.fx[ax]);
    const Real dbar = (A[ax][0] * d[0] + A[ax][1] * d[1] + A[ax][2] * d[2]) / asum;
    for (int o = 0; o < 3; ++o) sm.e[ax][o] = d[o] - dbar;
  }
  // Regularised by 1e-3 of the full-stencil moment (asum dx^2 / 4) in case the nodes with
  // mass are (nearly) coplanar.
  const Real reg = Real(2.5e-4) * asum * dx * dx;
  Mat3 M;
  for (int ax = 0; ax < 3; ++ax)
    M(ax, ax) = reg + A[ax][0] * sm.e[ax][0] * sm.e[ax][0] + A[ax][1] * sm.e[ax][1] * sm.e[ax][1] +
                A[ax][2] * sm.e[ax][2] * sm.e[ax][2];
  const R4 ez = {sm.e[2][0], sm.e[2][1], sm.e[2][2], Real(0)};
  Real mxy = 0, mxz = 0, myz = 0;
  for (int p = 0; p < 3; ++p) {
    for (int r = 0; r < 3; ++r) mxy += Aij[p][r] * sm.e[0][p] * sm.e[1][r];
    const R4 xz = Aik[p] * ez, yz = Ajk[p] * ez;
    mxz += sm.e[0][p] * ((xz[0] + xz[1]) + xz[2]);
    myz += sm.e[1][p] * ((yz[0] + yz[1]) + yz[2]);
  }
  M(0, 1) = M(1, 0) = mxy;
  M(0, 2) = M(2, 0) = mxz;
  M(1, 2) = M(2, 1) = myz;
  sm.Minv = M.inverse();
  return sm;
}

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
  const QuadraticWeights W(grid.grid_coord(x));
  const Vec3i base(W.base[0], W.base[1], W.base[2]);
  const SiteMoments sm = site_moments(
      W, static_cast<Real>(grid.dx()), base,
      [&](const StencilNode& n) { return mass(base[0] + n.i, base[1] + n.j, base[2] + n.k); });
  SiteStencil st;
  for (int a = 0; a < 3; ++a) st.base[a] = sm.base[a];
  int at = 0;
  for_each_stencil_node(W, base, [&](const StencilNode& nd) {
    st.w[at] = nd.w;
    st.massive[at++] = mass(base[0] + nd.i, base[1] + nd.j, base[2] + nd.k) > 0;
  });
  st.any = sm.any;
  if (!st.any) {
    for (int n = 0; n < 27; ++n) st.grad[n].setZero();
    return st;
  }
  // Minv (d_n - dbar) = e[0][i] Minv.col(0) + e[1][j] Minv.col(1) + e[2][k] Minv.col(2).
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 ci = sm.e[0][i] * sm.Minv.col(0);
    for (int j = 0; j < 3; ++j) {
      const Vec3 cij = ci + sm.e[1][j] * sm.Minv.col(1);
      for (int k = 0; k < 3; ++k, ++n)
        st.grad[n] =
            sm.a[n] > 0 ? Vec3(sm.a[n] * (cij + sm.e[2][k] * sm.Minv.col(2))) : Vec3::Zero();
    }
  }
  return st;
}

}  // namespace shellmpm
