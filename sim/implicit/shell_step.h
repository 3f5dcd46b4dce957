// The theta method (theta 1: backward Euler; 1/2: the trapezoidal rule, which damps
// nothing) for a shell without contact (its control points are the unknowns; no grid).
// One step from t to t + dt minimises over the control-point velocities u, with
// x(u) = x^n + dt ((1 - theta) v^n + theta u),
//   E(u) = sum_j m_j (|u_j - v_j^n|^2 + dt theta c |u_j|^2) / 2 + Psi_KL(x(u))
//          + dt theta beta u . K(x^n) u / 2 - dt (f_ext + (1 - theta) f^n) . u
// (c: mass damping, beta: Rayleigh stiffness damping with K at the step's start, f_ext:
// gravity, pressure and point loads at x^n, f^n = f_KL(x^n) - c m v^n - beta K v^n),
// whose stationarity is
//   m (u - v^n) = dt (f_ext + (1 - theta) f^n + theta (f_KL(x(u)) - c m u - beta K u)),
// the implicit counterpart of ShellObject::integrate. Pinned components are constraints
// (their velocity takes them to the pin pose at t + dt), as are points without mass.
// Denting is applied after the step by the denting stage, as in the explicit path.
// Colliders (posed for the step) add their penalty on the moved control points
// (collider_penalty.h); the projection stage then puts the points on the surface.
//
// The Kirchhoff-Love energy is evaluated in double (ShellObject::double_kl); Hessian
// products are central differences of the gradient (newton.h). Preconditioner: the
// tangent M (1 + dt theta c) + (dt^2 theta^2 + dt theta beta) K + dt^2 theta^2 K_collider,
// K from per quadrature point Hessians (kl_stiffness.h), factorised (`factorised`, CG
// then takes a few iterations per Newton step), or its 3x3 diagonal blocks
// (`block_jacobi`, no factorisation; many more CG iterations on stiff sheets). The
// stiffness is kept for the next steps of the same epoch
// (the solver's advance: a resume starts a new one, so it reproduces the run) and the
// preconditioner rebuilt from it with the step's dt, mass and collider terms; it is
// assembled afresh after kMaxStiffnessAge steps, when a step needs more than twice the
// CG iterations per Newton iteration of the last fresh one (plus 4), and when a solve
// with it does not converge (that step is then solved again with a fresh one).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/implicit/newton.h"
#include "sim/shell/shell_object.h"

namespace shellmpm {

class ShellImplicitStep {
 public:
  struct StiffnessCache;
  static constexpr int kMaxStiffnessAge = 20;

  explicit ShellImplicitStep(const ShellObject& sh);
  ~ShellImplicitStep();

  /// One step of sh from t to t + dt. On convergence writes sh.x and sh.v, and adds the
  /// moving colliders' work through the penalty to *collider_work (when given; the
  /// penalty's impulse times their velocity, collider_penalty.h), the moving pins' (their
  /// impulse on the held components times the pin's velocity) and the loads'; otherwise
  /// leaves sh as it was. The report says which.
  NewtonReport step(ShellObject& sh, const Vec3d& gravity, double t, double dt, double theta,
                    const NewtonOptions& opt, ImplicitPreconditioner pre, bool serial,
                    const std::vector<Collider>* colliders = nullptr, std::uint64_t epoch = 0,
                    double* collider_work = nullptr);
  /// Denting plasticity inside the solve (KirchhoffLoveShellT::set_plasticity_in_energy).
  void set_plasticity_in_solve(bool on);
  /// Steps whose preconditioner reused an earlier step's stiffness (for tests).
  long reused_steps() const { return reused_steps_; }
  /// The objective of that step (for tests), and in u0 its starting point (v^n, with
  /// the pinned components at their pin velocity).
  std::unique_ptr<ImplicitObjective> objective(const ShellObject& sh, const Vec3d& gravity,
                                               double t, double dt, double theta,
                                               ImplicitPreconditioner pre, bool serial, VecXd& u0,
                                               const std::vector<Collider>* colliders = nullptr);

 private:
  std::unique_ptr<KirchhoffLoveShellT<double>> kl_;
  std::unique_ptr<StiffnessCache> cache_;
  std::uint64_t epoch_ = 0;
  int age_ = 0;  ///< steps since the cached stiffness was assembled
  long reused_steps_ = 0;
  double fresh_cg_per_newton_ = 0;
};

}  // namespace shellmpm
