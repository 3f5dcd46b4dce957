#include "sim/solver/stages/implicit_shells.h"

#include <sstream>

#include "sim/core/simulation_error.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

ImplicitShellsStage::ImplicitShellsStage() = default;
ImplicitShellsStage::~ImplicitShellsStage() = default;

bool ImplicitShellsStage::needed(const Scene& s) {
  return s.shot.integrator == Integrator::Implicit && any_direct_shell(s);
}

void ImplicitShellsStage::run(StepContext& c) {
  if (steps_.empty())
    for (std::size_t i = 0; i < c.shells.size(); ++i)
      steps_.push_back(c.contacts[i] ? nullptr : std::make_unique<ShellImplicitStep>(*c.shells[i]));
  for (auto& s : steps_)
    if (s) s->set_plasticity_in_solve(c.scene.shot.plasticity_in_solve);
  advance(c, c.time, c.dt);
}

void ImplicitShellsStage::advance(StepContext& c, double t, double dt) {
  const ShotSettings& shot = c.scene.shot;
  std::vector<std::vector<Vec3>> x0(c.shells.size()), v0(c.shells.size());
  for (std::size_t i = 0; i < c.shells.size(); ++i)
    if (steps_[i]) {
      x0[i] = c.shells[i]->x;
      v0[i] = c.shells[i]->v;
    }
  NewtonOptions opt = newton_options(shot);
  // The shell's tangent (kl_stiffness.h: per quadrature point Hessians) costs about 16
  // force evaluations, a CG iteration 2: a tangent at every other iterate pays. Measured
  // on the direct steel dent at cfl 0.125 (27 steps): 1.10 s a frame against 1.65 s
  // refreshing every 10 iterations and 1.71 s at every one.
  opt.refresh_after = 2;
  // The colliders at this (sub)step's end; the collider stages pose them again for theirs.
  for (Collider& col : c.colliders) col.begin_step(t, dt);
  double work = 0;  // the colliders' work, kept once every shell's step is taken
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    if (!steps_[i]) continue;
    const NewtonReport rep = steps_[i]->step(*c.shells[i], shot.gravity, t, dt, shot.implicit_theta,
                                             opt, shot.implicit_preconditioner, c.opt.serial,
                                             &c.colliders, c.advance_epoch, &work);
    c.implicit_frame.add(rep.iterations, rep.cg_iterations, rep.residual);
    if (rep.converged) continue;
    // Every shell back to the start, then the step in two halves.
    for (std::size_t k = 0; k < c.shells.size(); ++k)
      if (steps_[k]) {
        c.shells[k]->x = x0[k];
        c.shells[k]->v = v0[k];
      }
    ++c.implicit_frame.retries;
    if (0.5 * dt < shot.dt_min) {
      std::ostringstream os;
      os << "at t = " << t << " s the implicit step of shell '" << c.shells[i]->name()
         << "' did not converge even at dt = " << dt << " s (residual " << rep.residual
         << " m/s after " << rep.iterations << " Newton iterations"
         << (rep.line_search_failed ? ", the line search found no decrease" : "")
         << "; shot.implicit_tolerance = " << shot.implicit_tolerance
         << " m/s); raise shot.newton_max_iterations or shot.implicit_tolerance, or lower "
            "shot.dt_min";
      throw SimulationError(os.str());
    }
    advance(c, t, 0.5 * dt);
    advance(c, t + 0.5 * dt, 0.5 * dt);
    return;
  }
  c.energy_supplied += work;
}

}  // namespace shellmpm
