#include "sim/implicit/shell_step.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "sim/implicit/collider_penalty.h"
#include "sim/shell/kl_stiffness.h"

namespace shellmpm {
/// The Kirchhoff-Love stiffness of the last step's preconditioner, for the next steps.
struct ShellImplicitStep::StiffnessCache {
  std::shared_ptr<const SparseMatrixD> K;  ///< d^2E/dx^2 over the free components; null: none
  std::vector<int> dof_of;                 ///< the numbering it was assembled with
};

namespace {

class ShellObjective final : public ImplicitObjective {
 public:
  /// cache: where the stiffness is kept between steps; reuse: the first preconditioner
  /// of this step may take it from there (when the free components are the same).
  ShellObjective(const KirchhoffLoveShellT<double>& kl, const ShellObject& sh, const Vec3d& gravity,
                 double t, double dt, double theta, ImplicitPreconditioner pre, bool serial,
                 const std::vector<Collider>* colliders,
                 ShellImplicitStep::StiffnessCache* cache = nullptr, bool reuse = false)
      : kl_(kl), dt_(dt), theta_(theta), pre_(pre), serial_(serial), cache_(cache), reuse_(reuse) {
    n_ = sh.size();
    x0_.resize(n_);
    xb_.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      x0_[i] = sh.x[i].cast<double>();
      xb_[i] = x0_[i] + dt * (1 - theta) * sh.v[i].cast<double>();
    }
    sh.external_forces(gravity, x0_, fext_);
    loads_ = sh.load_forces();
    std::vector<Vec3d> target;
    sh.pin_targets(t, dt, held_, target);
    u0_.resize(3 * n_);
    v0_.resize(3 * n_);
    m_.resize(3 * n_);
    fixed_.assign(3 * n_, 0);
    for (std::size_t i = 0; i < n_; ++i)
      for (int a = 0; a < 3; ++a) {
        const std::size_t k = 3 * i + a;
        m_[k] = static_cast<double>(sh.mass[i]);
        u0_[k] = static_cast<double>(sh.v[i][a]);
        v0_[k] = u0_[k];
        if (held_[i] & (1u << a)) {
          fixed_[k] = 1;
          u0_[k] = (target[i][a] - xb_[i][a]) / (dt * theta);
        } else if (!(m_[k] > 0)) {
          fixed_[k] = 1;
        }
      }
    damping_ = sh.material().damping;
    beta_ = sh.material().stiffness_damping;
    penalty_.colliders = colliders;
    penalty_.mass = &sh.mass;
    penalty_.held = &held_;
    penalty_.dt = dt;
    penalty_.membrane = sh.material().youngs_modulus * sh.material().thickness;
    Eigen::AlignedBox<double, 3> box;
    for (const Vec3d& p : x0_) box.extend(p);
    length_ = std::max(box.diagonal().norm(), 1e-12);
    // The explicit share of the theta method: (1 - theta) of the forces at the start.
    explicit_.setZero(3 * n_);
    if (theta < 1) {
      std::vector<Vec3d> fn(n_, Vec3d::Zero());
      kl_.energy(x0_.data(), fn.data(), serial_, false);
      for (std::size_t k = 0; k < 3 * n_; ++k) {
        const double c = damping_ * m_[k] * v0_[k];
        explicit_[k] = (1 - theta) * (fn[k / 3][static_cast<int>(k % 3)] - c);
      }
      if (beta_ > 0) {
        VecXd kv0;
        stiffness_damping(v0_, kv0);
        explicit_ -= (1 - theta) * beta_ * kv0;
      }
    }
  }

  Eigen::Index size() const override { return static_cast<Eigen::Index>(3 * n_); }
  const VecXd& initial() const { return u0_; }
  const std::vector<Vec3d>& start() const { return x0_; }
  /// The moving colliders' work through the penalty at x over dt (collider_penalty.h).
  double collider_work(const std::vector<Vec3d>& x) const {
    double w = 0;
    collider_penalty(penalty_, x, nullptr, nullptr, &w);
    return w;
  }

  double energy(const VecXd& u) override {
    const std::vector<Vec3d> x = moved(u);
    double e = kl_.energy(x.data(), nullptr, serial_, false).total +
               collider_penalty(penalty_, x, nullptr, nullptr);
    for (std::size_t k = 0; k < 3 * n_; ++k) {
      const double du = u[k] - v0_[k];
      e += 0.5 * m_[k] * (du * du + dt_ * theta_ * damping_ * u[k] * u[k]) -
           dt_ * (fext_[k / 3][static_cast<int>(k % 3)] + explicit_[k]) * u[k];
    }
    if (beta_ > 0) {
      stiffness_damping(u, kv_);
      e += 0.5 * dt_ * theta_ * beta_ * u.dot(kv_);
    }
    return e;
  }

  void gradient(const VecXd& u, VecXd& g) override {
    full_gradient(u, g);
    project(g);
  }

  /// The pressure's and point loads' work over the step to x: their force at the step's
  /// start times the control points' displacement.
  double load_work(const std::vector<Vec3d>& x) const {
    double w = 0;
    for (std::size_t i = 0; i < loads_.size(); ++i) w += loads_[i].dot(x[i] - x0_[i]);
    return w;
  }

  /// The pins' work over the step at the solution u: at a held component the gradient
  /// is the impulse the pin applies (the momentum balance the free components meet), times
  /// the pin's velocity there.
  double pin_work(const VecXd& u) {
    bool moving = false;
    for (std::size_t k = 0; k < 3 * n_; ++k) moving = moving || (held_[k / 3] && u[k] != 0);
    if (!moving) return 0.0;
    VecXd g;
    full_gradient(u, g);
    double w = 0;
    for (std::size_t k = 0; k < 3 * n_; ++k)
      if (held_[k / 3] & (1u << (k % 3))) w += g[k] * u[k];
    return w;
  }

 private:
  /// The gradient before the fixed components are projected out.
  void full_gradient(const VecXd& u, VecXd& g) {
    f_.assign(n_, Vec3d::Zero());
    const std::vector<Vec3d> x = moved(u);
    kl_.energy(x.data(), f_.data(), serial_, false);
    pen_grad_.assign(n_, Vec3d::Zero());
    collider_penalty(penalty_, x, &pen_grad_, nullptr);
    g.resize(size());
    for (std::size_t k = 0; k < 3 * n_; ++k) {
      const int a = static_cast<int>(k % 3);
      g[k] = m_[k] * (u[k] - v0_[k] + dt_ * theta_ * damping_ * u[k]) -
             dt_ * (fext_[k / 3][a] + explicit_[k] + theta_ * (f_[k / 3][a] - pen_grad_[k / 3][a]));
    }
    if (beta_ > 0) {
      stiffness_damping(u, kv_);
      g += dt_ * theta_ * beta_ * kv_;
    }
  }

 public:
  void prepare_preconditioner(const VecXd& u) override {
    // Tangent at x* = x^n + dt u over the free components. A rebuild frees the old factor
    // first: two alive at once would double the peak (measured: 437 MiB against 320 on a
    // steel sheet of 80 x 80 elements that refreshed it).
    ldlt_.reset();
    std::vector<int> dof_of(3 * n_, -1);
    int dofs = 0;
    for (std::size_t k = 0; k < 3 * n_; ++k)
      if (!fixed_[k]) {
        dof_of[k] = dofs++;
      }
    dof_of_ = dof_of;
    if (reuse_ && cache_ && cache_->K && cache_->dof_of == dof_of) {
      reused_ = true;
      K_ = cache_->K;
    } else {
      // The old stiffness goes first (as the factor above): not two alive at once.
      K_.reset();
      if (cache_) cache_->K.reset();
      K_ = std::make_shared<const SparseMatrixD>(
          kl_stiffness_matrix(kl_, moved(u), dof_of, dofs, serial_));
      ++assembled_;
      if (cache_) {
        cache_->K = K_;
        cache_->dof_of = dof_of;
      }
    }
    reuse_ = false;  // a refresh within the solve assembles afresh
    build_preconditioner(u);
  }

  /// The preconditioner from the stiffness K_ (assembled or taken from the cache), with
  /// the step's dt, mass and damping and the collider penalty's Hessian at u.
  void build_preconditioner(const VecXd& u) {
    const std::vector<int>& dof_of = dof_of_;
    const std::vector<Vec3d> xs = moved(u);
    std::vector<Mat3d> kc;
    collider_penalty(penalty_, xs, nullptr, &kc);
    ldlt_.reset();
    SparseMatrixD A = *K_;
    const double th = theta_;
    A *= dt_ * dt_ * th * th + dt_ * th * beta_;
    for (std::size_t k = 0; k < 3 * n_; ++k)
      if (dof_of[k] >= 0) A.coeffRef(dof_of[k], dof_of[k]) += m_[k] * (1 + dt_ * th * damping_);
    for (std::size_t i = 0; i < n_; ++i) {
      if (kc[i].isZero()) continue;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          const int ra = dof_of[3 * i + a], rb = dof_of[3 * i + b];
          if (ra >= 0 && rb >= 0) A.coeffRef(ra, rb) += dt_ * dt_ * th * th * kc[i](a, b);
        }
    }
    if (pre_ == ImplicitPreconditioner::Factorised) {
      ldlt_ = factorise_positive(A);
      return;
    }
    // 3x3 diagonal blocks, made positive definite (eigenvalues at least the mass term).
    blocks_.assign(n_, Mat3d::Identity());
    for (std::size_t i = 0; i < n_; ++i) {
      Mat3d b = Mat3d::Zero();
      double mass = 0;
      for (int a = 0; a < 3; ++a) {
        const int ra = dof_of[3 * i + a];
        if (ra < 0) continue;
        mass = m_[3 * i + a] * (1 + dt_ * theta_ * damping_);
        for (int c = 0; c < 3; ++c) {
          const int rc = dof_of[3 * i + c];
          b(a, c) = rc >= 0 ? A.coeff(ra, rc) : (a == c ? 1.0 : 0.0);
        }
      }
      if (!(mass > 0)) continue;
      Eigen::SelfAdjointEigenSolver<Mat3d> es(0.5 * (b + b.transpose()));
      const Eigen::Vector3d ev = es.eigenvalues().cwiseMax(mass);
      blocks_[i] =
          es.eigenvectors() * ev.cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
    }
  }

  void apply_preconditioner(const VecXd& r, VecXd& z) const override {
    z.setZero(r.size());
    if (ldlt_) {
      VecXd rr(ldlt_->rows());
      for (std::size_t k = 0; k < 3 * n_; ++k)
        if (dof_of_[k] >= 0) rr[dof_of_[k]] = r[k];
      const VecXd zz = ldlt_->solve(rr);
      for (std::size_t k = 0; k < 3 * n_; ++k)
        if (dof_of_[k] >= 0) z[k] = zz[dof_of_[k]];
      return;
    }
    if (blocks_.empty()) {
      z = r;
      return;
    }
    for (std::size_t i = 0; i < n_; ++i) z.segment<3>(3 * i) = blocks_[i] * r.segment<3>(3 * i);
  }

  void project(VecXd& d) const override {
    for (std::size_t k = 0; k < 3 * n_; ++k)
      if (fixed_[k]) d[k] = 0;
  }

  /// Whether the solve started from the cached stiffness, and how often it assembled one.
  bool reused() const { return reused_; }
  int assembled() const { return assembled_; }

  std::vector<Vec3d> moved(const VecXd& u) const {
    std::vector<Vec3d> x(n_);
    for (std::size_t i = 0; i < n_; ++i) x[i] = xb_[i] + dt_ * theta_ * u.segment<3>(3 * i);
    return x;
  }

 private:
  /// kv = K(x^n) u by a central difference of the elastic force at the step's start.
  void stiffness_damping(const VecXd& u, VecXd& kv) {
    kv.setZero(size());
    const double umax = u.lpNorm<Eigen::Infinity>();
    if (umax == 0) return;
    const double h = 1e-7 * length_ / umax;
    std::vector<Vec3d> xp(n_), xm(n_), fp(n_, Vec3d::Zero()), fm(n_, Vec3d::Zero());
    for (std::size_t i = 0; i < n_; ++i) {
      xp[i] = x0_[i] + h * u.segment<3>(3 * i);
      xm[i] = x0_[i] - h * u.segment<3>(3 * i);
    }
    kl_.energy(xp.data(), fp.data(), serial_, false);
    kl_.energy(xm.data(), fm.data(), serial_, false);
    for (std::size_t i = 0; i < n_; ++i) kv.segment<3>(3 * i) = (fm[i] - fp[i]) / (2 * h);
  }

  const KirchhoffLoveShellT<double>& kl_;
  double dt_, theta_, damping_ = 0, beta_ = 0, length_ = 1;
  ImplicitPreconditioner pre_;
  bool serial_;
  ShellImplicitStep::StiffnessCache* cache_;
  bool reuse_, reused_ = false;
  int assembled_ = 0;  ///< stiffness assemblies in this solve
  std::shared_ptr<const SparseMatrixD> K_;
  std::size_t n_ = 0;
  std::vector<Vec3d> x0_, xb_, fext_, f_, pen_grad_;
  std::vector<Vec3d> loads_;  ///< pressure and point loads at x0_ (empty without)
  std::vector<std::uint8_t> held_;
  ColliderPenaltyInput penalty_;
  VecXd u0_, v0_, m_, kv_, explicit_;
  std::vector<char> fixed_;
  std::vector<int> dof_of_;
  std::unique_ptr<SparseLdlt> ldlt_;
  std::vector<Mat3d> blocks_;
};

}  // namespace

ShellImplicitStep::ShellImplicitStep(const ShellObject& sh)
    : kl_(sh.double_kl()), cache_(std::make_unique<StiffnessCache>()) {}
ShellImplicitStep::~ShellImplicitStep() = default;

void ShellImplicitStep::set_plasticity_in_solve(bool on) {
  kl_->set_plasticity_in_energy(on);
}

std::unique_ptr<ImplicitObjective> ShellImplicitStep::objective(
    const ShellObject& sh, const Vec3d& gravity, double t, double dt, double theta,
    ImplicitPreconditioner pre, bool serial, VecXd& u0, const std::vector<Collider>* colliders) {
  sh.sync_double_kl(*kl_);
  auto obj =
      std::make_unique<ShellObjective>(*kl_, sh, gravity, t, dt, theta, pre, serial, colliders);
  u0 = obj->initial();
  return obj;
}

NewtonReport ShellImplicitStep::step(ShellObject& sh, const Vec3d& gravity, double t, double dt,
                                     double theta, const NewtonOptions& opt,
                                     ImplicitPreconditioner pre, bool serial,
                                     const std::vector<Collider>* colliders, std::uint64_t epoch,
                                     double* collider_work) {
  sh.sync_double_kl(*kl_);
  if (epoch != epoch_) cache_->K.reset();
  epoch_ = epoch;
  bool reuse = cache_->K && age_ < kMaxStiffnessAge;
  NewtonReport total;
  for (;;) {
    ShellObjective obj(*kl_, sh, gravity, t, dt, theta, pre, serial, colliders, cache_.get(),
                       reuse);
    VecXd u = obj.initial();
    NewtonReport rep = newton_minimise(obj, u, opt);
    rep.iterations += total.iterations;
    rep.cg_iterations += total.cg_iterations;
    total = rep;
    const double per_newton = static_cast<double>(rep.cg_iterations) / std::max(rep.iterations, 1);
    if (obj.reused()) ++reused_steps_;
    if (obj.assembled() > 0) {
      age_ = 0;  // the cache holds this step's stiffness
      if (!obj.reused()) fresh_cg_per_newton_ = per_newton;
    } else {
      ++age_;
      // A stale stiffness that costs CG iterations (or the solve) is assembled afresh.
      if (per_newton > 2 * fresh_cg_per_newton_ + 4) cache_->K.reset();
      if (!rep.converged) {
        reuse = false;
        continue;  // again with the stiffness at this state
      }
    }
    if (!rep.converged) return rep;
    const std::vector<Vec3d> x = obj.moved(u);
    if (collider_work)
      *collider_work += theta * obj.collider_work(x) + obj.pin_work(u) + obj.load_work(x);
    for (std::size_t i = 0; i < sh.size(); ++i) {
      sh.x[i] = x[i].cast<Real>();
      sh.v[i] = u.segment<3>(3 * i).cast<Real>();
    }
    return rep;
  }
}

}  // namespace shellmpm
