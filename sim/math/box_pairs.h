// Pairs of axis-aligned boxes that come within a distance of each other on every axis,
// found cell by cell in a uniform grid rather than by a walk per box: the shell guard's
// edge-edge search. Each box is listed in the cells its box grown by half the distance
// (and a margin for round-off) overlaps, so two boxes within the distance share a cell,
// and each pair is taken in exactly one of the cells it shares: on each axis, the larger
// of its boxes' first cells. No hash lookup per query and no marks per visit.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "sim/core/parallel.h"
#include "sim/math/triangle_queries.h"

namespace shellmpm {

class BoxPairs {
 public:
  using Box = std::array<double, 6>;  ///< lo x, y, z, hi x, y, z

  /// The pairs a < b of `boxes` with, on each axis, b.lo - a.hi < r and a.lo - b.hi < r
  /// (in these operations; a box with a non-finite corner is in none) for which
  /// keep(a, b) is true (called on the threads, once per such pair), sorted by (a, b): the
  /// same on any thread count. cell: the grid's side [m] (about a box's size plus r).
  template <class Keep>
  std::vector<Eigen::Vector2i> find(const std::vector<Box>& boxes, double r, double cell,
                                    bool serial, const Keep& keep) {
    const auto n = prepare(boxes, r, cell, serial);
    struct Part {
      std::vector<std::uint8_t> mask;
      std::vector<Eigen::Vector2i> out;
    };
    const auto parts =
        chunk_parts(n, 256, serial, Part(), [&](std::size_t c0, std::size_t c1, Part& part) {
          for (std::size_t c = c0; c < c1; ++c) {
            const int *it = grid_.cell_begin(c), *end = grid_.cell_end(c);
            axes_at_cell(c, it, end, part.mask);
            const std::size_t m = static_cast<std::size_t>(end - it);
            for (std::size_t i = 0; i < m; ++i) {
              const std::uint8_t need = static_cast<std::uint8_t>(7 & ~part.mask[i]);
              const Box& A = boxes[static_cast<std::size_t>(it[i])];
              for (std::size_t j = i + 1; j < m; ++j) {       // a cell lists its boxes ascending
                if ((part.mask[j] & need) != need) continue;  // taken in another cell
                const Box& B = boxes[static_cast<std::size_t>(it[j])];
                if (B[0] - A[3] >= r || A[0] - B[3] >= r || B[1] - A[4] >= r || A[1] - B[4] >= r ||
                    B[2] - A[5] >= r || A[2] - B[5] >= r)
                  continue;
                if (keep(it[i], it[j])) part.out.emplace_back(it[i], it[j]);
              }
            }
          }
        });
    std::vector<Eigen::Vector2i> pairs;
    for (const Part& part : parts) pairs.insert(pairs.end(), part.out.begin(), part.out.end());
    sort_pairs(pairs);
    return pairs;
  }

 private:
  /// Bins the boxes; returns the number of cells.
  std::size_t prepare(const std::vector<Box>& boxes, double r, double cell, bool serial);
  /// Per box of cell c's list [it, end), the axes on which its first cell is c's (bits 0,
  /// 1, 2 for x, y, z).
  void axes_at_cell(std::size_t c, const int* it, const int* end,
                    std::vector<std::uint8_t>& mask) const;
  static void sort_pairs(std::vector<Eigen::Vector2i>& pairs);

  TriangleGrid grid_;
  std::vector<std::uint64_t> first_;  ///< per box, the key of its first cell
};

}  // namespace shellmpm
