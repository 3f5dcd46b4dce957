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
#include <limits>
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
  /// Per control point, while a pin holds one: the pins' impulse on its held components
  /// over the step's transfer (what the grid would have given them, made up to the pin's
  /// velocity) [N s]; empty while no pin holds.
  std::vector<Vec3> pin_impulse;
};

/// The shell points binned in front of the bulk particles: all control points of all
/// grid shells, then all their contact particles. Built once (counts never change).
class ShellPointTable {
 public:
  void build(const std::vector<GridShell>& shells);
  std::size_t size() const { return shell_.size(); }
  std::uint32_t num_control_points() const { return num_ctrl_; }
  /// Current positions in binning order (control points, then contact particles).
  void positions(const std::vector<GridShell>& shells, std::vector<Vec3>& out,
                 bool serial = false) const;
  /// Velocities in binning order: the control points', zero for contact particles (they
  /// move with them).
  void velocities(const std::vector<GridShell>& shells, std::vector<Vec3>& out) const;
  /// Shell and index in it of point i (one shell: by arithmetic, no table read).
  std::uint16_t shell(std::uint32_t i) const { return single_ ? 0 : shell_[i]; }
  std::uint32_t local(std::uint32_t i) const {
    return single_ ? (i < num_ctrl_ ? i : i - num_ctrl_) : local_[i];
  }

 private:
  std::vector<std::uint16_t> shell_;
  std::vector<std::uint32_t> local_;
  std::uint32_t num_ctrl_ = 0;
  bool single_ = false;  ///< one shell
};

/// Sets the velocity of pinned components to the pin's motion over [t, t + dt], records
/// them in g.held (released pins hold nothing) and zeroes g.pin_impulse for them. Returns
/// the pins' work in changing those velocities, m (v_new - v_old) . v_new [J].
double prescribe_pins(GridShell& g, double t, double dt);

/// The pins' work over a step's transfer, sum over held components of the impulse in
/// g.pin_impulse times the pin's velocity [J].
double pin_transfer_work(const GridShell& g);

/// A grid node's fold heights (shell_folds.cpp): the mass of one shell's control points
/// there and the least and greatest height of the node over their tangent planes, in
/// cells, along their normals turned to a fixed direction.
struct NodeHeights {
  Real m, hmin, hmax;
};
/// No mass, empty height range.
constexpr NodeHeights kNoHeights{Real(0), std::numeric_limits<Real>::max(),
                                 std::numeric_limits<Real>::lowest()};

/// A node's heights spread by this many cells or more: the shell folds there (two layers;
/// sim/contact/shell_folds.cpp). Two layers resting on each other lie 1-2 cells apart; one
/// flat layer spreads by round-off, one bent to a radius of R cells by about 2.25 / R.
constexpr Real kFoldMinRange = Real(1.0);
inline bool heights_spread(const NodeHeights& d) {
  return d.m > 0 && d.hmax - d.hmin >= kFoldMinRange;
}

/// The fold heights of a lone shell's control points, summed in the combined P2G
/// (ShellFields::begin_p2g): per combined grid block, a node's sum of w m and range of
/// fold_height over the points with w > 0. A block's nodes are set (from kNoHeights)
/// when a point first reaches one of them: where ready is 0 they are all kNoHeights.
struct FoldHeights {
  const Vec3* normal = nullptr;  ///< per control point: unit normal
  Vec3 align;                    ///< normals are turned to this direction's side
  std::vector<std::array<NodeHeights, kBlockNodes>> blocks;
  std::vector<std::uint8_t> ready;
  /// Whether some node's heights spread (heights_spread), set as the particle blocks'
  /// heights are merged: a node's mass and range only grow, so this is the same as testing
  /// every node after the P2G.
  std::atomic<bool> spread{false};
  const std::array<NodeHeights, kBlockNodes>& block(std::size_t g) const {
    static const std::array<NodeHeights, kBlockNodes> none = [] {
      std::array<NodeHeights, kBlockNodes> a;
      a.fill(kNoHeights);
      return a;
    }();
    return ready[g] ? blocks[g] : none;
  }
};

/// P2G of the control points binned in particle block b into its buffer: mass, APIC
/// momentum and dt * force, with weights w_ij; where `heights` is not null, also their
/// fold heights into heights->blocks (call colour by colour: blocks of a colour touch
/// disjoint nodes). Where box is not null, it is grown to cover the nodes written.
void shell_p2g_block(const SparseGrid& grid, const ShellPointTable& table,
                     const std::vector<GridShell>& shells, Real dt, std::size_t b, GridNode* buf,
                     FoldHeights* heights = nullptr, PadBox* box = nullptr);

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
  Real a[27];
  Real e[3][3];
  Mat3 Minv;
  bool any = false;  ///< false: no stencil node has mass (e and Minv unset)
  /// (d_n - dbar) . (Minv^T u) for all 27 nodes (g_n . u without the factor a[n]).
  void offsets_dot(const Vec3& u, Real out[27]) const {
    Vec3 q;
    for (int r = 0; r < 3; ++r) q[r] = (Minv(0, r) * u[0] + Minv(1, r) * u[1]) + Minv(2, r) * u[2];
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
/// The arithmetic of site_moments on one site per lane: F is Real (one site) or a GCC
/// vector of Reals (several sites, each lane the same operations in the same order, so
/// the same bits as one site alone). Inputs per lane: the weights w[axis][o], fx and the
/// 27 node masses; outputs a, e, the inverse moment (symmetric: minv = 00 01 02 11 12 22)
/// and asum (> 0 where any node has mass; elsewhere e and minv are not finite).
template <class F>
struct MomentLanes {
  F a[27];
  F e[3][3];
  F minv[6];
  F asum;
};
template <class F>
[[gnu::always_inline]] inline void moment_lanes(const F (&w)[3][3], const F (&fx)[3],
                                                const F (&m)[27], Real dx, MomentLanes<F>& out) {
  // Two-axis marginals of a: Aij = sum_k a, Aik = sum_j a, Ajk = sum_i a.
  F Aij[3][3], Aik[3][3], Ajk[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const F wxy = w[0][i] * w[1][j];
      F r[3];
      for (int k = 0; k < 3; ++k) {
        r[k] = wxy * (w[2][k] * m[9 * i + 3 * j + k]);
        out.a[9 * i + 3 * j + k] = r[k];
        Aik[i][k] = j == 0 ? r[k] : Aik[i][k] + r[k];
        Ajk[j][k] = i == 0 ? r[k] : Ajk[j][k] + r[k];
      }
      Aij[i][j] = (r[0] + r[1]) + r[2];
    }
  F A[3][3];  // one-axis marginals A[axis][o]
  for (int o = 0; o < 3; ++o) {
    A[0][o] = (Aij[o][0] + Aij[o][1]) + Aij[o][2];
    A[1][o] = (Aij[0][o] + Aij[1][o]) + Aij[2][o];
    A[2][o] = (Aik[0][o] + Aik[1][o]) + Aik[2][o];
  }
  const F asum = (A[0][0] + A[0][1]) + A[0][2];
  out.asum = asum;
  F(&e)[3][3] = out.e;
  for (int ax = 0; ax < 3; ++ax) {
    F d[3];
    for (int o = 0; o < 3; ++o) d[o] = dx * (Real(o) - fx[ax]);
    const F dbar = ((A[ax][0] * d[0] + A[ax][1] * d[1]) + A[ax][2] * d[2]) / asum;
    for (int o = 0; o < 3; ++o) e[ax][o] = d[o] - dbar;
  }
  // Regularised by 1e-3 of the full-stencil moment (asum dx^2 / 4) in case the nodes with
  // mass are (nearly) coplanar.
  const F reg = (Real(2.5e-4) * dx * dx) * asum;
  F M[3];
  for (int ax = 0; ax < 3; ++ax)
    M[ax] = ((reg + (A[ax][0] * e[ax][0]) * e[ax][0]) + (A[ax][1] * e[ax][1]) * e[ax][1]) +
            (A[ax][2] * e[ax][2]) * e[ax][2];
  F mxy = F{} + Real(0), mxz = mxy, myz = mxy;
  for (int p = 0; p < 3; ++p) {
    mxy = mxy + e[0][p] * ((Aij[p][0] * e[1][0] + Aij[p][1] * e[1][1]) + Aij[p][2] * e[1][2]);
    mxz = mxz + e[0][p] * ((Aik[p][0] * e[2][0] + Aik[p][1] * e[2][1]) + Aik[p][2] * e[2][2]);
    myz = myz + e[1][p] * ((Ajk[p][0] * e[2][0] + Ajk[p][1] * e[2][1]) + Ajk[p][2] * e[2][2]);
  }
  // The inverse of [[M0 mxy mxz] [mxy M1 myz] [mxz myz M2]] by cofactors.
  const F c00 = M[1] * M[2] - myz * myz, c01 = mxz * myz - mxy * M[2], c02 = mxy * myz - M[1] * mxz;
  const F inv_det = Real(1) / ((M[0] * c00 + mxy * c01) + mxz * c02);
  out.minv[0] = c00 * inv_det;
  out.minv[1] = c01 * inv_det;
  out.minv[2] = c02 * inv_det;
  out.minv[3] = (M[0] * M[2] - mxz * mxz) * inv_det;
  out.minv[4] = (mxy * mxz - M[0] * myz) * inv_det;
  out.minv[5] = (M[0] * M[1] - mxy * mxy) * inv_det;
}

/// Lane j of a MomentLanes as a SiteMoments (base from W).
template <class F>
inline void moments_of_lane(const MomentLanes<F>& L, int j, const QuadraticWeights& W,
                            SiteMoments& sm) {
  const auto lane = [j](const F& v) -> Real {
    if constexpr (sizeof(F) == sizeof(Real))
      return v;
    else
      return v[j];
  };
  for (int a = 0; a < 3; ++a) sm.base[a] = W.base[a];
  for (int n = 0; n < 27; ++n) sm.a[n] = lane(L.a[n]);
  sm.any = lane(L.asum) > 0;
  if (!sm.any) return;
  for (int a = 0; a < 3; ++a)
    for (int o = 0; o < 3; ++o) sm.e[a][o] = lane(L.e[a][o]);
  const Real m00 = lane(L.minv[0]), m01 = lane(L.minv[1]), m02 = lane(L.minv[2]),
             m11 = lane(L.minv[3]), m12 = lane(L.minv[4]), m22 = lane(L.minv[5]);
  sm.Minv << m00, m01, m02, m01, m11, m12, m02, m12, m22;
}

/// The moments of the point with weights W on a grid of spacing dx [m]. The stencil is
/// walked with for_each_stencil_node(W, block_corner, ...) (sim/mpm/apic_stencil.h);
/// mass(const StencilNode&) gives the mass of a node (>= 0). The sums are moment_lanes'
/// (site_dots_batch: the same bits for several sites at once).
template <class MassFn>
SiteMoments site_moments(const QuadraticWeights& W, Real dx, const Vec3i& block_corner,
                         MassFn mass) {
  Real m[27], w[3][3], fx[3];
  int n = 0;
  for_each_stencil_node(W, block_corner, [&](const StencilNode& nd) { m[n++] = mass(nd); });
  for (int a = 0; a < 3; ++a) {
    fx[a] = W.fx[a];
    for (int o = 0; o < 3; ++o) w[a][o] = W.w[a][o];
  }
  MomentLanes<Real> L;
  moment_lanes<Real>(w, fx, m, dx, L);
  SiteMoments sm;
  moments_of_lane(L, 0, W, sm);
  return sm;
}

constexpr int kSiteLanes = 8;
/// The inputs of up to kSiteLanes sites in lane order ([...][lane], the layout of the
/// batch's vectors): weights, fx, the 27 node masses in stencil order and a vector u.
struct SiteLaneInputs {
  alignas(32) Real w[3][3][kSiteLanes];
  alignas(32) Real fx[3][kSiteLanes];
  alignas(32) Real m[27][kSiteLanes];
  alignas(32) Real u[3][kSiteLanes];
  /// Lane j's weights and fx from W and its u (its masses go to m[k][j]).
  void set(int j, const QuadraticWeights& W, const Vec3& uj) {
    for (int a = 0; a < 3; ++a) {
      fx[a][j] = W.fx[a];
      u[a][j] = uj[a];
      for (int o = 0; o < 3; ++o) w[a][o][j] = W.w[a][o];
    }
  }
};
/// For the first n <= kSiteLanes sites of `in` at once, one per lane: out[k][j] =
/// site_moments(site j).offsets_dot(u_j)[k], or .dot(u_j)[k] when `weighted`, the same
/// bits; any[j] = its moments' `any` (out unset where false). Lanes n.. of `in` are
/// overwritten. (sim/contact/site_dots.h; the shells' transfers run its per-ISA
/// instances, shell_blocks.h.)
void site_dots_batch(SiteLaneInputs& in, int n, Real dx, bool weighted, Real (&out)[27][kSiteLanes],
                     bool (&any)[kSiteLanes]);

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
