// The one quadratic B-spline stencil every transfer uses: a point's 3x3x3 nodes in its
// particle block's padded buffer (sim/mpm/sparse_grid.h), the APIC/MLS scatter of mass and
// momentum (with the APIC stress term), and the gather of velocity, its affine matrix B
// and its gradient. Bulk particles (sim/mpm/transfer.cpp), shell control points
// (sim/contact/shell_transfer.cpp) and the per-body fields (sim/contact/shell_fields.cpp,
// shell_folds.cpp) all go through here.
//
// The node loops factor the tensor-product sums: with d = node - fx (grid units),
// A d = (A (-fx)) + A.col(0) i + A.col(1) j + A.col(2) k, and the kernel gradient
// (dwx wy wz, wx dwy wz, wx wy dwz) splits into per-axis factors, so the innermost loop
// does a few vector FMAs per node.
#pragma once
#include "sim/core/types.h"
#include "sim/mpm/bspline.h"
#include "sim/mpm/sparse_grid.h"

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
template <bool kStress>
inline void apic_scatter(GridNode* buf, const QuadraticWeights& W, const Vec3i& block_corner,
                         Real m, const Vec3& base, const Mat3& A, const Mat3& S) {
  const int lx = W.base[0] - block_corner[0], ly = W.base[1] - block_corner[1],
            lz = W.base[2] - block_corner[2];
  for (int i = 0; i < 3; ++i) {
    const Vec3 bi = base + Real(i) * A.col(0);
    Vec3 s0i, s12i, s2i;
    if constexpr (kStress) {
      s0i = W.dw[0][i] * S.col(0);
      s12i = W.w[0][i] * S.col(1);
      s2i = W.w[0][i] * S.col(2);
    }
    for (int j = 0; j < 3; ++j) {
      const Vec3 bij = bi + Real(j) * A.col(1);
      const Real wxy = W.w[0][i] * W.w[1][j];
      // Force factors: S gw = (s0i wy + s12i dwy) wz + (s2i wy) dwz.
      Vec3 fz, fdz;
      if constexpr (kStress) {
        fz = W.w[1][j] * s0i + W.dw[1][j] * s12i;
        fdz = W.w[1][j] * s2i;
      }
      GridNode* row = &buf[pad_node(lx + i, ly + j, lz)];
      for (int k = 0; k < 3; ++k) {
        const Real w = wxy * W.w[2][k];
        Vec3 mom = w * (bij + Real(k) * A.col(2));
        if constexpr (kStress) mom -= W.w[2][k] * fz + W.dw[2][k] * fdz;
        GridNode& nd = row[k];
        nd.m += w * m;
        nd.v[0] += mom[0];
        nd.v[1] += mom[1];
        nd.v[2] += mom[2];
      }
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

template <bool kGrad>
inline ApicGather apic_gather(const GridNode* buf, const QuadraticWeights& W,
                              const Vec3i& block_corner) {
  const int lx = W.base[0] - block_corner[0], ly = W.base[1] - block_corner[1],
            lz = W.base[2] - block_corner[2];
  // Sums over nodes of w v, w v i, w v j, w v k and the gradient sums, built per axis.
  Vec3 v = Vec3::Zero(), vi_sum = Vec3::Zero(), vj_sum = Vec3::Zero(), vk_sum = Vec3::Zero();
  Vec3 gx = Vec3::Zero(), gy = Vec3::Zero(), gz = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    Vec3 P = Vec3::Zero(), Pj = Vec3::Zero(), Pk = Vec3::Zero(), Gy = Vec3::Zero(),
         Gz = Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      const GridNode* row = &buf[pad_node(lx + i, ly + j, lz)];
      Vec3 Q = Vec3::Zero(), Qk = Vec3::Zero(), Qdz = Vec3::Zero();
      for (int k = 0; k < 3; ++k) {
        const Vec3 vn(row[k].v[0], row[k].v[1], row[k].v[2]);
        const Vec3 wv = W.w[2][k] * vn;
        Q += wv;
        Qk += Real(k) * wv;
        if constexpr (kGrad) Qdz += W.dw[2][k] * vn;
      }
      P += W.w[1][j] * Q;
      Pj += (W.w[1][j] * Real(j)) * Q;
      Pk += W.w[1][j] * Qk;
      if constexpr (kGrad) {
        Gy += W.dw[1][j] * Q;
        Gz += W.w[1][j] * Qdz;
      }
    }
    v += W.w[0][i] * P;
    vi_sum += (W.w[0][i] * Real(i)) * P;
    vj_sum += W.w[0][i] * Pj;
    vk_sum += W.w[0][i] * Pk;
    if constexpr (kGrad) {
      gx += W.dw[0][i] * P;
      gy += W.w[0][i] * Gy;
      gz += W.w[0][i] * Gz;
    }
  }
  ApicGather out;
  out.v = v;
  out.B.col(0) = vi_sum - W.fx[0] * v;
  out.B.col(1) = vj_sum - W.fx[1] * v;
  out.B.col(2) = vk_sum - W.fx[2] * v;
  if constexpr (kGrad) {
    out.grad.col(0) = gx;
    out.grad.col(1) = gy;
    out.grad.col(2) = gz;
  }
  return out;
}

}  // namespace shellmpm
