#include "render/particle_culling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace shellmpm {

std::size_t cull_hidden_particles(RenderParticles& ps) {
  std::vector<Vec3f>& x = ps.positions;
  if (x.size() < 64 || !(ps.radius > 0.0f)) return 0;
  Vec3f lo = x[0], hi = x[0];
  for (const Vec3f& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float h = 3.0f * ps.radius;
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / h)) + 1;
  const double cells = static_cast<double>(n[0]) * n[1] * n[2];
  if (cells > static_cast<double>(1u << 27)) return 0;
  auto cell_of = [&](const Vec3f& p, int c[3]) {
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo[a]) / h)), 0, n[a] - 1);
  };
  auto inside = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < n[0] && j < n[1] && k < n[2];
  };
  auto index = [&](int i, int j, int k) {
    return (static_cast<std::size_t>(k) * n[1] + j) * n[0] + i;
  };
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(cells), 0);
  int c[3] = {0, 0, 0};
  for (const Vec3f& p : x) {
    cell_of(p, c);
    occ[index(c[0], c[1], c[2])] = 1;
  }
  // full: the cell and its 26 neighbours are occupied. Buried: the cell and its 26
  // neighbours are full.
  std::vector<std::uint8_t> full(occ.size(), 0);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (!occ[index(i, j, k)]) continue;
        bool all = true;
        for (int d = 0; d < 27 && all; ++d) {
          const int a = i + d % 3 - 1, b = j + d / 3 % 3 - 1, e = k + d / 9 - 1;
          all = inside(a, b, e) && occ[index(a, b, e)];
        }
        full[index(i, j, k)] = all;
      }
  std::size_t kept = 0;
  for (std::size_t p = 0; p < x.size(); ++p) {
    cell_of(x[p], c);
    bool buried = true;
    for (int d = 0; d < 27 && buried; ++d) {
      const int a = c[0] + d % 3 - 1, b = c[1] + d / 3 % 3 - 1, e = c[2] + d / 9 - 1;
      buried = inside(a, b, e) && full[index(a, b, e)];
    }
    if (!buried) x[kept++] = x[p];
  }
  const std::size_t removed = x.size() - kept;
  x.resize(kept);
  return removed;
}

}  // namespace shellmpm
