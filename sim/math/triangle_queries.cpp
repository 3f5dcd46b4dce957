#include "sim/math/triangle_queries.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "sim/core/parallel.h"

namespace shellmpm {

Vec3d closest_point_barycentric(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) return {1, 0, 0};  // degenerate triangle
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

Eigen::Vector2d closest_segment_params(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0,
                                       const Vec3d& q1) {
  const Vec3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double tiny = 1e-300;
  if (a <= tiny && e <= tiny) return {0, 0};
  if (a <= tiny) return {0, std::clamp(f / e, 0.0, 1.0)};
  const double c = d1.dot(r);
  if (e <= tiny) return {std::clamp(-c / a, 0.0, 1.0), 0};
  const double b = d1.dot(d2), denom = a * e - b * b;
  // Parallel segments (denom ~ 0): any s; take 0.
  double s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0) {
    t = 0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1) {
    t = 1;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return {s, t};
}

bool segment_crosses_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b,
                              const Vec3d& c) {
  const Vec3d d = q - p, e1 = b - a, e2 = c - a;
  const Vec3d h = d.cross(e2);
  const double det = e1.dot(h);
  const double scale = e1.norm() * e2.norm() * d.norm();
  if (!(std::abs(det) > 1e-12 * scale)) return false;  // parallel (or degenerate)
  const double inv = 1.0 / det;
  const Vec3d s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return false;
  const Vec3d qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0 || u + v > 1) return false;
  const double t = inv * e2.dot(qv);
  return t >= 0 && t <= 1;
}

std::uint64_t TriangleGrid::key(const Vec3i& c) const {
  // 21 bits per axis, offset so negative cells stay distinct.
  const auto u = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffff; };
  return (u(c[0]) << 42) | (u(c[1]) << 21) | u(c[2]);
}

Vec3i TriangleGrid::cell_of(const Vec3d& p) const {
  Vec3i c;
  for (int a = 0; a < 3; ++a) c[a] = static_cast<int>(std::floor(p[a] * inv_cell_));
  return c;
}

template <class BoxOf>
void TriangleGrid::build_impl(std::size_t nt, const BoxOf& box_of, double cell, double pad,
                              bool serial) {
  inv_cell_ = 1.0 / cell;
  // Each item's cells (none for a non-finite box), counted, then listed at its offset.
  auto cells_of = [&](std::size_t t, Vec3i& c0, Vec3i& c1) {
    Vec3d lo, hi;
    box_of(t, lo, hi);
    if (!lo.allFinite() || !hi.allFinite()) return false;
    c0 = cell_of(lo.array() - pad);
    c1 = cell_of(hi.array() + pad);
    return true;
  };
  std::vector<std::size_t> start(nt + 1, 0);
  parallel_for_each(
      nt, 4096,
      [&](std::size_t t) {
        Vec3i c0, c1;
        if (cells_of(t, c0, c1))
          start[t + 1] = static_cast<std::size_t>(c1[0] - c0[0] + 1) *
                         static_cast<std::size_t>(c1[1] - c0[1] + 1) *
                         static_cast<std::size_t>(c1[2] - c0[2] + 1);
      },
      serial);
  for (std::size_t t = 0; t < nt; ++t) start[t + 1] += start[t];
  pairs_.resize(start[nt]);
  parallel_for_each(
      nt, 4096,
      [&](std::size_t t) {
        Vec3i c0, c1;
        if (!cells_of(t, c0, c1)) return;
        std::size_t at = start[t];
        for (int i = c0[0]; i <= c1[0]; ++i)
          for (int j = c0[1]; j <= c1[1]; ++j)
            for (int k = c0[2]; k <= c1[2]; ++k)
              pairs_[at++] = {key(Vec3i(i, j, k)), static_cast<int>(t)};
      },
      serial);
  // A stable counting sort by cell, cells numbered by first appearance: per chunk of
  // pairs its distinct cells and their counts (in parallel), the cells' numbers and each
  // chunk's first slot per cell (once per distinct cell of a chunk), then the triangles
  // into place (in parallel). The pairs are in triangle order, so each cell lists its
  // triangles ascending, for any thread count.
  const std::size_t np = pairs_.size(), nc = (np + kChunk - 1) / kChunk;
  chunk_keys_.resize(nc);
  if (chunk_slots_.size() < nc) chunk_slots_.resize(nc);
  pair_cell_.resize(np);
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        chunk_keys_.begin_chunk(c);
        std::vector<std::size_t>& counts = chunk_slots_[c];
        counts.clear();
        for (std::size_t i = c * kChunk; i < std::min(np, (c + 1) * kChunk); ++i) {
          const int id = chunk_keys_.local(c, pairs_[i].first);
          if (static_cast<std::size_t>(id) == counts.size()) counts.push_back(0);
          ++counts[static_cast<std::size_t>(id)];
          pair_cell_[i] = id;
        }
      },
      serial);
  cells_.clear();
  std::vector<std::uint64_t>& cell_keys = cell_key_;
  cell_keys.clear();
  chunk_keys_.number(cells_, cell_keys);
  cell_start_.assign(cell_keys.size() + 1, 0);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t l = 0; l < chunk_slots_[c].size(); ++l)
      cell_start_[static_cast<std::size_t>(chunk_keys_.global(c, static_cast<int>(l))) + 1] +=
          chunk_slots_[c][l];
  for (std::size_t g = 0; g < cell_keys.size(); ++g) cell_start_[g + 1] += cell_start_[g];
  {
    std::vector<std::size_t> next(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t c = 0; c < nc; ++c)
      for (std::size_t l = 0; l < chunk_slots_[c].size(); ++l) {
        std::size_t& n = next[static_cast<std::size_t>(chunk_keys_.global(c, static_cast<int>(l)))];
        const std::size_t first = n;
        n += chunk_slots_[c][l];
        chunk_slots_[c][l] = first;  // from here the chunk's next slot in that cell
      }
  }
  tri_.resize(np);
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        std::vector<std::size_t>& slot = chunk_slots_[c];
        for (std::size_t i = c * kChunk; i < std::min(np, (c + 1) * kChunk); ++i)
          tri_[slot[static_cast<std::size_t>(pair_cell_[i])]++] = pairs_[i].second;
      },
      serial);
  // The work space goes where it was large (a first build before the mesh moved apart).
  if (pairs_.capacity() > 2 * np + 4096) {
    std::vector<std::pair<std::uint64_t, int>>().swap(pairs_);
    std::vector<int>().swap(pair_cell_);
  }
}

void TriangleGrid::build(const std::vector<Vec3d>& pos, const std::vector<Eigen::Vector3i>& tris,
                         double cell, double pad, bool serial) {
  build_impl(
      tris.size(),
      [&](std::size_t t, Vec3d& lo, Vec3d& hi) {
        lo = pos[tris[t][0]];
        hi = lo;
        for (int k = 1; k < 3; ++k) {
          lo = lo.cwiseMin(pos[tris[t][k]]);
          hi = hi.cwiseMax(pos[tris[t][k]]);
        }
      },
      cell, pad, serial);
}

void TriangleGrid::build(const std::vector<std::array<double, 6>>& boxes, double cell, double pad,
                         bool serial) {
  build_impl(
      boxes.size(),
      [&](std::size_t t, Vec3d& lo, Vec3d& hi) {
        lo = Vec3d(boxes[t][0], boxes[t][1], boxes[t][2]);
        hi = Vec3d(boxes[t][3], boxes[t][4], boxes[t][5]);
      },
      cell, pad, serial);
}

void TriangleGrid::query(const Vec3d& p, std::vector<int>& out) const {
  out.clear();
  if (!p.allFinite()) return;
  for_each_in_box(p, p, [&](int t) { out.push_back(t); });
}

void TriangleGrid::query_box(const Vec3d& lo, const Vec3d& hi, std::vector<int>& out) const {
  out.clear();
  for_each_in_box(lo, hi, [&](int t) { out.push_back(t); });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace shellmpm
