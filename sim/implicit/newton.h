// Backward Euler as an energy minimisation (the optimisation-integrator view of Gast,
// Schroeder, Stomakhin, Jiang and Teran 2015): one implicit step minimises an objective
// E(u) over the step's unknown velocities u, E = kinetic term + dt^2-scaled elastic energy
// at the moved positions - work of the external loads. This file holds the minimiser,
// independent of what the unknowns are (sim/implicit/shell_step.h: a shell's control
// points; sim/implicit/grid_step.h: the grid nodes).
//
// Newton's method with a backtracking line search on E itself (Armijo's condition, so
// the objective decreases at every accepted iteration, down to the round-off of its
// evaluation: see NewtonOptions::energy_round_off). Each Newton direction is a
// truncated preconditioned conjugate-gradient solve of H d = -g, matrix-free: H d comes
// from the objective (by default a central difference of the gradient along d, in
// double). Definiteness: CG stops at the first direction of non-positive curvature and
// keeps what it has (or, on the first one, the preconditioned gradient), so d is always
// a descent direction. Constraints (pins, colliders) are linear: the objective zeroes
// the constrained entries of every direction (project), inside CG as outside.
//
// Everything is double and sequential over vectors (Eigen's dot products in index
// order), so a solve is bitwise the same for any thread count as long as the
// objective's own evaluations are.
#pragma once
#include <Eigen/Core>
#include <vector>

namespace shellmpm {

using VecXd = Eigen::VectorXd;

/// What a Newton solve minimises. Unknowns are a flat vector of doubles.
class ImplicitObjective {
 public:
  virtual ~ImplicitObjective() = default;
  virtual Eigen::Index size() const = 0;
  /// E(u) [J].
  virtual double energy(const VecXd& u) = 0;
  /// dE/du at u into g (sized by the caller); constrained entries are zero.
  virtual void gradient(const VecXd& u, VecXd& g) = 0;
  /// out = H(u) d for a projected d. Default: central difference of the gradient,
  /// (g(u + h d) - g(u - h d)) / 2h with h = 1e-6 (1 + |u|_inf) / |d|_inf.
  virtual void hessian_product(const VecXd& u, const VecXd& d, VecXd& out);
  /// Builds the preconditioner at u (called once per solve, at the start, and again every
  /// refresh_every() iterations). Default: none.
  virtual void prepare_preconditioner(const VecXd& u) { (void)u; }
  /// How many iterations the preconditioner is worth keeping, for an objective that knows
  /// better than NewtonOptions::refresh_after (asked after each build; 0: the options).
  virtual int refresh_every() const { return 0; }
  /// z = P^-1 r (a symmetric positive definite approximation of H^-1). Default: z = r.
  virtual void apply_preconditioner(const VecXd& r, VecXd& z) const { z = r; }
  /// Zeroes the constrained entries of a direction.
  virtual void project(VecXd& d) const = 0;

 protected:
  VecXd hp_plus_, hp_minus_, hp_u_;  // scratch of the default hessian_product
};

struct NewtonOptions {
  /// Converged when the residual, the largest entry of the correction P^-1 g the
  /// gradient asks for (a velocity for the objectives here), is at most this [m/s], and
  /// so is the Newton step CG then finds (a weak preconditioner can make P^-1 g small
  /// where the step is not).
  /// (Not max |g_i| / m_i: where the stiffness dominates the mass, dt^2 K >> m, that
  /// overstates the correction by dt^2 K / m and stalls at the gradient's round-off.)
  double tolerance = 1e-4;
  int max_iterations = 30;  ///< Newton iterations
  int max_cg_iterations = 500;
  /// CG stops when |r|_P <= eta |g|_P, eta = clamp(sqrt(residual / first residual),
  /// cg_min_eta, cg_max_eta) (inexact Newton: loose far away, tight near the solution).
  double cg_max_eta = 0.5, cg_min_eta = 1e-4;
  /// Rebuilds the preconditioner at the current iterate every this many iterations of a
  /// solve that has not converged (0: never; 1: every iteration): one built at the start of a step
  /// with large rotations stops describing H, and CG then needs many more iterations.
  int refresh_after = 0;
  /// Armijo constant c1 and the most halvings of the step length.
  double armijo = 1e-4;
  int max_halvings = 30;
  /// Relative round-off of E's evaluation: where the decrease a full step promises is
  /// below energy_round_off |E|, Armijo's test cannot see it, and the full step is taken
  /// if E does not rise beyond that and the residual falls.
  double energy_round_off = 1e-11;
};

struct NewtonReport {
  bool converged = false;
  int iterations = 0;               ///< Newton iterations taken
  int cg_iterations = 0;            ///< summed over the Newton iterations
  double residual = 0;              ///< at the end [m/s]
  double residual0 = 0;             ///< at the start [m/s]
  bool line_search_failed = false;  ///< no decrease along the last direction
  int round_off_steps = 0;          ///< steps taken at round-off level (see energy_round_off)
  std::vector<double> energies;     ///< E at the start and after each iteration
};

/// Minimises obj from u (in place; u must satisfy the constraints, which projected
/// directions keep). Stops at residual <= tolerance, after max_iterations, or when the
/// line search finds no decrease (then converged is false).
NewtonReport newton_minimise(ImplicitObjective& obj, VecXd& u, const NewtonOptions& opt);

}  // namespace shellmpm
