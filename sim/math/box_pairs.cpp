#include "sim/math/box_pairs.h"

#include <algorithm>
#include <cmath>

namespace shellmpm {

std::size_t BoxPairs::prepare(const std::vector<Box>& boxes, double r, double cell, bool serial) {
  // Half the distance, and a margin for the round-off of the corners' sums: a pair just
  // within r still shares a cell.
  double extent = 0;
  for (const Box& b : boxes)
    for (double v : b)
      if (std::isfinite(v)) extent = std::max(extent, std::abs(v));
  const double half = 0.5 * r * (1 + 1e-6) + 1e-12 * extent;
  grid_.build(boxes, cell, half, serial);
  first_.resize(boxes.size());
  parallel_for_each(
      boxes.size(), 4096,
      [&](std::size_t i) {
        // TriangleGrid::build's lower corner (the same operations).
        const Vec3d lo(boxes[i][0], boxes[i][1], boxes[i][2]);
        first_[i] = lo.allFinite() ? grid_.key(grid_.cell_of(lo.array() - half)) : 0;
      },
      serial);
  return grid_.num_cells();
}

void BoxPairs::axes_at_cell(std::size_t c, const int* it, const int* end,
                            std::vector<std::uint8_t>& mask) const {
  // Keys hold 21 bits per axis, x highest (TriangleGrid::key).
  constexpr std::uint64_t kField = 0x1fffff;
  const std::uint64_t here = grid_.cell_key(c);
  mask.resize(static_cast<std::size_t>(end - it));
  for (std::size_t k = 0; it + k != end; ++k) {
    const std::uint64_t d = first_[static_cast<std::size_t>(it[k])] ^ here;
    mask[k] = static_cast<std::uint8_t>(
        ((d & (kField << 42)) == 0) | ((d & (kField << 21)) == 0) << 1 | ((d & kField) == 0) << 2);
  }
}

void BoxPairs::sort_pairs(std::vector<Eigen::Vector2i>& pairs) {
  std::sort(pairs.begin(), pairs.end(), [](const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
    return a[0] != b[0] ? a[0] < b[0] : a[1] < b[1];
  });
}

}  // namespace shellmpm
