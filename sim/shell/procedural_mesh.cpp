#include "sim/shell/procedural_mesh.h"

#include <cmath>
#include <map>

#include "sim/core/check.h"

namespace shellmpm {

ShellMesh make_sheet(double size_x, double size_z, int nx, int nz) {
  SHELLMPM_CHECK(nx >= 1 && nz >= 1 && size_x > 0 && size_z > 0, << nx << " " << nz);
  ShellMesh m;
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i) {
      m.vertices.emplace_back(size_x * (double(i) / nx - 0.5), 0.0,
                              size_z * (double(j) / nz - 0.5));
      m.uvs.emplace_back(double(i) / nx, double(j) / nz);
    }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      // (Z x X) = +Y: the corner order (i,j), (i,j+1), (i+1,j) faces +Y.
      m.triangles.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j));
      m.triangles.emplace_back(id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
    }
  m.uv_triangles = m.triangles;  // one UV per vertex
  return m;
}

ShellMesh make_cylinder(double radius, double height, double angle_deg, int n_around, int n_along) {
  const bool closed = angle_deg >= 360.0 - 1e-9;
  SHELLMPM_CHECK(n_along >= 1 && n_around >= (closed ? 3 : 1) && radius > 0 && height > 0,
                 << n_around << " " << n_along);
  ShellMesh m;
  const int cols = closed ? n_around : n_around + 1;
  const double arc = angle_deg * M_PI / 180.0;
  for (int j = 0; j <= n_along; ++j)
    for (int i = 0; i < cols; ++i) {
      const double th = arc * i / n_around;
      m.vertices.emplace_back(radius * std::cos(th), height * (double(j) / n_along - 0.5),
                              -radius * std::sin(th));
      m.uvs.emplace_back(double(i) / n_around, double(j) / n_along);
    }
  auto id = [&](int i, int j) { return j * cols + (i % cols); };
  for (int j = 0; j < n_along; ++j)
    for (int i = 0; i < n_around; ++i) {
      // Around is counter-clockwise seen from +Y; outward normal = d(around) x d(up).
      m.triangles.emplace_back(id(i, j), id(i + 1, j), id(i, j + 1));
      m.triangles.emplace_back(id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
    }
  m.uv_triangles = m.triangles;  // one UV per vertex
  return m;
}

ShellMesh make_sphere(double radius, int subdivisions) {
  SHELLMPM_CHECK(radius > 0 && subdivisions >= 0, << radius);
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                          {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                          {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (auto& x : v) x.normalize();
  std::vector<Eigen::Vector3i> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      mid[key] = id;
      return id;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& f : t) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.emplace_back(f[0], a, c);
      next.emplace_back(f[1], b, a);
      next.emplace_back(f[2], c, b);
      next.emplace_back(a, b, c);
    }
    t.swap(next);
  }
  ShellMesh m;
  for (const auto& x : v) {
    m.vertices.push_back(radius * x);
    m.uvs.emplace_back(0.5 + std::atan2(x.z(), x.x()) / (2 * M_PI), 0.5 + std::asin(x.y()) / M_PI);
  }
  m.triangles = t;
  m.uv_triangles = t;  // one UV per vertex
  return m;
}

}  // namespace shellmpm
