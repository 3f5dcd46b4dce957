#include "sim/shell/preroll.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/core/simulation_error.h"

namespace shellmpm {
namespace {

int settle_static(std::vector<std::unique_ptr<ShellObject>>& shells, const Vec3d& gravity,
                  double time, double fref, const PrerollSettings& p, bool serial) {
  // Each shell settles on its own; the residual criterion is the dynamic one's.
  int iterations = 0;
  for (auto& sh : shells) {
    const StaticSolveResult r = sh->settle(gravity, time, p.tolerance * fref, p.max_steps, serial);
    if (!r.converged) {
      std::ostringstream os;
      os << "pre-roll did not settle shell '" << sh->name() << "' in " << r.iterations
         << " iterations: residual " << r.residual << " N = " << r.residual / fref
         << " x the reference force " << fref << " N, tolerance " << p.tolerance;
      if (r.stalled)
        os << "; no progress in the last " << StaticSolveOptions().stall_iterations
           << " iterations: is there an equilibrium (pins holding the shell)?";
      else
        os << " (preroll.max_steps = " << p.max_steps << ")";
      throw SimulationError(os.str());
    }
    iterations = std::max(iterations, r.iterations);
  }
  return iterations;
}

void stop_all(std::vector<std::unique_ptr<ShellObject>>& shells) {
  for (auto& sh : shells)
    for (auto& v : sh->v) v.setZero();
}

}  // namespace

int settle_shells(std::vector<std::unique_ptr<ShellObject>>& shells, const Vec3d& gravity,
                  double time, double dt, const PrerollSettings& p, bool serial) {
  // Reference force scale: the largest weight of a control point (or 1 N without gravity).
  double fref = 0;
  for (const auto& sh : shells)
    for (Real m : sh->mass) fref = std::max(fref, m * gravity.norm());
  for (const auto& sh : shells)
    for (const PointLoadDesc& pl : sh->desc().point_loads) fref = std::max(fref, pl.force.norm());
  if (fref <= 0) fref = 1;
  if (p.method == PrerollSettings::Method::Static)
    return settle_static(shells, gravity, time, fref, p, serial);
  std::vector<std::vector<Vec3>> f(shells.size());
  double ke_prev = 0;
  for (int step = 1; step <= p.max_steps; ++step) {
    double residual = 0, ke = 0;
    for (std::size_t i = 0; i < shells.size(); ++i) {
      ShellObject& sh = *shells[i];
      sh.forces(gravity, f[i], serial);
      for (std::size_t j = 0; j < sh.size(); ++j)
        for (int a = 0; a < 3; ++a)
          if (!(sh.pin_mask[j] & (1u << a)))
            residual = std::max(residual, std::abs(double(f[i][j][a])));
      sh.integrate(f[i], time, dt, serial);
      ke += sh.kinetic_energy();
    }
    if (residual / fref < p.tolerance) {
      stop_all(shells);
      return step;
    }
    // Kinetic damping: at a peak of kinetic energy, stop every point.
    if (ke < ke_prev) {
      stop_all(shells);
      ke = 0;
    }
    ke_prev = ke;
  }
  std::ostringstream os;
  os << "pre-roll did not settle within preroll.max_steps = " << p.max_steps << " steps (tolerance "
     << p.tolerance << ")";
  throw SimulationError(os.str());
}

}  // namespace shellmpm
