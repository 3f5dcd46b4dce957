#include "sim/scene/sdf_grid.h"

#include <algorithm>
#include <cmath>

namespace shellmpm {

double SdfGrid::sample(const Vec3d& p) const {
  if (values.empty()) return background;
  const Vec3d g = (p - origin) / spacing;
  double outside = 0.0;
  int base[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const double hi = dims[a] - 1;
    if (g[a] < 0) outside = std::max(outside, -g[a] * spacing);
    if (g[a] > hi) outside = std::max(outside, (g[a] - hi) * spacing);
    const double c = std::clamp(g[a], 0.0, hi);
    base[a] = std::min(static_cast<int>(std::floor(c)), std::max(dims[a] - 2, 0));
    f[a] = dims[a] > 1 ? c - base[a] : 0.0;
  }
  auto at = [&](int i, int j, int k) {
    i = std::min(i, dims.x() - 1);
    j = std::min(j, dims.y() - 1);
    k = std::min(k, dims.z() - 1);
    return static_cast<double>(values[(static_cast<size_t>(k) * dims.y() + j) * dims.x() + i]);
  };
  double v = 0;
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
        v += w * at(base[0] + di, base[1] + dj, base[2] + dk);
      }
  if (outside > 0) return std::max<double>(std::max<double>(v, 0.0) + outside, 0.0);
  return v;
}

Vec3d SdfGrid::gradient(const Vec3d& p) const {
  const double h = 0.5 * spacing;
  Vec3d g;
  for (int a = 0; a < 3; ++a) {
    Vec3d e = Vec3d::Zero();
    e[a] = h;
    g[a] = (sample(p + e) - sample(p - e)) / (2 * h);
  }
  return g;
}

}  // namespace shellmpm
