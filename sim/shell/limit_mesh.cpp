#include "sim/shell/limit_mesh.h"

#include <algorithm>
#include <map>
#include <tuple>

namespace shellmpm {

LimitMesh::LimitMesh(const LoopBasis& basis, const std::vector<Eigen::Vector3i>& triangles,
                     const std::vector<Eigen::Vector2d>& uvs, int levels) {
  const int n = 1 << levels;
  // A sample point (i, j) of face f, xi = (i/n, j/n), is shared with neighbours when it
  // lies on a corner or an edge; key it by the control vertices so it is made once.
  std::map<std::tuple<int, int, int, int>, int> index;
  auto key_of = [&](int f, int i, int j) {
    const Eigen::Vector3i& t = triangles[f];
    const int k = n - i - j;  // weight of corner 0
    // Barycentric weights (corner0, corner1, corner2) = (k, i, j) / n.
    int w[3] = {k, i, j};
    int nz = 0;
    for (int c = 0; c < 3; ++c) nz += w[c] > 0;
    if (nz == 1) {
      for (int c = 0; c < 3; ++c)
        if (w[c] == n) return std::make_tuple(0, t[c], 0, 0);
    }
    if (nz == 2) {
      for (int c = 0; c < 3; ++c)
        if (w[c] == 0) {
          int a = t[(c + 1) % 3], b = t[(c + 2) % 3];
          int wb = w[(c + 2) % 3];
          if (a > b) {
            std::swap(a, b);
            wb = n - wb;
          }
          return std::make_tuple(1, a, b, wb);
        }
    }
    return std::make_tuple(2, f, i, j);
  };
  BasisPoint bp;
  for (int f = 0; f < static_cast<int>(triangles.size()); ++f) {
    std::vector<int> local((n + 1) * (n + 1), -1);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i + j <= n; ++i) {
        const auto key = key_of(f, i, j);
        auto it = index.find(key);
        int id;
        if (it == index.end()) {
          id = static_cast<int>(rows_.size());
          index.emplace(key, id);
          basis.evaluate(f, double(i) / n, double(j) / n, bp);
          Row r;
          r.ctrl = bp.ctrl;
          for (std::size_t c = 0; c < bp.ctrl.size(); ++c) {
            r.n.push_back(static_cast<Real>(bp.N[c]));
            r.d1.push_back(static_cast<Real>(bp.N1[c]));
            r.d2.push_back(static_cast<Real>(bp.N2[c]));
          }
          rows_.push_back(std::move(r));
          if (!uvs.empty()) {
            const Eigen::Vector3i& t = triangles[f];
            uvs_.push_back(
                (double(n - i - j) * uvs[t[0]] + double(i) * uvs[t[1]] + double(j) * uvs[t[2]]) /
                n);
          }
        } else {
          id = it->second;
        }
        local[j * (n + 1) + i] = id;
      }
    auto at = [&](int i, int j) { return local[j * (n + 1) + i]; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        tris_.emplace_back(at(i, j), at(i + 1, j), at(i, j + 1));
        if (i + j + 1 < n) tris_.emplace_back(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
  }
}

void LimitMesh::evaluate(const Vec3* x, std::vector<Vec3>& pos, std::vector<Vec3>& normal) const {
  pos.resize(rows_.size());
  normal.resize(rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    Vec3 p = Vec3::Zero(), a1 = Vec3::Zero(), a2 = Vec3::Zero();
    for (std::size_t c = 0; c < row.ctrl.size(); ++c) {
      const Vec3& xc = x[row.ctrl[c]];
      p += row.n[c] * xc;
      a1 += row.d1[c] * xc;
      a2 += row.d2[c] * xc;
    }
    pos[r] = p;
    const Vec3 nn = a1.cross(a2);
    const Real len = nn.norm();
    normal[r] = len > 0 ? Vec3(nn / len) : Vec3(0, 1, 0);
  }
}

void LimitMesh::evaluate_velocity(const Vec3* v, std::vector<Vec3>& vel) const {
  vel.resize(rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    Vec3 u = Vec3::Zero();
    for (std::size_t c = 0; c < row.ctrl.size(); ++c) u += row.n[c] * v[row.ctrl[c]];
    vel[r] = u;
  }
}

}  // namespace shellmpm
