// The shells in contact in the implicit grid step (grid_step.h): their control points and
// contact particles live on the grid, so their energies are functions of the node
// velocities u. With the control point j's weights w_nj (at x_j^n) and the contact
// particle p's gradient weights g_np (the mass-weighted least-squares gradient of
// shell_transfer.h, at its position x_p^n):
//   X_j(u)   = x_j^n + dt sum_n w_nj u_n              (a pinned component: its pin pose)
//   a3E_p(u) = a3E_p^n + dt sum_n (g_np . a3E_p^n) u_n
//   E_shells(u) = Psi_KL(X) + sum_p V_p psi(a_1(X), a_2(X), a3E_p)
//                 + sum_j (dt c m_j |v_j|^2 / 2 - dt f_ext,j . v_j),  v_j = (X_j - x_j^n) / dt,
// the Kirchhoff-Love energy at the moved control points, the contact particles' QR
// energy with a3E advanced by the same linearisation G2P applies (supplement sections 2
// and 4-5), mass damping c and the external loads (pressure, point loads; gravity acts on
// the nodes). The friction return mapping and denting follow the step (their stages), as
// in the explicit path. Everything is double; the weights are the float ones G2P uses.
//
// Preconditioner (prepare): the Hessian of the shells' terms in their own unknowns, the
// control points and the contact particles' a3E (Kirchhoff-Love from each quadrature
// point's Hessian, kl_stiffness.h; each contact particle's Hessian in (a_1, a_2, a3E) by
// differences of its gradient, made positive semi-definite, brought to its control points
// and a3E by the chain rule), brought to the nodes by Woodbury's identity, with the
// control points' coupling through shared nodes exact for shells of a few thousand
// unknowns and lumped above (see prepare).
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/contact/field_slots.h"
#include "sim/contact/shell_transfer.h"
#include "sim/implicit/collider_penalty.h"
#include "sim/implicit/newton.h"
#include "sim/implicit/symmetric_factor.h"
#include "sim/shell/fd_stiffness.h"
#include "sim/shell/kirchhoff_love.h"

namespace shellmpm {

using PadD = std::array<Vec3d, kPadNodes>;

/// A grid shell's double Kirchhoff-Love copy (ShellObject::double_kl) and its coupling.
struct GridShellKl {
  std::unique_ptr<KirchhoffLoveShellT<double>> kl;
  std::vector<std::vector<int>> coupling;
};

/// The largest joint space (control-point components and contact-particle normals with
/// stiffness) whose coupling the preconditioner keeps exactly (see prepare). Measured (2
/// threads, the exact factor by MUMPS): the steel dent's first moving frame at 1,938
/// unknowns (15 x 15) exact 15 s against lumped 67 s, at about 4,900 (24 x 24) 115 s
/// against 154 s; cloth_drape's first six frames (14,643) 163 s against 140 s.
constexpr int kExactCouplingLimit = 8000;

class GridShellTerms {
 public:
  /// grid: binned with the shells' points in front (table), after P2G (node masses);
  /// kls: per grid shell, synced with its plastic state. t, dt: the step.
  GridShellTerms(const SparseGrid& grid, const ShellPointTable& table,
                 const std::vector<GridShell>& shells, const std::vector<GridShellKl>& kls,
                 double t, double dt, bool serial);

  /// Colliders (posed at the end of the step; null: none): each free control point inside
  /// one adds the penalty kappa_j phi(X_j)^2 / 2, with kappa_j = kColliderPenalty
  /// max(m_j / dt^2, E h) (its inertia over the step or the sheet's membrane stiffness,
  /// whichever is larger). The nodes' collider constraints reach a control point only
  /// through the stencil nodes inside the collider; over a long step the free ones let
  /// the stiff sheet lag behind a ball pressing into it (2.5 mm of a 3 cm press at 1e-4 s),
  /// which the explicit path's per-step projection of the control points does not allow.
  void set_colliders(const std::vector<Collider>* colliders) { colliders_ = colliders; }
  /// The moving colliders' work on the control points over the step through the penalty,
  /// at the positions of the last evaluation [J] (collider_penalty.h).
  double collider_work() const;
  /// The pins' work over the step in holding their components against the shells' forces
  /// at the last gradient evaluation: dt dE/dX . v on each held component [J]. (The rest
  /// of their impulse, against the nodes' motion, is G2P's: pin_transfer_work.)
  double pin_work() const;
  /// The pressure's and point loads' work on the free components over the step, to the
  /// positions of the last evaluation [J] (a held component's load is the pin's).
  double load_work() const;
  /// The shells' own velocities at shared nodes (field_slots.h; null: none): a control
  /// point reads slot k's velocity (*slot_vel)[k] at a node of slot_of, and adds its
  /// offset. The objective's unknowns are then the nodes' 3 N_nodes components followed by
  /// the slots' (vel holds the nodes').
  void set_slots(const FieldSlots* fs, const std::vector<Vec3d>* slot_vel) {
    slots_ = fs;
    slot_vel_ = slot_vel;
  }
  /// The joint size up to which prepare couples exactly (kExactCouplingLimit; 0: never).
  void set_exact_limit(int m) { exact_limit_ = m; }
  /// E_shells at the node velocities in the particle blocks' padded buffers.
  double energy(const std::vector<PadD>& vel);
  /// Adds dE_shells/du to the particle blocks' padded buffers (summed per node by the
  /// caller), and with slots dE_shells/dU per slot to slot_grad; returns E_shells.
  double gradient(const std::vector<PadD>& vel, std::vector<PadD>& grad,
                  std::vector<Vec3d>* slot_grad = nullptr);

  /// The preconditioner's shell part at vel (objective dofs 3 (g kBlockNodes + n) + a;
  /// minv: the inverse of the rest of the objective's Hessian, the nodes' mass and bulk
  /// diagonal, on the constrained subspace: 3x3 blocks Pi D^-1 Pi^T per node, zero where
  /// a node is fixed; the same at every call on one GridShellTerms). With the joint unknowns y =
  /// (the free control-point components, every contact particle's a3E), y = J u + const, and K
  /// their Hessian (Kirchhoff-Love and contact, made positive semi-definite), the Hessian is M +
  /// J^T K J; by Woodbury its inverse is M^-1 - M^-1 J^T (K^-1 + S)^-1 J M^-1 with S = J M^-1 J^T,
  /// which couples the control points and contact particles that share nodes. Joint spaces up to
  /// the exact limit (kExactCouplingLimit unknowns with stiffness) keep S exactly: (K^-1 + S)^-1
  /// comes from one sparse LDL^T of the quasi-definite [S I; I -K] of twice their size, and the
  /// preconditioner inverts the shells' part of the Hessian (CG then needs 1-3 iterations a Newton
  /// step on the steel dent against about 200). The factor is MUMPS's (symmetric_factor.h); J and S
  /// are formed at the step's first prepare and kept (J and minv are fixed within a step), and the
  /// factor's analysis is reused while the pattern holds. Larger ones (a cloth of 1,681 control
  /// points and 3,200 contact particles: 14,643 unknowns, whose factor has 17 million
  /// entries and takes 2-3 s) lump S into S~,
  /// its absolute row sums (S~ >= S, so the approximation stays positive definite), and
  /// apply (K^-1 + S~)^-1 as S~^-1 - S~^-1 (K + S~^-1)^-1 S~^-1: one factorisation of K's
  /// size and sparsity.
  void prepare(const std::vector<PadD>& vel, const SparseMatrixD& minv);
  /// M^-1 changed within the step (friction's stiffness added at collider nodes,
  /// grid_step.cpp): the next prepare forms S again.
  void minv_changed() {
    Sall_ = SparseMatrixD();
    kept_.clear();
  }
  /// Whether the last prepare kept the coupling exactly.
  bool exact() const { return exact_; }
  /// z = P^-1 r (after prepare).
  void apply(const VecXd& r, const SparseMatrixD& minv, VecXd& z) const;
  /// Adds diag(J^T K J) at vel to diag (the block_jacobi preconditioner).
  void add_diagonal(const std::vector<PadD>& vel, VecXd& diag);

 private:
  struct Shell {
    const GridShell* gs = nullptr;
    const GridShellKl* kl = nullptr;
    std::vector<Vec3d> x0, X, v, f, fext, dX;  ///< start, moved, velocity, forces, loads, dE/dX
    std::vector<std::uint8_t> held;
    std::vector<Vec3d> target;
    /// dE/dX on the held components at the last gradient evaluation (what the pins hold
    /// them against); empty when nothing is held.
    std::vector<Vec3d> held_grad;
    double damping = 0;
    double length = 1;
    double membrane = 0;  ///< E h [N/m]
  };
  /// A contact particle's stencil: 27 coefficients dt (g_n . a3E^n), or none.
  struct Site {
    std::uint32_t shell, local;
    int lx, ly, lz;  ///< stencil base in its particle block's padded buffer
    bool any;
    double ga[27];
  };
  /// Calls f(n, px, py, pz) for the 27 stencil nodes of st (n as in ga; padded-buffer
  /// coordinates in its particle block).
  template <class F>
  static void each_site_node(const Site& st, F&& f) {
    int n = 0;
    for (int x = 0; x < 3; ++x)
      for (int y = 0; y < 3; ++y)
        for (int z = 0; z < 3; ++z, ++n) f(n, st.lx + x, st.ly + y, st.lz + z);
  }
  /// X of every control point from vel; v_j kept in V_.
  void move(const std::vector<PadD>& vel);
  /// a3E(u) of every contact particle from vel.
  void advance_sites(const std::vector<PadD>& vel);
  /// Energy at the moved state; with `grad`, dE/dX into Shell::dX and dE/da3E into G3_.
  double evaluate(bool grad);
  /// K at vel, and J with J non-null (see prepare); N: the objective's size.
  void joint(const std::vector<PadD>& vel, Eigen::Index N, SparseMatrixD* J, SparseMatrixD& K);

  /// The collider penalty of the control points at X into S.dX (with grad) and its
  /// Hessian kappa n n^T (with K: per control point, zero if none); returns its energy.
  double collider_penalty(Shell& S, bool grad, std::vector<Mat3d>* K) const;
  ColliderPenaltyInput penalty_input(const Shell& S) const;

  const SparseGrid& grid_;
  const ShellPointTable& table_;
  const std::vector<Collider>* colliders_ = nullptr;
  const FieldSlots* slots_ = nullptr;
  const std::vector<Vec3d>* slot_vel_ = nullptr;
  /// Slot k of shell s at global node `node`, or -1.
  int slot_at(std::size_t s, std::size_t node) const {
    if (!slots_ || slots_->slot_of[s].empty()) return -1;
    return slots_->slot_of[s][node];
  }
  /// The objective's index of slot k's first component.
  Eigen::Index slot_dof(int k) const {
    return 3 * static_cast<Eigen::Index>(grid_.num_grid_blocks() * kBlockNodes + std::size_t(k));
  }
  double dt_;
  bool serial_;
  std::vector<Shell> sh_;
  std::vector<Site> sites_;
  std::vector<std::uint32_t> site_start_;  ///< per shell: its first entry in sites_
  std::vector<Vec3d> a3_, G3_;             ///< per site: a3E(u), V dpsi/da3E
  SparseMatrixD Jall_, Sall_;              ///< J and S of every joint unknown (the step's)
  std::vector<int> kept_;                  ///< per joint unknown its kept row, or -1
  SparseMatrixD P_, Pt_;                   ///< the kept rows' selection and its transpose
  SparseMatrixD J_, Sk_;                   ///< J and S on the kept rows
  std::unique_ptr<SymmetricFactor> qd_;    ///< the exact coupling's factor (kept: its analysis)
  std::unique_ptr<SparseLdlt> ldlt_;       ///< the lumped coupling's factor
  VecXd sinv_;                             ///< lumped: S~^-1
  bool exact_ = false;                     ///< the last prepare coupled exactly
  int exact_limit_ = kExactCouplingLimit;
};

}  // namespace shellmpm
