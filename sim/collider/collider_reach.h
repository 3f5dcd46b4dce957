// Which nodes take a collider's boundary condition (collider.h). A node inside a collider
// stands for the material within 1.5 dx of it, not for a point of its own. A 0.5 mm steel
// sheet 1 cm below a ball shares the nodes the ball already covers at dx 2 cm; the
// condition, applied to those nodes every step, handed the sheet a share of the ball's
// velocity every step, so the ball dragged the sheet before it touched it, by an amount
// that grew as the step shrank (the struck sheet's plastic work 13.9, 18.3 and 22.5 J at
// CFL 0.5, 0.25 and 0.125), and a backward Euler step, which lets the free nodes move
// against it, saw a different contact again.
//
// So a node takes collider k's condition only when, besides lying inside it, some binned
// point whose stencil covers the node (a bulk particle, a shell control point, a contact
// particle) lies within `reach` of the collider in its pose at the end of the step, at the
// step's start or where its velocity takes it by the end: the contact is where the
// material is, at any step size. Points pushed into a collider in
// one step are put back on its surface by the particle projection (particle_projection.h)
// and then engage their nodes, so material rests on a collider with a gap below reach,
// where it rested about a cell away before.
//
// The marks are ORs of per-particle-block buffers, so they do not depend on the thread
// count.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/mpm/sparse_grid.h"

namespace shellmpm {

/// Fraction of dx within which a point engages its nodes' collider conditions.
constexpr double kColliderReachCells = 0.1;
/// Shell points with contact at the surfaces (given offsets) engage within this share of
/// the reach past their contact surface: their look-ahead by the step's motion catches
/// them before they pass it, and they rest within 0.02 dx of it.
constexpr double kSurfaceReachShare = 0.2;

class ColliderReach {
 public:
  /// Marks the nodes of `grid` (binned from the concatenation of `first`, which may be
  /// null, and `x`, as SparseGrid::bin) whose points come within reach [m] of each
  /// collider (begin_step already called) at the start of the step or where their
  /// velocities (first_v, v, alongside) take them by its end, x + dt v. first_offset
  /// (may be null): per point of `first`, how far out its contact surface lies [m] (half a
  /// shell's contact thickness): it reaches that much further.
  void compute(const SparseGrid& grid, const std::vector<Vec3>* first,
               const std::vector<Vec3>* first_v, const std::vector<Vec3>& x,
               const std::vector<Vec3>& v, const std::vector<Collider>& colliders, double reach,
               double dt, bool serial, const std::vector<Real>* first_offset = nullptr);
  /// Whether node n of grid block g takes collider k's condition. Colliders past the
  /// 32nd, and every collider before compute, always do.
  bool engaged(std::size_t g, int n, std::size_t k) const {
    if (k >= 32 || !computed_) return true;
    const std::uint32_t s = slot_[g];
    if (s == kNone) return false;
    return (mask_[std::size_t(s) * kBlockNodes + static_cast<std::size_t>(n)] >> k) & 1u;
  }
  /// Nodes that take some collider's condition (for tests and statistics).
  std::size_t count() const;

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  bool computed_ = false;
  /// Per grid block, where its nodes' marks are in mask_ (kBlockNodes from
  /// slot * kBlockNodes), or kNone: no point of a block it gathers from came near.
  std::vector<std::uint32_t> slot_;
  std::vector<std::uint32_t> mask_;
  std::vector<std::array<std::uint32_t, kPadNodes>> buf_;
  std::vector<std::uint8_t> touched_;  ///< per particle block: buf_ holds a mark
};

}  // namespace shellmpm
