#include "sim/implicit/newton.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace shellmpm {

void ImplicitObjective::hessian_product(const VecXd& u, const VecXd& d, VecXd& out) {
  const double dmax = d.lpNorm<Eigen::Infinity>();
  out.setZero(d.size());
  if (dmax == 0) return;
  const double h = 1e-6 * (1.0 + u.lpNorm<Eigen::Infinity>()) / dmax;
  hp_u_ = u + h * d;
  hp_plus_.resize(u.size());
  gradient(hp_u_, hp_plus_);
  hp_u_ = u - h * d;
  hp_minus_.resize(u.size());
  gradient(hp_u_, hp_minus_);
  out = (hp_plus_ - hp_minus_) / (2.0 * h);
  project(out);
}

namespace {

struct CgResult {
  int iterations = 0;
};

/// Truncated PCG on H d = -g from d = 0: stops at |r|_P <= eta |g|_P, at the cap, or at
/// the first direction of non-positive curvature (keeping d, or z = P^-1 (-g) if that
/// happens before any step).
CgResult truncated_pcg(ImplicitObjective& obj, const VecXd& u, const VecXd& g, double eta,
                       int max_iterations, VecXd& d) {
  CgResult res;
  const Eigen::Index n = g.size();
  d.setZero(n);
  VecXd r = -g, z(n), p, Hp(n);
  obj.project(r);
  obj.apply_preconditioner(r, z);
  obj.project(z);
  double rz = r.dot(z);
  if (!(rz > 0)) {
    d = z;
    return res;
  }
  const double target = eta * eta * rz;
  p = z;
  for (int k = 0; k < max_iterations; ++k) {
    obj.hessian_product(u, p, Hp);
    ++res.iterations;
    const double pHp = p.dot(Hp);
    if (!(pHp > 0) || !std::isfinite(pHp)) {
      if (k == 0) d = z;  // no curvature information: the preconditioned gradient
      break;
    }
    const double alpha = rz / pHp;
    d += alpha * p;
    r -= alpha * Hp;
    obj.apply_preconditioner(r, z);
    obj.project(z);
    const double rz_new = r.dot(z);
    if (rz_new <= target) break;
    p = z + (rz_new / rz) * p;
    rz = rz_new;
  }
  return res;
}

/// SHELLMPM_NEWTON_TRACE (any value) prints each Newton iteration and each solve's
/// outcome to stderr (docs/implicit.md, "Statistics"): a diagnostic for solves that take
/// many iterations, not part of any output.
bool newton_trace() {
  static const bool on = std::getenv("SHELLMPM_NEWTON_TRACE") != nullptr;
  return on;
}

NewtonReport newton_solve(ImplicitObjective& obj, VecXd& u, const NewtonOptions& opt) {
  NewtonReport rep;
  const Eigen::Index n = obj.size();
  VecXd g(n), d(n), trial(n), g_trial(n);
  obj.prepare_preconditioner(u);
  // The correction the gradient asks for, P^-1 g.
  VecXd z(n);
  auto residual = [&](const VecXd& grad) {
    obj.apply_preconditioner(grad, z);
    obj.project(z);
    return z.lpNorm<Eigen::Infinity>();
  };
  obj.gradient(u, g);
  double e = obj.energy(u);
  rep.energies.push_back(e);
  rep.residual0 = rep.residual = residual(g);
  while (true) {
    if (!std::isfinite(rep.residual)) break;
    const bool small = rep.residual <= opt.tolerance;
    if (!small && rep.iterations >= opt.max_iterations) break;
    const int every = obj.refresh_every() > 0 ? obj.refresh_every() : opt.refresh_after;
    if (rep.iterations > 0 && every > 0 && rep.iterations % every == 0)
      obj.prepare_preconditioner(u);
    // Where P^-1 g looks converged, CG solves tightly: its step is the convergence test
    // below, and a loose CG stops early for the same reason P^-1 g looks small (both
    // measure in P's norm, where the modes P misses hardly show).
    const double eta =
        small ? opt.cg_min_eta
              : std::clamp(std::sqrt(rep.residual / rep.residual0), opt.cg_min_eta, opt.cg_max_eta);
    const int cg = truncated_pcg(obj, u, g, eta, opt.max_cg_iterations, d).iterations;
    rep.cg_iterations += cg;
    if (small) {
      // P^-1 g is small, but a preconditioner far from H^-1 (block Jacobi on a stiff
      // sheet, whose low bending modes it misses by orders of magnitude) makes it small
      // where the Newton correction is not: a clamped steel sheet "converged" at rest,
      // 0 iterations, every step. Converged only when the Newton step is small too.
      const double step_size = d.lpNorm<Eigen::Infinity>();
      if (step_size <= opt.tolerance) {
        rep.converged = true;
        break;
      }
      rep.residual = step_size;  // the better measure of what is left
      if (rep.iterations >= opt.max_iterations) break;
    }
    double slope = g.dot(d);
    if (!(slope < 0)) {
      // Not a descent direction (CG broke down on round-off): the preconditioned gradient.
      obj.apply_preconditioner(-g, d);
      obj.project(d);
      slope = g.dot(d);
      if (!(slope < 0)) {
        rep.line_search_failed = true;
        break;
      }
    }
    double step = 1.0, e_trial = 0;
    bool accepted = false;
    for (int h = 0; h <= opt.max_halvings; ++h, step *= 0.5) {
      trial = u + step * d;
      e_trial = obj.energy(trial);
      if (std::isfinite(e_trial) && e_trial <= e + opt.armijo * step * slope) {
        accepted = true;
        break;
      }
    }
    ++rep.iterations;
    if (newton_trace())
      std::fprintf(stderr,
                   "newton %d: E %.9e J, residual %.3e m/s, CG %d, |d| %.3e m/s, g.d %.3e J, "
                   "step %g\n",
                   rep.iterations, e, rep.residual, cg, d.lpNorm<Eigen::Infinity>(), slope,
                   accepted ? step : 0.0);
    if (!accepted) {
      // Near the solution the decrease a full step promises, -slope, can fall below the
      // round-off of E's sums: Armijo then cannot tell. The full step is still taken when
      // E does not rise beyond that round-off and the residual falls.
      trial = u + d;
      e_trial = obj.energy(trial);
      const double noise = opt.energy_round_off * std::max(std::abs(e), std::abs(rep.energies[0]));
      if (std::isfinite(e_trial) && -slope <= noise && e_trial <= e + noise) {
        obj.gradient(trial, g_trial);
        const double r_trial = residual(g_trial);
        if (r_trial < rep.residual) {
          u = trial;
          e = std::min(e, e_trial);
          rep.energies.push_back(e);
          g = g_trial;
          rep.residual = r_trial;
          ++rep.round_off_steps;
          continue;
        }
      }
      rep.line_search_failed = true;
      break;
    }
    u = trial;
    e = e_trial;
    rep.energies.push_back(e);
    obj.gradient(u, g);
    rep.residual = residual(g);
  }
  return rep;
}

}  // namespace

NewtonReport newton_minimise(ImplicitObjective& obj, VecXd& u, const NewtonOptions& opt) {
  NewtonReport rep = newton_solve(obj, u, opt);
  if (newton_trace())
    std::fprintf(stderr,
                 "newton: %d iterations, %d CG, %s, residual %.3e -> %.3e m/s, %zu unknowns\n",
                 rep.iterations, rep.cg_iterations,
                 rep.converged            ? "converged"
                 : rep.line_search_failed ? "line search failed"
                                          : "not converged",
                 rep.residual0, rep.residual, static_cast<std::size_t>(u.size()));
  return rep;
}

}  // namespace shellmpm
