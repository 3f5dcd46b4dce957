// Patches of quadrature points for the batched float Kirchhoff-Love kernel
// (sim/shell/kl_batch_body.h): the in-plane points of one face share their control points
// (12 on a regular Loop patch), and faces of the same shape share their basis
// coefficients bit for bit (every regular interior triangle of a sheet evaluates the same
// box splines at the same parametric points). A patch is a run of `points` consecutive
// quadrature points with the same control point list; a pattern is one distinct table of
// coefficients. The kernel then reads a face's control points once for all its points,
// broadcasts the pattern's coefficients (no per-entry coefficient stream: 20 bytes per
// (point, control point) on the per-point path) and writes one force share per (face,
// control point) instead of one per (point, control point): a third of the shares to
// write and gather on a 3-point rule. Internal to sim/shell.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace shellmpm::kl {

struct Patches {
  /// Most points per patch and control points per patch the kernel takes (its stack
  /// arrays); a shell with a larger one runs point by point.
  static constexpr int kMaxPoints = 16;
  static constexpr int kMaxCtrl = 40;
  int points = 0;                      ///< points per patch; 0: the shell's points form no patches
  std::vector<std::uint32_t> order;    ///< patches by pattern, ascending within a pattern
  std::vector<std::uint32_t> pattern;  ///< per patch
  std::vector<std::uint32_t> begin;    ///< per patch: first patch entry (one per control point)
  std::vector<int> ctrl;               ///< per patch entry: its control point
  std::vector<std::uint32_t> slot;     ///< per patch entry: its slot in gather order
  std::vector<std::size_t> gather_begin;    ///< per control point: its slots [j], [j + 1])
  std::vector<std::uint32_t> pattern_size;  ///< per pattern: control points m
  std::vector<std::uint32_t> pattern_coef;  ///< per pattern: offset of its [k][c][5] table
  std::vector<float> coefs;                 ///< the tables: N1, N2, N11, N12, N22
  /// The points' rest data in lanes (lay_out_lanes): for each block of kLaneBlock
  /// positions of `order`, each point k and layer l of a patch, the four entries of B and
  /// then the area, kLaneBlock patches side by side, so that a register of the patches at
  /// positions i .. i + W - 1 of one block loads them without a transpose. Padded by
  /// kLaneBlock floats (a register that starts inside a block may read past it).
  static constexpr int kLaneBlock = 16;
  std::vector<float> B_lanes;     ///< [block][k][l][4][kLaneBlock]
  std::vector<float> area_lanes;  ///< [block][k][kLaneBlock]

  bool empty() const { return points == 0; }
  std::size_t num_patches() const { return pattern.size(); }
  std::size_t num_entries() const { return ctrl.size(); }
};

/// Patches from the per-point entries (begin[q] .. begin[q + 1] - 1: control point ctrl[e],
/// coefficients coef[5 e ..]) of nq points over num_ctrl control points. Empty (points 0)
/// unless the points split into runs of one length (at most kMaxPoints) sharing their
/// control list (at most kMaxCtrl).
Patches build_patches(const std::vector<std::size_t>& begin, const std::vector<int>& ctrl,
                      const std::vector<float>& coef, std::size_t num_ctrl);

/// Fills p.B_lanes and p.area_lanes from the per-point B (4 per (point, layer)) and area
/// of num_layers layers (positions past the last patch repeat it).
void lay_out_lanes(Patches& p, const std::vector<float>& B, const std::vector<float>& area,
                   int num_layers);

}  // namespace shellmpm::kl
