#include "sim/shell/static_solver.h"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>

#include "sim/core/check.h"
#include "sim/shell/fd_stiffness.h"

namespace shellmpm {
namespace {

using VecX = Eigen::VectorXd;
using SpMat = Eigen::SparseMatrix<double>;
using ForceFn = std::function<void(const std::vector<Vec3d>&, std::vector<Vec3d>&)>;

struct Problem {
  std::vector<Vec3d>& x;
  const ForceFn& forces;
  std::vector<std::pair<int, int>> dofs;  // (point, component) of each free dof
  std::vector<int> dof_of;                // 3 * point + component -> dof, or -1
  std::vector<Vec3d> work, f;
  int calls = 0;

  VecX gather() const {
    VecX v(dofs.size());
    for (std::size_t k = 0; k < dofs.size(); ++k) v[k] = x[dofs[k].first][dofs[k].second];
    return v;
  }
  void set(const VecX& q, std::vector<Vec3d>& out) const {
    out = x;
    for (std::size_t k = 0; k < dofs.size(); ++k) out[dofs[k].first][dofs[k].second] = q[k];
  }
  // Full force vector at positions p into f.
  void eval(const std::vector<Vec3d>& p) {
    f.assign(x.size(), Vec3d::Zero());
    forces(p, f);
    ++calls;
  }
  // Gradient of the potential (minus the force) at free dofs q.
  VecX gradient(const VecX& q) {
    set(q, work);
    eval(work);
    VecX g(dofs.size());
    for (std::size_t k = 0; k < dofs.size(); ++k) g[k] = -f[dofs[k].first][dofs[k].second];
    return g;
  }
};

/// Tangent stiffness K = -df/dq at q (fd_stiffness.h), counting the evaluations.
SpMat problem_stiffness(Problem& pb, const VecX& q, const std::vector<std::vector<int>>& coupling,
                        const std::vector<std::vector<int>>& groups, double eps) {
  std::vector<Vec3d> base;
  pb.set(q, base);
  pb.eval(base);
  const std::vector<Vec3d> f0 = pb.f;
  const PointForceFn eval = [&pb](const std::vector<Vec3d>& p, std::vector<Vec3d>& f) {
    pb.eval(p);
    f = pb.f;
  };
  return fd_stiffness(eval, base, f0, pb.dof_of, static_cast<int>(pb.dofs.size()), coupling, groups,
                      eps);
}

/// Numbers the free (point, component) pairs of free_mask into pb.dofs / pb.dof_of;
/// returns which points have a free component.
std::vector<char> number_dofs(Problem& pb, const std::vector<std::uint8_t>& free_mask) {
  std::vector<char> movable(pb.x.size(), 0);
  for (std::size_t i = 0; i < pb.x.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (free_mask[i] & (1u << a)) {
        pb.dof_of[3 * i + a] = static_cast<int>(pb.dofs.size());
        pb.dofs.emplace_back(static_cast<int>(i), a);
        movable[i] = 1;
      }
  return movable;
}

/// Length scale of the problem: the bounding-box diagonal (or the largest coordinate,
/// or 1 for a single point at the origin).
double length_scale(const std::vector<Vec3d>& x) {
  Eigen::AlignedBox<double, 3> box;
  double size = 0;
  for (const Vec3d& p : x) {
    box.extend(p);
    size = std::max(size, p.lpNorm<Eigen::Infinity>());
  }
  size = std::max(size, box.diagonal().norm());
  if (!(size > 0)) size = 1;
  return size;
}

using History = std::deque<std::pair<VecX, VecX>>;  // (s, y)

/// L-BFGS two-loop recursion (Nocedal & Wright 2006, alg. 7.4): d = -H g, with H0 the
/// factorised stiffness when there is one, else the scaled identity.
VecX two_loop(const History& hist, const Eigen::SimplicialLDLT<SpMat>* H0, const VecX& g,
              double step_scale) {
  VecX d = -g;
  std::vector<double> alpha(hist.size());
  for (int k = static_cast<int>(hist.size()) - 1; k >= 0; --k) {
    const auto& [s, y] = hist[k];
    alpha[k] = s.dot(d) / y.dot(s);
    d -= alpha[k] * y;
  }
  if (H0) {
    d = H0->solve(d);
  } else if (!hist.empty()) {
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
  return d;
}

/// The step direction d at gradient g (two_loop(); without history if that is not a
/// descent direction), capped so no coordinate moves further than max_move: the first
/// steps of a sagging drape see only bending stiffness and would go far out. dphi0 = g . d.
VecX search_direction(History& hist, const Eigen::SimplicialLDLT<SpMat>* H0, const VecX& g,
                      double step_scale, double max_move, double& dphi0) {
  VecX d = two_loop(hist, H0, g, step_scale);
  dphi0 = g.dot(d);
  if (!(dphi0 < 0)) {  // not a descent direction: restart without history
    hist.clear();
    d = H0 ? VecX(-H0->solve(g)) : VecX(-step_scale * g);
    dphi0 = g.dot(d);
  }
  const double dmax = d.lpNorm<Eigen::Infinity>();
  if (dmax > max_move) {
    d *= max_move / dmax;
    dphi0 = g.dot(d);
  }
  return d;
}

/// Secant search on phi'(a) = g(q + a d) . d for a zero, starting at a = 1; a step to
/// where the forces are not finite (an inverted element) is halved. Returns a and the
/// gradient there in g_new.
double secant_search(Problem& pb, const VecX& q, const VecX& d, double dphi0, VecX& g_new) {
  double a_lo = 0, dphi_lo = dphi0, a = 1;
  g_new = pb.gradient(q + a * d);
  double dphi = g_new.dot(d);
  for (int k = 0; k < 40 && !std::isfinite(dphi); ++k) {
    a *= 0.5;
    g_new = pb.gradient(q + a * d);
    dphi = g_new.dot(d);
  }
  SHELLMPM_CHECK(std::isfinite(dphi), << "forces not finite near the current state");
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
    const VecX g_try = pb.gradient(q + a_next * d);
    const double dphi_try = g_try.dot(d);
    if (!std::isfinite(dphi_try)) break;  // keep the last finite point
    a = a_next;
    g_new = g_try;
    dphi = dphi_try;
  }
  return a;
}

}  // namespace

StaticSolveResult solve_static(std::vector<Vec3d>& x, const std::vector<std::uint8_t>& free_mask,
                               const ForceFn& forces, const StaticSolveOptions& opt) {
  SHELLMPM_CHECK(free_mask.size() == x.size(), << free_mask.size() << " vs " << x.size());
  const bool newton = !opt.coupling.empty();
  if (newton) SHELLMPM_CHECK(opt.coupling.size() == x.size(), << opt.coupling.size());
  Problem pb{x, forces, {}, std::vector<int>(3 * x.size(), -1), {}, {}, 0};
  const std::vector<char> movable = number_dofs(pb, free_mask);
  StaticSolveResult res;
  if (pb.dofs.empty()) {
    res.converged = true;
    return res;
  }
  const double size = length_scale(x);
  const double max_move = opt.max_move * size;
  std::vector<std::vector<int>> groups;
  double eps = 0;
  if (newton) {
    groups = colour_points(opt.coupling, movable);
    eps = opt.fd_step * size;
  }
  VecX q = pb.gather();
  VecX g = pb.gradient(q);
  std::unique_ptr<Eigen::SimplicialLDLT<SpMat>> H0;
  constexpr int kMemory = 12;
  History hist;
  const double step_scale = 1e-3 / std::max(g.lpNorm<Eigen::Infinity>(), 1e-300);
  int since_refresh = 0;
  std::vector<double> best;  // best residual up to each iteration
  for (int it = 0; it < opt.max_iterations; ++it) {
    res.iterations = it;
    res.residual = g.lpNorm<Eigen::Infinity>();
    if (res.residual < opt.tolerance) {
      res.converged = true;
      break;
    }
    best.push_back(best.empty() ? res.residual : std::min(best.back(), res.residual));
    if (it >= opt.stall_iterations && !(best.back() < 0.5 * best[it - opt.stall_iterations])) {
      res.stalled = true;
      break;
    }
    if (newton && (!H0 || since_refresh >= opt.hessian_every)) {
      H0 = factorise_positive(problem_stiffness(pb, q, opt.coupling, groups, eps));
      ++res.hessian_evaluations;
      hist.clear();
      since_refresh = 0;
    }
    ++since_refresh;
    double dphi0;
    const VecX d = search_direction(hist, H0.get(), g, step_scale, max_move, dphi0);
    VecX g_new;
    const double a = secant_search(pb, q, d, dphi0, g_new);
    const VecX s = a * d;
    const VecX y = g_new - g;
    q += s;
    g = g_new;
    if (s.dot(y) > 1e-300) {
      hist.emplace_back(s, y);
      if (static_cast<int>(hist.size()) > kMemory) hist.pop_front();
    }
    res.iterations = it + 1;
  }
  res.residual = g.lpNorm<Eigen::Infinity>();
  res.converged = res.converged || res.residual < opt.tolerance;
  res.force_evaluations = pb.calls;
  std::vector<Vec3d> out;
  pb.set(q, out);
  x = out;
  return res;
}

}  // namespace shellmpm
