#include "sim/shell/limit_mesh.h"

#include <algorithm>
#include <map>
#include <tuple>
#include <utility>

#include "sim/core/check.h"

namespace shellmpm {

LimitMesh::LimitMesh(const LoopBasis& basis, const std::vector<Eigen::Vector3i>& triangles,
                     const std::vector<Eigen::Vector2d>& uvs, int levels)
    : LimitMesh(basis, triangles, uvs, uvs.empty() ? std::vector<Eigen::Vector3i>{} : triangles,
                levels) {}

LimitMesh::LimitMesh(const LoopBasis& basis, const std::vector<Eigen::Vector3i>& triangles,
                     const std::vector<Eigen::Vector2d>& uvs,
                     const std::vector<Eigen::Vector3i>& uv_triangles, int levels) {
  const bool has_uvs = !uvs.empty();
  SHELLMPM_CHECK(has_uvs ? uv_triangles.size() == triangles.size() : uv_triangles.empty(),
                 << uvs.size() << " uvs, " << uv_triangles.size() << " uv triangles, "
                 << triangles.size() << " triangles");
  for (const Eigen::Vector3i& t : uv_triangles)
    SHELLMPM_CHECK(t.minCoeff() >= 0 && t.maxCoeff() < static_cast<int>(uvs.size()),
                   << "uv triangle " << t.transpose() << " of " << uvs.size() << " uvs");
  const int n = 1 << levels;
  // A sample point (i, j) of face f, xi = (i/n, j/n), is shared with neighbours when it
  // lies on a corner or an edge; key it by the control vertices so it is made once
  // (the row), and by the UV entries there so that the output vertex is split at seams.
  using Key = std::tuple<int, int, int, int>;
  std::map<Key, int> row_index;
  std::map<std::pair<Key, std::pair<int, int>>, int> vertex_index;
  auto key_of = [&](int f, int i, int j, std::pair<int, int>& uv_key) {
    const Eigen::Vector3i& t = triangles[f];
    const Eigen::Vector3i u = has_uvs ? uv_triangles[f] : Eigen::Vector3i::Zero();
    const int k = n - i - j;  // weight of corner 0
    // Barycentric weights (corner0, corner1, corner2) = (k, i, j) / n.
    int w[3] = {k, i, j};
    int nz = 0;
    for (int c = 0; c < 3; ++c) nz += w[c] > 0;
    uv_key = {0, 0};
    if (nz == 1) {
      for (int c = 0; c < 3; ++c)
        if (w[c] == n) {
          uv_key = {u[c], 0};
          return std::make_tuple(0, t[c], 0, 0);
        }
    }
    if (nz == 2) {
      for (int c = 0; c < 3; ++c)
        if (w[c] == 0) {
          int a = t[(c + 1) % 3], b = t[(c + 2) % 3];
          int ua = u[(c + 1) % 3], ub = u[(c + 2) % 3];
          int wb = w[(c + 2) % 3];
          if (a > b) {
            std::swap(a, b);
            std::swap(ua, ub);
            wb = n - wb;
          }
          uv_key = {ua, ub};
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
        std::pair<int, int> uv_key;
        const Key key = key_of(f, i, j, uv_key);
        auto it = vertex_index.find({key, uv_key});
        int id;
        if (it == vertex_index.end()) {
          id = static_cast<int>(vertex_row_.size());
          vertex_index.emplace(std::make_pair(key, uv_key), id);
          auto row = row_index.find(key);
          if (row == row_index.end()) {
            row = row_index.emplace(key, static_cast<int>(rows_.size())).first;
            basis.evaluate(f, double(i) / n, double(j) / n, bp);
            Row r;
            r.ctrl = bp.ctrl;
            for (std::size_t c = 0; c < bp.ctrl.size(); ++c) {
              r.n.push_back(static_cast<Real>(bp.N[c]));
              r.d1.push_back(static_cast<Real>(bp.N1[c]));
              r.d2.push_back(static_cast<Real>(bp.N2[c]));
            }
            rows_.push_back(std::move(r));
          }
          vertex_row_.push_back(row->second);
          if (has_uvs) {
            const Eigen::Vector3i& t = uv_triangles[f];
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
  pos.resize(vertex_row_.size());
  normal.resize(vertex_row_.size());
  for (std::size_t r = 0; r < vertex_row_.size(); ++r) {
    const Row& row = rows_[vertex_row_[r]];
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
  vel.resize(vertex_row_.size());
  for (std::size_t r = 0; r < vertex_row_.size(); ++r) {
    const Row& row = rows_[vertex_row_[r]];
    Vec3 u = Vec3::Zero();
    for (std::size_t c = 0; c < row.ctrl.size(); ++c) u += row.n[c] * v[row.ctrl[c]];
    vel[r] = u;
  }
}

}  // namespace shellmpm
