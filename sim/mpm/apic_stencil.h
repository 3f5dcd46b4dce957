// The one quadratic B-spline stencil every transfer uses: a point's 3x3x3 nodes in its
// particle block's padded buffer (sim/mpm/sparse_grid.h), the APIC/MLS scatter of mass and
// momentum (with the APIC stress term), and the gather of velocity, its affine matrix B
// and its gradient. Bulk particles (sim/mpm/transfer.cpp), shell control points
// (sim/contact/shell_transfer.cpp) and the per-body fields (sim/contact/shell_fields.cpp,
// shell_folds.cpp) all go through here.
//
// The node loops factor the tensor-product sums: with d = node - fx (grid units),
// A d = (A (-fx)) + A.col(0) i + A.col(1) j + A.col(2) k, and the kernel gradient
// (dwx wy wz, wx dwy wz, wx wy dwz) splits into per-axis factors. The z axis lives in the
// lanes of a row vector (sim/mpm/stencil_row.h: the three nodes along z at once), so each
// of the nine rows costs a few vector operations.
#pragma once
#include "sim/core/types.h"
#include "sim/mpm/bspline.h"
#include "sim/mpm/sparse_grid.h"
#include "sim/mpm/stencil_row.h"

namespace shellmpm {

/// One node of a point's stencil: its coordinates in the padded buffer of the point's
/// particle block, its offset (i, j, k) from QuadraticWeights::base, and its weight.
struct StencilNode {
  int px, py, pz;  ///< padded-buffer coordinates, in [0, kPadSize)
  int i, j, k;     ///< offset from W.base, in [0, 3)
  Real w;          ///< wx wy wz
  int pad() const { return pad_node(px, py, pz); }
};

/// Calls f(StencilNode) for the 27 nodes of the point with weights W, in the padded buffer
/// of the particle block whose first node is `block_corner` (its key times kBlockSize).
template <class F>
inline void for_each_stencil_node(const QuadraticWeights& W, const Vec3i& block_corner, F&& f) {
  const int lx = W.base[0] - block_corner[0], ly = W.base[1] - block_corner[1],
            lz = W.base[2] - block_corner[2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        f(StencilNode{lx + i, ly + j, lz + k, i, j, k, W.w[0][i] * W.w[1][j] * W.w[2][k]});
}

/// Scatters one point's mass m and momentum into the buffer: node n gets m w_n and
/// w_n (base + A (n - fx)) - S grad w_n (kStress), where `base` already holds
/// m v - A fx (plus any impulse), A is the affine term in grid units (m dx C, MLS: minus the
/// stress term) and S the APIC stress term dt V0 tau / dx.
///
/// With the z factors in the lanes of a row vector (WZ, DWZ, K = k), node (i, j, k) is
///   wx wy [WZ (mb + K a2) - DWZ s2] + i wx wy WZ a0 + j wx wy WZ a1 - dwx wy WZ s0
///   - wx dwy WZ s1,
/// mb = (m, base), a_c = (0, A.col(c)), s_c = (0, S.col(c)): per row two products and a
/// difference.
template <bool kStress>
inline void apic_scatter(GridNode* buf, const QuadraticWeights& W, const Vec3i& block_corner,
                         Real m, const Vec3& base, const Mat3& A, const Mat3& S) {
  const int lx = W.base[0] - block_corner[0], ly = W.base[1] - block_corner[1],
            lz = W.base[2] - block_corner[2];
  using namespace stencil_row;
  const Real ks[3] = {0, 1, 2};
  const Row wz = per_node(W.w[2]);
  Row p0 = wz * (splat(m, base) + per_node(ks) * splat(0, A.col(2)));
  const Row pa0 = wz * splat(0, A.col(0)), pa1 = wz * splat(0, A.col(1));
  Row ps0 = zero(), ps1 = zero();
  if constexpr (kStress) {
    p0 = p0 - per_node(W.dw[2]) * splat(0, S.col(2));
    ps0 = wz * splat(0, S.col(0));
    ps1 = wz * splat(0, S.col(1));
  }
  for (int i = 0; i < 3; ++i) {
    Row xi = W.w[0][i] * (p0 + Real(i) * pa0);
    Row yi = zero();
    if constexpr (kStress) {
      xi = xi - W.dw[0][i] * ps0;
      yi = W.w[0][i] * ps1;
    }
    const Row ai = W.w[0][i] * pa1;
    for (int j = 0; j < 3; ++j) {
      Row add = W.w[1][j] * (xi + Real(j) * ai);
      if constexpr (kStress) add = add - W.dw[1][j] * yi;
      GridNode* row = &buf[pad_node(lx + i, ly + j, lz)];
      store(row, load(row) + add);
    }
  }
}

/// What a point reads back from its nodes: v = sum w_n v_n, B = sum w_n v_n (n - fx)^T
/// (grid units) and, with kGrad, the kernel-gradient sum sum v_n (grad w_n)^T in grid units
/// (columns; divide by dx for world).
struct ApicGather {
  Vec3 v;
  Mat3 B;
  Mat3 grad;  ///< only with kGrad
};

/// The sums run over rows first (weights of x and y), with the z weights applied to the
/// lanes at the end.
template <bool kGrad>
inline ApicGather apic_gather(const GridNode* buf, const QuadraticWeights& W,
                              const Vec3i& block_corner) {
  const int lx = W.base[0] - block_corner[0], ly = W.base[1] - block_corner[1],
            lz = W.base[2] - block_corner[2];
  using namespace stencil_row;
  Row v = zero(), vi = zero(), vj = zero(), gx = zero(), gy = zero();
  for (int i = 0; i < 3; ++i) {
    Row P = zero(), Pj = zero(), Gy = zero();
    for (int j = 0; j < 3; ++j) {
      const Row r = load(&buf[pad_node(lx + i, ly + j, lz)]);
      P = P + W.w[1][j] * r;
      Pj = Pj + (W.w[1][j] * Real(j)) * r;
      if constexpr (kGrad) Gy = Gy + W.dw[1][j] * r;
    }
    v = v + W.w[0][i] * P;
    vi = vi + (W.w[0][i] * Real(i)) * P;
    vj = vj + W.w[0][i] * Pj;
    if constexpr (kGrad) {
      gx = gx + W.dw[0][i] * P;
      gy = gy + W.w[0][i] * Gy;
    }
  }
  const Real ks[3] = {0, 1, 2};
  const Row wz = per_node(W.w[2]);
  // Lane 0 of each node sum is the (unused) mass; 1..3 the velocity components.
  alignas(16) Real sv[4], si[4], sj[4], sk[4];
  node_sum(wz * v, sv);
  node_sum(wz * vi, si);
  node_sum(wz * vj, sj);
  node_sum((wz * per_node(ks)) * v, sk);
  ApicGather out;
  for (int c = 0; c < 3; ++c) {
    out.v[c] = sv[c + 1];
    out.B(c, 0) = si[c + 1] - W.fx[0] * sv[c + 1];
    out.B(c, 1) = sj[c + 1] - W.fx[1] * sv[c + 1];
    out.B(c, 2) = sk[c + 1] - W.fx[2] * sv[c + 1];
  }
  if constexpr (kGrad) {
    alignas(16) Real gxs[4], gys[4], gzs[4];
    node_sum(wz * gx, gxs);
    node_sum(wz * gy, gys);
    node_sum(per_node(W.dw[2]) * v, gzs);
    for (int c = 0; c < 3; ++c) {
      out.grad(c, 0) = gxs[c + 1];
      out.grad(c, 1) = gys[c + 1];
      out.grad(c, 2) = gzs[c + 1];
    }
  }
  return out;
}

}  // namespace shellmpm
