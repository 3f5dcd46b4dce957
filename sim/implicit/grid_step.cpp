#include "sim/implicit/grid_step.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "sim/core/parallel.h"
#include "sim/implicit/friction_potential.h"
#include "sim/mpm/bspline.h"

namespace shellmpm {
namespace {

using Pad = PadD;

constexpr int kRefreshExact = 3, kRefreshLumped = 10;
/// Friction inside the solve: the solves with the normal impulses of the one before.
constexpr int kFrictionLags = 1;
/// A solve that started from bounds within this share of those its solution needs (summed
/// over the nodes) is not solved again (GridStepInput::friction_bounds).
constexpr double kLagTolerance = 0.25;

/// A stencil node: offsets from the weights' base, padded-buffer index, weight.
struct StencilNodeD {
  int i, j, k, pad;
  double w;
};

class GridObjective final : public ImplicitObjective {
 public:
  GridObjective(const GridStepInput& in, double dt) : in_(in), grid_(*in.grid), dt_(dt) {
    nb_ = grid_.num_grid_blocks();
    const std::size_t nodes = nb_ * kBlockNodes;
    const std::size_t slots = in.slots ? in.slots->num_slots() : 0;
    nodes_ = nodes;
    const std::size_t all = nodes + slots;
    m_.setZero(static_cast<Eigen::Index>(all));
    vhat_.setZero(3 * m_.size());
    fixed_.assign(3 * all, 1);
    normal_.assign(all, Vec3d::Zero());
    collider_of_.assign(all, -1);
    sticky_of_.assign(all, -1);
    position_.assign(all, Vec3d::Zero());
    u0_.setZero(3 * m_.size());
    vbuf_.resize(grid_.num_particle_blocks());
    fbuf_.resize(grid_.num_particle_blocks());
    // Where the shells keep fields of their own, the bulk field's group stands for the node.
    std::vector<int> base(in.slots ? nodes : 0, -1);
    if (in.slots)
      for (std::size_t k = 0; k < in.slots->base_node.size(); ++k)
        base[in.slots->base_node[k]] = static_cast<int>(k);
    for (std::size_t g = 0; g < nb_; ++g) {
      const Vec3i corner = unpack_block(grid_.gblock_key[g]) * kBlockSize;
      for (int n = 0; n < kBlockNodes; ++n) {
        const GridNode& nd = grid_.gblock_nodes[g][n];
        if (!(nd.m > 0)) continue;
        const std::size_t i = g * kBlockNodes + n;
        const double m = static_cast<double>(nd.m);
        m_[i] = m;
        for (int a = 0; a < 3; ++a) {
          vhat_[3 * i + a] = static_cast<double>(nd.v[a]) / m;  // p / m, in double
          fixed_[3 * i + a] = 0;
        }
        if (!base.empty() && base[i] >= 0) {
          const auto k = static_cast<std::size_t>(base[i]);
          m_[i] = static_cast<double>(in.slots->base_m[k]);
          vhat_.segment<3>(3 * i) = in.slots->base_v[k].cast<double>();
        }
        const Vec3i c(corner[0] + n / 16, corner[1] + (n / 4) % 4, corner[2] + n % 4);
        constrain(i, c);
      }
    }
    for (std::size_t k = 0; k < slots; ++k) {
      const std::size_t i = nodes + k;
      m_[static_cast<Eigen::Index>(i)] = static_cast<double>(in.slots->slot_m[k]);
      vhat_.segment<3>(3 * i) = in.slots->slot_v[k].cast<double>();
      u0_.segment<3>(3 * i) = vhat_.segment<3>(3 * i) + dt_ * in_.gravity;
      for (int a = 0; a < 3; ++a) fixed_[3 * i + a] = 0;
    }
    if (in.start) start_from(*in.start);
    slot_vel_.assign(slots, Vec3d::Zero());
    slot_grad_.assign(slots, Vec3d::Zero());
    if (in.shells && in.slots) in.shells->set_slots(in.slots, &slot_vel_);
    prepare_diagonal();
  }

  Eigen::Index size() const override { return vhat_.size(); }
  /// Slot k's velocity in u.
  Vec3d slot_velocity(const VecXd& u, std::size_t k) const {
    return u.segment<3>(3 * static_cast<Eigen::Index>(nodes_ + k));
  }
  const VecXd& initial() const { return u0_; }

  double energy(const VecXd& u) override {
    scatter(u);
    double e = elastic(nullptr);
    if (in_.shells) e += in_.shells->energy(vbuf_);  // slot_vel_ from scatter
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
      if (!(m_[i] > 0)) continue;
      const Vec3d du = u.segment<3>(3 * i) - vhat_.segment<3>(3 * i);
      e += m_[i] * (0.5 * du.squaredNorm() - dt_ * in_.gravity.dot(u.segment<3>(3 * i)));
    }
    if (friction_on_)
      for (std::size_t k = 0; k < fric_.size(); ++k)
        e += fric_[k].energy(u.segment<3>(3 * fric_node_[k]));
    return e;
  }

  void gradient(const VecXd& u, VecXd& g) override {
    raw_gradient(u, g);
    project(g);
  }

  /// Friction inside the solve (GridStepInput::friction_in_solve): each slip or separate
  /// collider node's Coulomb bound, friction * (g . n), from the constraint's normal
  /// impulse at u (g the unprojected gradient without friction: m (u - v^n) - dt f = g);
  /// 0 where it pulls or has no friction.
  std::vector<double> friction_bounds(const VecXd& u) {
    const bool on = friction_on_;
    friction_on_ = false;
    VecXd g;
    raw_gradient(u, g);
    friction_on_ = on;
    std::vector<double> b;
    bounds_from(g, b);
    return b;
  }

  /// The bounds of friction_bounds from that gradient g.
  void bounds_from(const VecXd& g, std::vector<double>& b) const {
    b.assign(nodes_, 0.0);
    for (std::size_t i = 0; i < nodes_; ++i) {
      if (collider_of_[i] < 0) continue;
      const double mu = (*in_.colliders)[collider_of_[i]].desc().friction;
      const double jn = g.segment<3>(3 * static_cast<Eigen::Index>(i)).dot(normal_[i]);
      if (mu > 0 && jn > 0) b[i] = mu * jn;
    }
  }

  /// Whether bounds b differ from those the last solve used by more than kLagTolerance
  /// of their sum.
  bool friction_moved(const std::vector<double>& b) const {
    double diff = 0, sum = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
      const int k = friction_on_ && i < fric_of_.size() ? fric_of_[i] : -1;
      diff += std::abs(b[i] - (k < 0 ? 0.0 : fric_[std::size_t(k)].bound));
      sum += b[i];
    }
    return diff > kLagTolerance * sum;
  }

  /// The lagged potential of friction_potential.h at the nodes with a bound in b (sized
  /// by the nodes), its Hessian at u for the preconditioner. Returns whether any node has
  /// friction; the next solve minimises with it.
  bool set_friction(const std::vector<double>& b, const VecXd& u) {
    fric_.clear();
    fric_node_.clear();
    fric_h_.clear();
    fric_of_.assign(static_cast<std::size_t>(m_.size()), -1);
    for (std::size_t i = 0; i < nodes_ && i < b.size(); ++i) {
      if (collider_of_[i] < 0 || !(b[i] > 0)) continue;
      const Collider& col = (*in_.colliders)[collider_of_[i]];
      LaggedFriction f;
      f.n = normal_[i];
      f.vc = col.velocity(position_[i]);
      f.bound = b[i];
      f.eps = in_.friction_stick_speed;
      const auto e = static_cast<Eigen::Index>(i);
      fric_of_[i] = static_cast<int>(fric_.size());
      fric_.push_back(f);
      fric_node_.push_back(e);
      fric_h_.push_back(f.hessian(u.segment<3>(3 * e)));
    }
    friction_on_ = !fric_.empty();
    // The preconditioner's M takes friction's Hessian at u, fixed for the solve (the
    // shells' S = J M^-1 J^T is formed once per M).
    if (friction_on_ && in_.shells) in_.shells->minv_changed();
    return friction_on_;
  }

  /// Ends the step at the solution u. Without friction in the solve, Coulomb friction at
  /// the slip and separate collider nodes (the explicit collider stage's rule, with the
  /// constraint's impulse for the approach it stops): the normal impulse per unit mass
  /// the constraint applies at u, j = (g . n) / m from the unprojected gradient, removes
  /// up to friction * j of the tangential velocity relative to the collider. Returns the
  /// moving colliders' and pins' work over the step (energy_audit.h): each constrained
  /// node's impulse (g, which with friction in the solve includes friction's, plus the
  /// friction applied here) times the collider's velocity there, plus the penalty's on
  /// shell control points and the pins' against the shells' forces on the components they
  /// hold, and the shells' loads'. With `bounds`, also friction_bounds at u.
  double finish(VecXd& u, std::vector<double>* bounds) {
    friction_on_ = false;  // g: the constraints' impulse, friction's share included
    VecXd g;
    raw_gradient(u, g);
    if (bounds) bounds_from(g, *bounds);
    double work =
        in_.shells ? in_.shells->collider_work() + in_.shells->pin_work() + in_.shells->load_work()
                   : 0.0;
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
      if (sticky_of_[i] >= 0) {
        const Collider& col = (*in_.colliders)[sticky_of_[i]];
        if (col.animated()) work += g.segment<3>(3 * i).dot(col.velocity(position_[i]));
      }
      if (collider_of_[i] < 0) continue;
      const Collider& col = (*in_.colliders)[collider_of_[i]];
      const double mu = in_.friction_in_solve ? 0.0 : col.desc().friction;
      const Vec3d& n = normal_[i];
      const double j = g.segment<3>(3 * i).dot(n) / m_[i];
      const Vec3d vc = col.velocity(position_[i]);
      const Vec3d before = u.segment<3>(3 * i);
      if (col.animated()) work += g.segment<3>(3 * i).dot(vc);
      if (!(mu > 0) || !(j > 0)) continue;
      const Vec3d vr = before - vc;
      const double vn = vr.dot(n);
      const Vec3d vt = vr - vn * n;
      const double tn = vt.norm(), drop = mu * j;
      u.segment<3>(3 * i) =
          vc + vn * n + (tn <= drop ? Vec3d::Zero() : Vec3d(vt * (1 - drop / tn)));
      if (col.animated()) work += m_[i] * (u.segment<3>(3 * i) - before).dot(vc);
    }
    return work;
  }

 private:
  /// dE/du without the constraints' projection.
  void raw_gradient(const VecXd& u, VecXd& g) {
    scatter(u);
    elastic(&fbuf_);
    std::fill(slot_grad_.begin(), slot_grad_.end(), Vec3d::Zero());
    if (in_.shells) in_.shells->gradient(vbuf_, fbuf_, &slot_grad_);
    g.setZero(size());
    gather(fbuf_, g);
    for (std::size_t k = 0; k < slot_grad_.size(); ++k)
      g.segment<3>(3 * static_cast<Eigen::Index>(nodes_ + k)) += slot_grad_[k];
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
      if (!(m_[i] > 0)) continue;
      g.segment<3>(3 * i) +=
          m_[i] * (u.segment<3>(3 * i) - vhat_.segment<3>(3 * i) - dt_ * in_.gravity);
    }
    if (friction_on_)
      for (std::size_t k = 0; k < fric_.size(); ++k) {
        const Eigen::Index i = 3 * fric_node_[k];
        g.segment<3>(i) += fric_[k].gradient(u.segment<3>(i));
      }
  }

 public:
  void apply_preconditioner(const VecXd& r, VecXd& z) const override {
    if (shells_ready_) {
      in_.shells->apply(r, minv_, z);
      return;
    }
    z = r.cwiseQuotient(diag_);
  }

  /// With shells: their part of the Hessian (grid_shells.h, prepare), or with
  /// block_jacobi its diagonal added to the nodes' own.
  void prepare_preconditioner(const VecXd& u) override {
    if (!in_.shells) {
      diag_ = base_diag_;
      add_friction_diagonal();
      return;
    }
    scatter(u);
    if (in_.factorise) {
      projected_inverse_diagonal();
      in_.shells->prepare(vbuf_, minv_);
      shells_ready_ = true;
      return;
    }
    diag_ = base_diag_;
    in_.shells->add_diagonal(vbuf_, diag_);
    add_friction_diagonal();
  }

  /// Factorised shells: every kRefreshExact iterations with the exact coupling, every
  /// kRefreshLumped with the lumped one. Measured on the steel dent's first moving frame:
  /// exact, refreshing at every iteration, 219 Newton iterations, 628 CG, 50 s; every 3,
  /// 267, 1,157, 25 s; every 10, 409, 4,216 and 4 retries, 23 s. The lumped factor is
  /// cheaper, its preconditioner weaker, and the cloth drape kept 10.
  int refresh_every() const override {
    if (!shells_ready_) return 0;
    return in_.shells->exact() ? kRefreshExact : kRefreshLumped;
  }

  void project(VecXd& d) const override {
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
      Vec3d n;
      const bool cut = free_normal(i, n);
      if (n.squaredNorm() > 0) {
        const double s = n.dot(d.segment<3>(3 * i));
        d.segment<3>(3 * i) -= (cut ? s / n.squaredNorm() : s) * n;
      }
      for (int a = 0; a < 3; ++a)
        if (fixed_[3 * i + a]) d[3 * i + a] = 0;
    }
  }

 private:
  /// Node i's slip normal within its free components (n with the wall-fixed ones zeroed):
  /// project removes the velocity along it and zeroes the fixed components, the
  /// orthogonal projection onto the velocities both constraints allow. Returns whether a
  /// fixed component cut n (a collider's oblique normal at an edge, beside a domain
  /// wall); only then is n no longer unit. Projecting along the whole n and then zeroing
  /// the fixed components is not a projection there (applied twice it moves the vector
  /// again): Newton's directions left the constraints' subspace, the projected gradient
  /// was not the energy's slope along them, and the line search found no decrease (the
  /// can on sand at the draft preset, frame 3, at every halving of the step).
  bool free_normal(Eigen::Index i, Vec3d& n) const {
    n = normal_[static_cast<std::size_t>(i)];
    bool cut = false;
    for (int a = 0; a < 3; ++a)
      if (fixed_[static_cast<std::size_t>(3 * i + a)] && n[a] != 0) {
        n[a] = 0;
        cut = true;
      }
    return cut;
  }

  /// Walls and colliders on node i (grid coordinate c), from its predicted velocity; sets
  /// u0_ for the node.
  void constrain(std::size_t i, const Vec3i& c) {
    Vec3d v = vhat_.segment<3>(3 * i) + dt_ * in_.gravity;
    if (in_.colliders) {
      const Vec3d x = grid_.node_position(c);
      for (std::size_t k = 0; k < in_.colliders->size(); ++k) {
        const Collider& col = (*in_.colliders)[k];
        if (col.phi(x) > 0) continue;
        if (in_.reach && !in_.reach->engaged(i / kBlockNodes, static_cast<int>(i % kBlockNodes), k))
          continue;
        const Vec3d n = col.normal(x), vc = col.velocity(x);
        const BoundaryKind kind = col.desc().boundary;
        if (kind == BoundaryKind::Sticky) {
          v = vc;
          for (int a = 0; a < 3; ++a) fixed_[3 * i + a] = 1;
          sticky_of_[i] = static_cast<int>(k);
          position_[i] = x;
        } else if (kind == BoundaryKind::Slip || (v - vc).dot(n) < 0) {
          v -= (v - vc).dot(n) * n;  // the collider's normal velocity, free along it
          normal_[i] = n;
          collider_of_[i] = static_cast<int>(k);
          position_[i] = x;
        }
        break;
      }
    }
    // A step solved again starts from its last solution: a wall also holds the components
    // that solution drove into it or held (the walls after the step clamp the solved ones;
    // the held set only grows, so the solves settle).
    const bool again = in_.start && i / kBlockNodes < in_.start->size();
    Vec3d s = Vec3d::Constant(again ? 0.0 : std::nan(""));
    if (again) {
      const Real* sv = (*in_.start)[i / kBlockNodes][i % kBlockNodes].v;
      s = Vec3d(sv[0], sv[1], sv[2]);
    }
    for (int a = 0; a < 3; ++a) {
      const bool low = c[a] < in_.wall_cells && (v[a] < 0 || s[a] <= 0);
      const bool high = c[a] > in_.domain_cells[a] - in_.wall_cells && (v[a] > 0 || s[a] >= 0);
      if (low || high) {
        v[a] = 0;
        fixed_[3 * i + a] = 1;
      }
    }
    u0_.segment<3>(3 * i) = v;
  }

  /// u0_ moved to a previous solution of the step (GridStepInput::start) within the
  /// constraints.
  void start_from(const std::vector<std::array<GridNode, kBlockNodes>>& start) {
    VecXd d = VecXd::Zero(u0_.size());
    for (std::size_t g = 0; g < nb_ && g < start.size(); ++g)
      for (int n = 0; n < kBlockNodes; ++n) {
        const std::size_t i = g * kBlockNodes + static_cast<std::size_t>(n);
        if (!(m_[static_cast<Eigen::Index>(i)] > 0)) continue;
        const Real* v = start[g][static_cast<std::size_t>(n)].v;
        for (int a = 0; a < 3; ++a)
          d[static_cast<Eigen::Index>(3 * i) + a] = static_cast<double>(v[a]) - u0_[3 * i + a];
      }
    const std::size_t slots = static_cast<std::size_t>(m_.size()) - nodes_;
    if (in_.slots && in_.slots->slot_start.size() == slots)
      for (std::size_t k = 0; k < slots; ++k) {
        const auto i = 3 * static_cast<Eigen::Index>(nodes_ + k);
        d.segment<3>(i) = in_.slots->slot_start[k].cast<double>() - u0_.segment<3>(i);
      }
    project(d);
    u0_ += d;
  }

  /// The nodes' part of u into every particle block's padded buffer (vbuf_), the slots'
  /// into slot_vel_.
  void scatter(const VecXd& u) {
    for (std::size_t k = 0; k < slot_vel_.size(); ++k) slot_vel_[k] = slot_velocity(u, k);
    parallel_for_each(
        grid_.num_particle_blocks(), 4,
        [&](std::size_t b) {
          Pad& buf = vbuf_[b];
          for (int o = 0; o < 8; ++o) {
            const std::size_t g = static_cast<std::size_t>(grid_.pblock_nbr[b][o]);
            const int ox = (o >> 2) * 4, oy = ((o >> 1) & 1) * 4, oz = (o & 1) * 4;
            const int ix1 = ox ? 2 : 4, iy1 = oy ? 2 : 4, iz1 = oz ? 2 : 4;
            for (int i = 0; i < ix1; ++i)
              for (int j = 0; j < iy1; ++j)
                for (int k = 0; k < iz1; ++k)
                  buf[pad_node(i + ox, j + oy, k + oz)] =
                      u.segment<3>(3 * (g * kBlockNodes + block_node(i, j, k)));
          }
        },
        in_.serial);
  }

  /// Sums the particle blocks' buffers into per-node vectors (the grid's fixed order).
  void gather(const std::vector<Pad>& bufs, VecXd& out) const {
    parallel_for_each(
        nb_, 4,
        [&](std::size_t g) {
          grid_.for_each_buffer_node(g, [&](int bn, std::size_t src, int pn) {
            out.segment<3>(3 * (g * kBlockNodes + bn)) += bufs[src][pn];
          });
        },
        in_.serial);
  }

  /// Calls f(q, W, corner) for the bulk particles of particle block b.
  template <class F>
  void each_particle(std::size_t b, F&& f) const {
    const Vec3i corner = unpack_block(grid_.pblock_key[b]) * kBlockSize;
    for (std::uint32_t s = grid_.pblock_start[b]; s < grid_.pblock_start[b + 1]; ++s) {
      if (grid_.order()[s] < in_.first_bulk) continue;  // a shell point
      const std::uint32_t q = grid_.order()[s] - in_.first_bulk;
      f(q, QuadraticWeights(grid_.grid_coord(in_.particles->x[q])), corner);
    }
  }

  /// The velocity-gradient weight of a stencil node [1/m]: grad w (APIC) or MLS's
  /// 4 w (x_i - x_p) / dx^2.
  Vec3d grad_weight(const QuadraticWeights& W, const StencilNodeD& s) const {
    const double inv_dx = 1.0 / grid_.dx();
    if (in_.mls) {
      const Vec3d d(s.i - W.fx[0], s.j - W.fx[1], s.k - W.fx[2]);
      return (4.0 * inv_dx * s.w) * d;
    }
    return inv_dx * Vec3d(W.dw[0][s.i] * W.w[1][s.j] * W.w[2][s.k],
                          W.w[0][s.i] * W.dw[1][s.j] * W.w[2][s.k],
                          W.w[0][s.i] * W.w[1][s.j] * W.dw[2][s.k]);
  }

  /// Elastic energy sum V psi(F(v)) at the velocities in vbuf_; with `forces`, also
  /// dt V P(F) F^n^T grad w into each block's buffer.
  double elastic(std::vector<Pad>* forces) {
    const ParticleSet& p = *in_.particles;
    const std::vector<double> parts = chunk_parts(
        grid_.num_particle_blocks(), 1, in_.serial, 0.0,
        [&](std::size_t b0, std::size_t b1, double& e) {
          for (std::size_t b = b0; b < b1; ++b) {
            if (forces) (*forces)[b].fill(Vec3d::Zero());
            each_particle(b, [&](std::uint32_t q, const QuadraticWeights& W, const Vec3i& c) {
              Mat3d gradv = Mat3d::Zero();
              for_each_node(W, c, [&](const StencilNodeD& s) {
                gradv += vbuf_[b][s.pad].cast<double>() * grad_weight(W, s).transpose();
              });
              const Mat3d Fn = p.F[q].cast<double>();
              const Mat3d F = (Mat3d::Identity() + dt_ * gradv) * Fn;
              const double pl = p.has_plastic() ? static_cast<double>(p.plastic[q]) : 0.0;
              const ConstitutiveModelT<double>& model = (*in_.models)[p.material_of(q)];
              const double V = static_cast<double>(p.volume_of(q));
              e += V * model.energy(F, pl);
              if (!forces) return;
              const Mat3d G = (dt_ * V) * model.first_piola(F, pl) * Fn.transpose();
              for_each_node(W, c, [&](const StencilNodeD& s) {
                (*forces)[b][s.pad] += G * grad_weight(W, s);
              });
            });
          }
        });
    double e = 0;
    for (double part : parts) e += part;
    return e;
  }

  template <class F>
  static void for_each_node(const QuadraticWeights& W, const Vec3i& corner, F&& f) {
    const int lx = W.base[0] - corner[0], ly = W.base[1] - corner[1], lz = W.base[2] - corner[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          f(StencilNodeD{i, j, k, pad_node(lx + i, ly + j, lz + k),
                         static_cast<double>(W.w[0][i]) * W.w[1][j] * W.w[2][k]});
  }

  /// minv_ = Pi D^-1 Pi^T per node, D the nodes' diagonal (mass and bulk) and Pi the
  /// constraints' projection (project: the slip normal's component removed, then the
  /// fixed components zeroed): the inverse of Pi D Pi^T on the directions CG moves in, so
  /// the shells' Woodbury preconditioner inverts the projected Hessian.
  /// With friction in the solve, D's block at a node with friction adds friction's Hessian
  /// where the lag was taken.
  void projected_inverse_diagonal() {
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
      if (!(m_[i] > 0)) continue;
      Mat3d Pi = Mat3d::Identity();
      Vec3d n;
      const bool cut = free_normal(i, n);
      if (n.squaredNorm() > 0) Pi -= (cut ? 1.0 / n.squaredNorm() : 1.0) * n * n.transpose();
      for (int a = 0; a < 3; ++a)
        if (fixed_[static_cast<std::size_t>(3 * i + a)]) Pi.row(a).setZero();
      const int k = friction_on_ ? fric_of_[static_cast<std::size_t>(i)] : -1;
      const Mat3d Dinv =
          k < 0 ? Mat3d(base_diag_.segment<3>(3 * i).cwiseInverse().asDiagonal())
                : Mat3d((Mat3d(base_diag_.segment<3>(3 * i).asDiagonal()) + fric_h_[std::size_t(k)])
                            .inverse());
      const Mat3d B = Pi * Dinv * Pi.transpose();
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (B(a, b) != 0) t.emplace_back(3 * i + a, 3 * i + b, B(a, b));
    }
    minv_.resize(size(), size());
    minv_.setFromTriplets(t.begin(), t.end());
  }

  /// Friction's Hessian diagonal where the lag was taken, added to diag_.
  void add_friction_diagonal() {
    if (!friction_on_) return;
    for (std::size_t k = 0; k < fric_.size(); ++k) {
      const Eigen::Index i = 3 * fric_node_[k];
      diag_.segment<3>(i) += fric_h_[k].diagonal();
    }
  }

  /// Jacobi diagonal m_i + dt^2 sum_p V_p c_p |grad w_ip|^2 (at F^n).
  void prepare_diagonal() {
    const ParticleSet& p = *in_.particles;
    parallel_for_each(
        grid_.num_particle_blocks(), 1,
        [&](std::size_t b) {
          fbuf_[b].fill(Vec3d::Zero());
          each_particle(b, [&](std::uint32_t q, const QuadraticWeights& W, const Vec3i& c) {
            const double pl = p.has_plastic() ? static_cast<double>(p.plastic[q]) : 0.0;
            const double k =
                static_cast<double>(p.volume_of(q)) *
                (*in_.models)[p.material_of(q)].wave_modulus(p.F[q].cast<double>(), pl);
            for_each_node(W, c, [&](const StencilNodeD& s) {
              fbuf_[b][s.pad] += Vec3d::Constant(k * grad_weight(W, s).squaredNorm());
            });
          });
        },
        in_.serial);
    diag_.setZero(size());
    gather(fbuf_, diag_);
    for (Eigen::Index i = 0; i < m_.size(); ++i)
      for (int a = 0; a < 3; ++a) {
        double& d = diag_[3 * i + a];
        d = m_[i] > 0 ? m_[i] + dt_ * dt_ * d : 1.0;
      }
    base_diag_ = diag_;
  }

  const GridStepInput& in_;
  SparseGrid& grid_;
  double dt_;
  std::size_t nb_ = 0;
  std::size_t nodes_ = 0;        ///< grid nodes; slot k's unknowns follow at 3 (nodes_ + k)
  std::vector<Vec3d> slot_vel_;  ///< the slots' velocities at the last scatter
  std::vector<Vec3d> slot_grad_;
  VecXd m_, vhat_, u0_, diag_, base_diag_;
  SparseMatrixD minv_;         // the diagonal's inverse on the constrained subspace (3x3 blocks)
  bool shells_ready_ = false;  // the shells' preconditioner is prepared
  std::vector<char> fixed_;
  std::vector<Vec3d> normal_;     // slip constraint normal per node (zero: none)
  std::vector<int> collider_of_;  // the collider of that constraint (-1: none)
  std::vector<int> sticky_of_;    // the sticky collider holding the node (-1: none)
  std::vector<Vec3d> position_;   // the node's position where it has one
  // Friction inside the solve (lag_friction): the nodes with friction, their terms, and
  // each node's index among them (-1: none).
  bool friction_on_ = false;
  std::vector<LaggedFriction> fric_;
  std::vector<Mat3d> fric_h_;  // their Hessians where the lag was taken (preconditioner)
  std::vector<Eigen::Index> fric_node_;
  std::vector<int> fric_of_;
  std::vector<Pad> vbuf_, fbuf_;
};

}  // namespace

std::unique_ptr<ImplicitObjective> grid_objective(const GridStepInput& in, double dt, VecXd& u0) {
  auto obj = std::make_unique<GridObjective>(in, dt);
  u0 = obj->initial();
  return obj;
}

NewtonReport implicit_grid_step(const GridStepInput& in, double dt, const NewtonOptions& opt) {
  GridObjective obj(in, dt);
  VecXd u = obj.initial();
  std::vector<double>* seed = in.friction_in_solve ? in.friction_bounds : nullptr;
  if (seed && !seed->empty()) obj.set_friction(*seed, u);
  NewtonReport rep = newton_minimise(obj, u, opt);
  if (!rep.converged) return rep;
  // Friction inside the solve: solved again from u with the normal impulses u needed,
  // unless it started from nearly those.
  for (int lag = 0; in.friction_in_solve && lag < kFrictionLags; ++lag) {
    const std::vector<double> b = obj.friction_bounds(u);
    if (!obj.friction_moved(b) || !obj.set_friction(b, u)) break;
    const NewtonReport again = newton_minimise(obj, u, opt);
    rep.iterations += again.iterations;
    rep.cg_iterations += again.cg_iterations;
    rep.round_off_steps += again.round_off_steps;
    rep.residual = again.residual;
    rep.line_search_failed = again.line_search_failed;
    rep.converged = again.converged;
    if (!rep.converged) return rep;
  }
  const double work = obj.finish(u, seed);  // and the bounds at u for a solve again
  if (in.collider_work) *in.collider_work = work;
  if (in.slot_out) {
    const std::size_t ns = in.slots ? in.slots->num_slots() : 0;
    in.slot_out->resize(ns);
    for (std::size_t k = 0; k < ns; ++k) (*in.slot_out)[k] = obj.slot_velocity(u, k).cast<Real>();
  }
  SparseGrid& grid = *in.grid;
  for (std::size_t g = 0; g < grid.num_grid_blocks(); ++g)
    for (int n = 0; n < kBlockNodes; ++n) {
      GridNode& nd = grid.gblock_nodes[g][n];
      if (!(nd.m > 0)) continue;
      for (int a = 0; a < 3; ++a) nd.v[a] = static_cast<Real>(u[3 * (g * kBlockNodes + n) + a]);
    }
  return rep;
}

}  // namespace shellmpm
