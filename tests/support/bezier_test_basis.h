// Test basis for shell mechanics tests: a grid of m x m squares over [0,1]^2, each split
// into two Bezier (Bernstein) triangles; values and exact first and second derivatives.
#pragma once
#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <vector>

#include "sim/core/parallel.h"
#include "sim/shell/denting.h"
#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/shell_quadrature.h"

namespace shellmpm_test {

// Test basis: a grid of m x m squares over [0,1]^2, each split into two Bezier
// (Bernstein) triangles of degree n; shared edge nodes are shared control points.
// Bernstein triangles reproduce linear fields and give exact derivatives.
struct BezierShell {
  std::vector<shellmpm::BasisPoint> points;
  std::vector<double> weights;
  std::vector<Eigen::Vector2d> node_uv;       // domain coordinates of control points
  std::vector<std::vector<int>> patch_nodes;  // per triangle, local node -> control id
  std::vector<Eigen::Vector2d> patch_corner;  // per triangle: P0, P1, P2 (3 entries each)
  int degree = 0;
};

inline double bern_pow(double x, int e) {
  return e < 0 ? 0.0 : std::pow(x, e);
}

// Values and derivatives of xi1^i xi2^j w^k (w = 1 - xi1 - xi2) times c.
inline void bern_eval(int i, int j, int k, double c, double x1, double x2, double out[6]) {
  const double w = 1.0 - x1 - x2;
  auto P = [&](int a, int b, int d) {
    if (a < 0 || b < 0 || d < 0) return 0.0;
    return bern_pow(x1, a) * bern_pow(x2, b) * bern_pow(w, d);
  };
  out[0] = c * P(i, j, k);
  out[1] = c * (i * P(i - 1, j, k) - k * P(i, j, k - 1));
  out[2] = c * (j * P(i, j - 1, k) - k * P(i, j, k - 1));
  out[3] = c * (i * (i - 1) * P(i - 2, j, k) - 2.0 * i * k * P(i - 1, j, k - 1) +
                k * (k - 1) * P(i, j, k - 2));
  out[4] = c * (i * j * P(i - 1, j - 1, k) - i * k * P(i - 1, j, k - 1) -
                j * k * P(i, j - 1, k - 1) + k * (k - 1) * P(i, j, k - 2));
  out[5] = c * (j * (j - 1) * P(i, j - 2, k) - 2.0 * j * k * P(i, j - 1, k - 1) +
                k * (k - 1) * P(i, j, k - 2));
}

inline double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

inline BezierShell make_bezier_grid(int m, int n, int qrule) {
  BezierShell s;
  s.degree = n;
  const int R = n * m;  // lattice resolution
  std::map<std::pair<int, int>, int> id;
  auto node = [&](int a, int b) {
    auto it = id.find({a, b});
    if (it != id.end()) return it->second;
    const int k = int(s.node_uv.size());
    id[{a, b}] = k;
    s.node_uv.emplace_back(double(a) / R, double(b) / R);
    return k;
  };
  const shellmpm::TriangleQuadrature tq = shellmpm::triangle_quadrature(qrule);
  for (int bx = 0; bx < m; ++bx)
    for (int by = 0; by < m; ++by)
      for (int half = 0; half < 2; ++half) {
        Eigen::Vector2i P0, P1, P2;
        if (half == 0) {
          P0 = {bx, by};
          P1 = {bx + 1, by};
          P2 = {bx, by + 1};
        } else {
          P0 = {bx + 1, by + 1};
          P1 = {bx, by + 1};
          P2 = {bx + 1, by};
        }
        std::vector<int> local;  // ordered by (i, j)
        std::vector<Eigen::Vector3i> ijk;
        for (int i = 0; i <= n; ++i)
          for (int j = 0; i + j <= n; ++j) {
            const Eigen::Vector2i L = n * P0 + i * (P1 - P0) + j * (P2 - P0);
            local.push_back(node(L.x(), L.y()));
            ijk.emplace_back(i, j, n - i - j);
          }
        s.patch_nodes.push_back(local);
        s.patch_corner.push_back(P0.cast<double>() / m);
        s.patch_corner.push_back(P1.cast<double>() / m);
        s.patch_corner.push_back(P2.cast<double>() / m);
        for (std::size_t g = 0; g < tq.points.size(); ++g) {
          shellmpm::BasisPoint bp;
          for (std::size_t a = 0; a < local.size(); ++a) {
            const int i = ijk[a].x(), j = ijk[a].y(), k = ijk[a].z();
            const double c = factorial(n) / (factorial(i) * factorial(j) * factorial(k));
            double v[6];
            bern_eval(i, j, k, c, tq.points[g].x(), tq.points[g].y(), v);
            bp.ctrl.push_back(local[a]);
            bp.N.push_back(v[0]);
            bp.N1.push_back(v[1]);
            bp.N2.push_back(v[2]);
            bp.N11.push_back(v[3]);
            bp.N12.push_back(v[4]);
            bp.N22.push_back(v[5]);
          }
          s.points.push_back(bp);
          s.weights.push_back(tq.weights[g]);
        }
      }
  return s;
}

// Control points interpolating phi(u, v) at the lattice nodes of each patch.
inline std::vector<Eigen::Vector3d> interpolate(
    const BezierShell& s, const std::function<Eigen::Vector3d(const Eigen::Vector2d&)>& phi) {
  std::vector<Eigen::Vector3d> x(s.node_uv.size(), Eigen::Vector3d::Zero());
  const int n = s.degree;
  for (std::size_t p = 0; p < s.patch_nodes.size(); ++p) {
    const auto& local = s.patch_nodes[p];
    const int nn = int(local.size());
    Eigen::MatrixXd A(nn, nn);
    Eigen::MatrixXd rhs(nn, 3);
    int r = 0;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j, ++r) {
        const double x1 = double(i) / n, x2 = double(j) / n;
        int c = 0;
        for (int a = 0; a <= n; ++a)
          for (int b = 0; a + b <= n; ++b, ++c) {
            const int k = n - a - b;
            double v[6];
            bern_eval(a, b, k, factorial(n) / (factorial(a) * factorial(b) * factorial(k)), x1, x2,
                      v);
            A(r, c) = v[0];
          }
        rhs.row(r) = phi(s.node_uv[local[r]]).transpose();
      }
    const Eigen::MatrixXd sol = A.partialPivLu().solve(rhs);
    for (int a = 0; a < nn; ++a) x[local[a]] = sol.row(a).transpose();
  }
  return x;
}
}  // namespace shellmpm_test
