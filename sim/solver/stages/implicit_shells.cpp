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

namespace {

NewtonOptions newton_options(const ShotSettings& s) {
  NewtonOptions o;
  o.tolerance = s.implicit_tolerance;
  o.max_iterations = s.newton_max_iterations;
  o.max_cg_iterations = s.cg_max_iterations;
  return o;
}

}  // namespace

void ImplicitShellsStage::run(StepContext& c) {
  if (steps_.empty())
    for (std::size_t i = 0; i < c.shells.size(); ++i)
      steps_.push_back(c.contacts[i] ? nullptr : std::make_unique<ShellImplicitStep>(*c.shells[i]));
  const ShotSettings& shot = c.scene.shot;
  const NewtonOptions opt = newton_options(shot);
  std::vector<std::vector<Vec3>> x0(c.shells.size()), v0(c.shells.size());
  for (std::size_t i = 0; i < c.shells.size(); ++i)
    if (steps_[i]) {
      x0[i] = c.shells[i]->x;
      v0[i] = c.shells[i]->v;
    }
  double dt = c.dt;
  while (true) {
    std::size_t failed = c.shells.size();
    NewtonReport bad;
    for (std::size_t i = 0; i < c.shells.size() && failed == c.shells.size(); ++i) {
      if (!steps_[i]) continue;
      const NewtonReport rep = steps_[i]->step(*c.shells[i], shot.gravity, c.time, dt, opt,
                                               shot.implicit_preconditioner, c.opt.serial);
      c.implicit_frame.add(rep.iterations, rep.cg_iterations, rep.residual);
      if (!rep.converged) {
        failed = i;
        bad = rep;
      }
    }
    if (failed == c.shells.size()) break;
    for (std::size_t i = 0; i < c.shells.size(); ++i)
      if (steps_[i]) {
        c.shells[i]->x = x0[i];
        c.shells[i]->v = v0[i];
      }
    ++c.implicit_frame.retries;
    dt *= 0.5;
    if (dt < shot.dt_min) {
      std::ostringstream os;
      os << "at t = " << c.time << " s the implicit step of shell '" << c.shells[failed]->name()
         << "' did not converge even at dt = " << 2 * dt << " s (residual " << bad.residual
         << " m/s after " << bad.iterations << " Newton iterations"
         << (bad.line_search_failed ? ", the line search found no decrease" : "")
         << "; shot.implicit_tolerance = " << shot.implicit_tolerance
         << " m/s); raise shot.newton_max_iterations or shot.implicit_tolerance, or lower "
            "shot.dt_min";
      throw SimulationError(os.str());
    }
  }
  c.dt = dt;
  ++c.implicit_frame.steps;
}

}  // namespace shellmpm
