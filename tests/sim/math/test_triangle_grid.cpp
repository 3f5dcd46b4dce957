// TriangleGrid against its definition: a triangle is listed in every cell its padded
// bounding box overlaps; a query sees the listings of the cells its box overlaps.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "sim/core/parallel.h"
#include "sim/math/triangle_queries.h"

using namespace shellmpm;

TEST_CASE("triangle grid lists each triangle in the cells of its padded box", "[grid]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), small(-0.08, 0.08);
  // 40k small triangles (more than two counting-sort chunks of pairs), some not finite.
  std::vector<Vec3d> pos;
  std::vector<Eigen::Vector3i> tris;
  for (int t = 0; t < 40000; ++t) {
    const Vec3d c(u(rng), u(rng), 0.3 * u(rng));
    const int v = static_cast<int>(pos.size());
    for (int k = 0; k < 3; ++k) pos.push_back(c + Vec3d(small(rng), small(rng), small(rng)));
    tris.emplace_back(v, v + 1, v + 2);
  }
  pos[30] = Vec3d(std::nan(""), 0, 0);
  const double cell = 0.05, pad = 0.01;
  auto cell_of = [&](double x) { return static_cast<int>(std::floor(x / cell)); };
  TriangleGrid serial_grid, grid;
  serial_grid.build(pos, tris, cell, pad, true);
  {
    ThreadLimit lim(2);
    grid.build(pos, tris, cell, pad);
  }
  std::size_t wrong = 0, unsorted = 0, differ = 0;
  std::vector<int> got, got_serial, in_cell;
  for (int q = 0; q < 300; ++q) {
    const Vec3d lo(u(rng), u(rng), 0.3 * u(rng)), hi = lo + Vec3d(0.07, 0.03, 0.11) * (q % 3);
    grid.query_box(lo, hi, got);
    serial_grid.query_box(lo, hi, got_serial);
    differ += got != got_serial;
    std::vector<int> want;
    for (std::size_t t = 0; t < tris.size(); ++t) {
      Vec3d a = pos[tris[t][0]], b = a;
      for (int k = 1; k < 3; ++k) {
        a = a.cwiseMin(pos[tris[t][k]]);
        b = b.cwiseMax(pos[tris[t][k]]);
      }
      if (!a.allFinite()) continue;
      bool overlap = true;
      for (int d = 0; d < 3; ++d)
        overlap = overlap && cell_of(a[d] - pad) <= cell_of(hi[d]) &&
                  cell_of(lo[d]) <= cell_of(b[d] + pad);
      if (overlap) want.push_back(static_cast<int>(t));
    }
    wrong += got != want;
    // One cell's listing: ascending, each triangle once.
    in_cell.clear();
    grid.for_each_in_box(lo, lo, [&](int t) { in_cell.push_back(t); });
    for (std::size_t i = 1; i < in_cell.size(); ++i) unsorted += in_cell[i] <= in_cell[i - 1];
  }
  CHECK(wrong == 0);
  CHECK(differ == 0);
  CHECK(unsorted == 0);
  // The damaged triangle is nowhere.
  grid.query_box(Vec3d::Constant(-2), Vec3d::Constant(2), got);
  CHECK(std::find(got.begin(), got.end(), 10) == got.end());
  CHECK(got.size() == tris.size() - 1);
}
