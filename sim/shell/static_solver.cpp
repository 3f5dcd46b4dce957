#include "sim/shell/static_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>

namespace shellmpm {
namespace {

using VecX = Eigen::VectorXd;

struct Problem {
  std::vector<Vec3>& x;
  const std::vector<std::uint8_t>& mask;
  const std::function<void(const std::vector<Vec3>&, std::vector<Vec3>&)>& forces;
  std::vector<std::pair<int, int>> dofs;  // (point, component) of each free dof
  VecX x0;                                // free dofs at the start (double)
  std::vector<Vec3> work, f;

  VecX gather() const {
    VecX v(dofs.size());
    for (std::size_t k = 0; k < dofs.size(); ++k) v[k] = x[dofs[k].first][dofs[k].second];
    return v;
  }
  // Gradient of the potential (minus the force) at free dofs q.
  VecX gradient(const VecX& q) {
    work = x;
    for (std::size_t k = 0; k < dofs.size(); ++k)
      work[dofs[k].first][dofs[k].second] = static_cast<Real>(q[k]);
    f.assign(x.size(), Vec3::Zero());
    forces(work, f);
    VecX g(dofs.size());
    for (std::size_t k = 0; k < dofs.size(); ++k) g[k] = -static_cast<double>(f[dofs[k].first][dofs[k].second]);
    return g;
  }
  void scatter(const VecX& q) {
    for (std::size_t k = 0; k < dofs.size(); ++k)
      x[dofs[k].first][dofs[k].second] = static_cast<Real>(q[k]);
  }
};

}  // namespace

StaticSolveResult solve_static(std::vector<Vec3>& x, const std::vector<std::uint8_t>& free_mask,
                               const std::function<void(const std::vector<Vec3>&, std::vector<Vec3>&)>& forces,
                               double tolerance, int max_iterations) {
  Problem pb{x, free_mask, forces, {}, {}, {}, {}};
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (free_mask[i] & (1u << a)) pb.dofs.emplace_back(static_cast<int>(i), a);
  StaticSolveResult res;
  if (pb.dofs.empty()) {
    res.converged = true;
    return res;
  }
  VecX q = pb.gather();
  VecX g = pb.gradient(q);
  constexpr int kMemory = 12;
  std::deque<std::pair<VecX, VecX>> hist;  // (s, y)
  double step_scale = 1e-3 / std::max(g.lpNorm<Eigen::Infinity>(), 1e-300);
  for (int it = 0; it < max_iterations; ++it) {
    res.iterations = it;
    res.residual = g.lpNorm<Eigen::Infinity>();
    if (res.residual < tolerance) {
      res.converged = true;
      break;
    }
    // Two-loop recursion: d = -H g.
    VecX d = -g;
    std::vector<double> alpha(hist.size());
    for (int k = static_cast<int>(hist.size()) - 1; k >= 0; --k) {
      const auto& [s, y] = hist[k];
      alpha[k] = s.dot(d) / y.dot(s);
      d -= alpha[k] * y;
    }
    if (!hist.empty()) {
      const auto& [s, y] = hist.back();
      d *= s.dot(y) / y.dot(y);
    } else {
      d *= step_scale;
    }
    for (std::size_t k = 0; k < hist.size(); ++k) {
      const auto& [s, y] = hist[k];
      const double beta = y.dot(d) / y.dot(s);
      d += (alpha[k] - beta) * s;
    }
    double dphi0 = g.dot(d);
    if (!(dphi0 < 0)) {  // not a descent direction: restart from steepest descent
      hist.clear();
      d = -step_scale * g;
      dphi0 = g.dot(d);
    }
    // Secant search on phi'(a) = g(q + a d) . d for a zero, starting at a = 1.
    double a_lo = 0, dphi_lo = dphi0, a = 1;
    VecX g_new = pb.gradient(q + a * d);
    double dphi = g_new.dot(d);
    for (int ls = 0; ls < 12 && std::abs(dphi) > 0.3 * std::abs(dphi0); ++ls) {
      double a_next;
      if (dphi < 0) {
        a_next = (dphi_lo < dphi) ? a + (a - a_lo) * dphi / (dphi_lo - dphi) : 2 * a;
        a_next = std::min(a_next, 4 * a);
        a_lo = a;
        dphi_lo = dphi;
      } else {
        a_next = a_lo + (a - a_lo) * dphi_lo / (dphi_lo - dphi);
      }
      if (!(a_next > 0) || !std::isfinite(a_next)) break;
      a = a_next;
      g_new = pb.gradient(q + a * d);
      dphi = g_new.dot(d);
    }
    const VecX s = a * d;
    const VecX y = g_new - g;
    q += s;
    g = g_new;
    if (s.dot(y) > 1e-300) {
      hist.emplace_back(s, y);
      if (static_cast<int>(hist.size()) > kMemory) hist.pop_front();
    }
  }
  res.residual = g.lpNorm<Eigen::Infinity>();
  res.converged = res.converged || res.residual < tolerance;
  pb.scatter(q);
  return res;
}

}  // namespace shellmpm
