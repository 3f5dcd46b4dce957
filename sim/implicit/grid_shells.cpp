#include "sim/implicit/grid_shells.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "sim/contact/contact_energy.h"
#include "sim/core/parallel.h"
#include "sim/core/psd_part.h"
#include "sim/mpm/apic_stencil.h"
#include "sim/mpm/bspline.h"
#include "sim/shell/kl_stiffness.h"

namespace shellmpm {
namespace {

constexpr std::size_t kSiteGrain = 1024;

/// Global node index (g kBlockNodes + n) of padded node (px, py, pz) of particle block b.
std::size_t node_of(const SparseGrid& grid, std::size_t b, int px, int py, int pz) {
  const int o =
      (px >= kBlockSize ? 4 : 0) + (py >= kBlockSize ? 2 : 0) + (pz >= kBlockSize ? 1 : 0);
  const auto g = static_cast<std::size_t>(grid.pblock_nbr[b][o]);
  return g * kBlockNodes + block_node(px % kBlockSize, py % kBlockSize, pz % kBlockSize);
}

/// Calls f(table index) for the shell points binned in particle block b (they are binned
/// in front of the bulk particles, and a block's entries ascend).
template <class F>
void each_shell_point(const SparseGrid& grid, std::size_t b, std::uint32_t count, F&& f) {
  for (std::uint32_t s = grid.pblock_start[b]; s < grid.pblock_start[b + 1]; ++s) {
    const std::uint32_t g = grid.order()[s];
    if (g >= count) break;
    f(g);
  }
}

/// Tangents a_1, a_2 of contact particle p at control points X (differences to its first
/// control point, as ShellContact::tangents).
void site_tangents(const ShellContact& c, const std::vector<Vec3d>& X, std::size_t p, Vec3d& a1,
                   Vec3d& a2) {
  const Vec3d ref = X[c.idx[c.off[p]]];
  a1.setZero();
  a2.setZero();
  const ShellContact::StencilWeight* w = c.weights(p);
  for (std::uint32_t k = c.off[p]; k < c.off[p + 1]; ++k) {
    const Vec3d d = X[c.idx[k]] - ref;
    a1 += static_cast<double>(w[k - c.off[p]].N1) * d;
    a2 += static_cast<double>(w[k - c.off[p]].N2) * d;
  }
}

/// V psi of contact particle p at control points X with normal column a3; with G, also
/// V dpsi/d(a1, a2, a3E) (columns).
double site_energy(const ShellContact& c, const std::vector<Vec3d>& X, std::size_t p,
                   const Vec3d& a3, Mat3d* G) {
  Vec3d a1, a2;
  site_tangents(c, X, p, a1, a2);
  const double V = static_cast<double>(c.volume[p]);
  const double psi = contact_gradient<double>(a1, a2, a3, c.params(), G);
  if (G) *G *= V;
  return V * psi;
}

/// Adds sign times contact particle p's dpsi/da_beta (columns 0, 1 of G) to its control
/// points' entries of out (dN_k/dxi_beta times them).
void scatter_tangential(const ShellContact& c, std::size_t p, const Mat3d& G, double sign,
                        std::vector<Vec3d>& out) {
  const ShellContact::StencilWeight* w = c.weights(p);
  for (std::uint32_t k = c.off[p]; k < c.off[p + 1]; ++k)
    out[c.idx[k]] += sign * (static_cast<double>(w[k - c.off[p]].N1) * G.col(0) +
                             static_cast<double>(w[k - c.off[p]].N2) * G.col(1));
}

Vec3i corner_of(const SparseGrid& grid, std::size_t b) {
  return unpack_block(grid.pblock_key[b]) * kBlockSize;
}

}  // namespace

GridShellTerms::GridShellTerms(const SparseGrid& grid, const ShellPointTable& table,
                               const std::vector<GridShell>& shells,
                               const std::vector<GridShellKl>& kls, double t, double dt,
                               bool serial)
    : grid_(grid), table_(table), dt_(dt), serial_(serial) {
  sh_.resize(shells.size());
  site_start_.assign(shells.size() + 1, 0);
  for (std::size_t s = 0; s < shells.size(); ++s) {
    Shell& S = sh_[s];
    S.gs = &shells[s];
    S.kl = &kls[s];
    const ShellObject& sh = *shells[s].shell;
    const std::size_t n = sh.size();
    S.x0.resize(n);
    for (std::size_t j = 0; j < n; ++j) S.x0[j] = sh.x[j].cast<double>();
    S.X = S.x0;
    S.v.assign(n, Vec3d::Zero());
    sh.external_forces(Vec3d::Zero(), S.x0, S.fext);
    sh.pin_targets(t, dt, S.held, S.target);
    if (std::any_of(S.held.begin(), S.held.end(), [](std::uint8_t h) { return h != 0; }))
      S.held_grad.assign(n, Vec3d::Zero());
    S.damping = sh.material().damping;
    S.membrane = sh.material().youngs_modulus * sh.material().thickness;
    Eigen::AlignedBox<double, 3> box;
    for (const Vec3d& p : S.x0) box.extend(p);
    S.length = std::max(box.diagonal().norm(), 1e-12);
    site_start_[s + 1] =
        site_start_[s] + static_cast<std::uint32_t>(shells[s].contact->num_sites());
  }
  // The contact particles' gradient weights from the node masses (as G2P computes them).
  sites_.resize(site_start_.back());
  a3_.assign(sites_.size(), Vec3d::Zero());
  G3_.assign(sites_.size(), Vec3d::Zero());
  const std::uint32_t nc = table.num_control_points();
  const Real dx = static_cast<Real>(grid.dx());
  parallel_for_each(
      grid.num_particle_blocks(), 1,
      [&](std::size_t b) {
        const Vec3i bc = corner_of(grid, b);
        each_shell_point(grid, b, static_cast<std::uint32_t>(table.size()), [&](std::uint32_t g) {
          if (g < nc) return;
          const std::uint32_t s = table.shell(g), p = table.local(g);
          const ShellContact& c = *shells[s].contact;
          Site& st = sites_[site_start_[s] + p];
          st.shell = s;
          st.local = p;
          const QuadraticWeights W(grid.grid_coord(c.x[p]));
          st.lx = W.base[0] - bc[0];
          st.ly = W.base[1] - bc[1];
          st.lz = W.base[2] - bc[2];
          const SiteMoments sm = site_moments(W, dx, bc, [&](const StencilNode& nd) {
            const std::size_t node = node_of(grid, b, nd.px, nd.py, nd.pz);
            return grid.gblock_nodes[node / kBlockNodes][node % kBlockNodes].m;
          });
          st.any = sm.any;
          if (!sm.any) return;
          Real ga[27];
          sm.dot(c.a3e[p], ga);
          for (int k = 0; k < 27; ++k) st.ga[k] = dt * static_cast<double>(ga[k]);
        });
      },
      serial);
}

void GridShellTerms::move(const std::vector<PadD>& vel) {
  const std::uint32_t nc = table_.num_control_points();
  parallel_for_each(
      grid_.num_particle_blocks(), 1,
      [&](std::size_t b) {
        const Vec3i bc = corner_of(grid_, b);
        each_shell_point(grid_, b, nc, [&](std::uint32_t g) {
          Shell& S = sh_[table_.shell(g)];
          const std::uint32_t j = table_.local(g);
          const QuadraticWeights W(grid_.grid_coord(S.gs->shell->x[j]));
          Vec3d v = Vec3d::Zero();
          const std::size_t s = table_.shell(g);
          const bool slotted = slots_ && !slots_->slot_of[s].empty();
          for_each_stencil_node(W, bc, [&](const StencilNode& nd) {
            const int k = slotted ? slot_at(s, node_of(grid_, b, nd.px, nd.py, nd.pz)) : -1;
            v += static_cast<double>(nd.w) *
                 (k >= 0 ? (*slot_vel_)[std::size_t(k)] : vel[b][nd.pad()]);
          });
          if (slots_) v += slots_->control[s][j].cast<double>();
          for (int a = 0; a < 3; ++a)
            if (S.held[j] & (1u << a)) {
              S.X[j][a] = S.target[j][a];
              v[a] = (S.target[j][a] - S.x0[j][a]) / dt_;
            } else {
              S.X[j][a] = S.x0[j][a] + dt_ * v[a];
            }
          S.v[j] = v;
        });
      },
      serial_);
}

void GridShellTerms::advance_sites(const std::vector<PadD>& vel) {
  parallel_for(
      sites_.size(), kSiteGrain,
      [&](std::size_t b0, std::size_t b1) {
        for (std::size_t i = b0; i < b1; ++i)
          a3_[i] = sh_[sites_[i].shell].gs->contact->a3e[sites_[i].local].cast<double>();
      },
      serial_);
  const std::uint32_t nc = table_.num_control_points();
  parallel_for_each(
      grid_.num_particle_blocks(), 1,
      [&](std::size_t b) {
        each_shell_point(grid_, b, static_cast<std::uint32_t>(table_.size()), [&](std::uint32_t g) {
          if (g < nc) return;
          const std::size_t i = site_start_[table_.shell(g)] + table_.local(g);
          const Site& st = sites_[i];
          if (!st.any) return;
          Vec3d d = Vec3d::Zero();
          each_site_node(st, [&](int n, int px, int py, int pz) {
            d += st.ga[n] * vel[b][pad_node(px, py, pz)];
          });
          a3_[i] += d;
        });
      },
      serial_);
}

double GridShellTerms::evaluate(bool grad) {
  double e = 0;
  for (std::size_t s = 0; s < sh_.size(); ++s) {
    Shell& S = sh_[s];
    const ShellContact& c = *S.gs->contact;
    const ShellObject& sh = *S.gs->shell;
    const std::size_t n = S.X.size();
    if (grad) S.f.assign(n, Vec3d::Zero());
    e += S.kl->kl->energy(S.X.data(), grad ? S.f.data() : nullptr, serial_, false).total;
    // Contact particles: energy, and their dpsi/da_beta (G1, G2) and dpsi/da3E.
    const std::uint32_t s0 = site_start_[s];
    const std::size_t ns = c.num_sites();
    std::vector<Mat3d> G(grad ? ns : 0);
    e += ordered_reduce(ns, kSiteGrain, serial_, 0.0, [&](std::size_t p) {
      const double ep = site_energy(c, S.X, p, a3_[s0 + p], grad ? &G[p] : nullptr);
      if (grad) G3_[s0 + p] = G[p].col(2);
      return ep;
    });
    // Damping and loads on the free components.
    for (std::size_t j = 0; j < n; ++j) {
      const double m = static_cast<double>(sh.mass[j]);
      for (int a = 0; a < 3; ++a) {
        if (S.held[j] & (1u << a)) continue;
        const double v = S.v[j][a];
        e += dt_ * (0.5 * S.damping * m * v * v - S.fext[j][a] * v);
      }
    }
    if (grad) S.dX.assign(n, Vec3d::Zero());
    e += collider_penalty(S, grad, nullptr);
    if (!grad) continue;
    for (std::size_t p = 0; p < ns; ++p) scatter_tangential(c, p, G[p], 1.0, S.dX);
    for (std::size_t j = 0; j < n; ++j) {
      const double m = static_cast<double>(sh.mass[j]);
      for (int a = 0; a < 3; ++a) {
        if (S.held[j] & (1u << a)) {
          S.held_grad[j][a] = S.dX[j][a] - S.f[j][a];
          S.dX[j][a] = 0.0;
        } else {
          S.dX[j][a] = S.dX[j][a] - S.f[j][a] + S.damping * m * S.v[j][a] - S.fext[j][a];
        }
      }
    }
  }
  return e;
}

ColliderPenaltyInput GridShellTerms::penalty_input(const Shell& S) const {
  ColliderPenaltyInput in;
  in.colliders = colliders_;
  in.mass = &S.gs->shell->mass;
  in.held = &S.held;
  in.dt = dt_;
  in.membrane = S.membrane;
  return in;
}

double GridShellTerms::collider_penalty(Shell& S, bool grad, std::vector<Mat3d>* K) const {
  return shellmpm::collider_penalty(penalty_input(S), S.X, grad ? &S.dX : nullptr, K);
}

double GridShellTerms::collider_work() const {
  double w = 0;
  for (const Shell& S : sh_)
    shellmpm::collider_penalty(penalty_input(S), S.X, nullptr, nullptr, &w);
  return w;
}

double GridShellTerms::pin_work() const {
  double w = 0;
  for (const Shell& S : sh_)
    for (std::size_t j = 0; j < S.held_grad.size(); ++j)
      for (int a = 0; a < 3; ++a)
        if (S.held[j] & (1u << a)) w += dt_ * S.held_grad[j][a] * S.v[j][a];
  return w;
}

double GridShellTerms::load_work() const {
  double w = 0;
  for (const Shell& S : sh_) {
    if (!S.gs->shell->has_loads()) continue;
    for (std::size_t j = 0; j < S.X.size(); ++j)
      for (int a = 0; a < 3; ++a)
        if (!(S.held[j] & (1u << a))) w += S.fext[j][a] * (S.X[j][a] - S.x0[j][a]);
  }
  return w;
}

double GridShellTerms::energy(const std::vector<PadD>& vel) {
  move(vel);
  advance_sites(vel);
  return evaluate(false);
}

double GridShellTerms::gradient(const std::vector<PadD>& vel, std::vector<PadD>& grad,
                                std::vector<Vec3d>* slot_grad) {
  move(vel);
  advance_sites(vel);
  const double e = evaluate(true);
  const std::uint32_t nc = table_.num_control_points();
  // The slots' parts per particle block, summed in block order after (the same sums for
  // any thread count).
  std::vector<std::vector<std::pair<int, Vec3d>>> slot_parts(slots_ ? grid_.num_particle_blocks()
                                                                    : 0);
  parallel_for_each(
      grid_.num_particle_blocks(), 1,
      [&](std::size_t b) {
        const Vec3i bc = corner_of(grid_, b);
        each_shell_point(grid_, b, static_cast<std::uint32_t>(table_.size()), [&](std::uint32_t g) {
          if (g < nc) {
            const std::size_t s = table_.shell(g);
            const Shell& S = sh_[s];
            const std::uint32_t j = table_.local(g);
            const Vec3d d = dt_ * S.dX[j];
            const QuadraticWeights W(grid_.grid_coord(S.gs->shell->x[j]));
            const bool slotted = slots_ && !slots_->slot_of[s].empty();
            for_each_stencil_node(W, bc, [&](const StencilNode& nd) {
              const int k = slotted ? slot_at(s, node_of(grid_, b, nd.px, nd.py, nd.pz)) : -1;
              if (k >= 0)
                slot_parts[b].emplace_back(k, static_cast<double>(nd.w) * d);
              else
                grad[b][nd.pad()] += static_cast<double>(nd.w) * d;
            });
            return;
          }
          const std::size_t i = site_start_[table_.shell(g)] + table_.local(g);
          const Site& st = sites_[i];
          if (!st.any) return;
          each_site_node(st, [&](int n, int px, int py, int pz) {
            grad[b][pad_node(px, py, pz)] += st.ga[n] * G3_[i];
          });
        });
      },
      serial_);
  if (slot_grad)
    for (const auto& parts : slot_parts)
      for (const auto& [k, v] : parts) (*slot_grad)[std::size_t(k)] += v;
  return e;
}

void GridShellTerms::joint(const std::vector<PadD>& vel, Eigen::Index N, SparseMatrixD* J,
                           SparseMatrixD& K) {
  move(vel);
  advance_sites(vel);
  // The joint space: per shell its free control-point components, then 3 per contact
  // particle (its a3E).
  std::vector<std::vector<int>> dof_of(sh_.size());
  std::vector<int> first(sh_.size() + 1, 0);
  std::vector<int> nfree(sh_.size(), 0);
  for (std::size_t s = 0; s < sh_.size(); ++s) {
    const Shell& S = sh_[s];
    const ShellObject& sh = *S.gs->shell;
    dof_of[s].assign(3 * sh.size(), -1);
    for (std::size_t j = 0; j < sh.size(); ++j)
      for (int a = 0; a < 3; ++a)
        if (!(S.held[j] & (1u << a)) && sh.mass[j] > 0) dof_of[s][3 * j + a] = nfree[s]++;
    first[s + 1] = first[s] + nfree[s] + 3 * static_cast<int>(S.gs->contact->num_sites());
  }
  // J: dX/du = dt w (control rows), da3E/du = dt g . a3E^n (contact particle rows).
  std::vector<Eigen::Triplet<double>> tj;
  const std::uint32_t nc = table_.num_control_points();
  for (std::size_t b = 0; J && b < grid_.num_particle_blocks(); ++b) {
    const Vec3i bc = corner_of(grid_, b);
    each_shell_point(grid_, b, static_cast<std::uint32_t>(table_.size()), [&](std::uint32_t g) {
      const std::size_t s = table_.shell(g);
      const std::uint32_t j = table_.local(g);
      if (g < nc) {
        const QuadraticWeights Wq(grid_.grid_coord(sh_[s].gs->shell->x[j]));
        for_each_stencil_node(Wq, bc, [&](const StencilNode& nd) {
          const std::size_t node = node_of(grid_, b, nd.px, nd.py, nd.pz);
          const int k = slot_at(s, node);
          const Eigen::Index col = k >= 0 ? slot_dof(k) : 3 * static_cast<Eigen::Index>(node);
          for (int a = 0; a < 3; ++a) {
            const int d = dof_of[s][3 * j + a];
            if (d >= 0) tj.emplace_back(first[s] + d, col + a, dt_ * static_cast<double>(nd.w));
          }
        });
        return;
      }
      const Site& st = sites_[site_start_[s] + j];
      if (!st.any) return;
      const int row = first[s] + nfree[s] + 3 * static_cast<int>(j);
      each_site_node(st, [&](int n, int px, int py, int pz) {
        if (st.ga[n] == 0) return;
        const auto node = static_cast<Eigen::Index>(node_of(grid_, b, px, py, pz));
        for (int a = 0; a < 3; ++a) tj.emplace_back(row + a, 3 * node + a, st.ga[n]);
      });
    });
  }
  if (J) {
    J->resize(first.back(), N);
    J->setFromTriplets(tj.begin(), tj.end());
  }
  // K: the Kirchhoff-Love and contact Hessian in (X, a3E).
  std::vector<Eigen::Triplet<double>> tk;
  for (std::size_t s = 0; s < sh_.size(); ++s) {
    const Shell& S = sh_[s];
    const ShellContact& c = *S.gs->contact;
    const std::size_t n = S.X.size();
    const int a0 = first[s] + nfree[s];
    // Each contact particle's Hessian in (a1, a2, a3E), by central differences of its
    // gradient, made positive semi-definite: its a3E-a3E block and its coupling to the
    // control points (the a1, a2 blocks enter through the forces' differences below).
    for (std::size_t p = 0; p < c.num_sites(); ++p) {
      Vec3d a1, a2;
      site_tangents(c, S.X, p, a1, a2);
      Eigen::Matrix<double, 9, 1> y;
      y << a1, a2, a3_[site_start_[s] + p];
      const auto grad = [&](const Eigen::Matrix<double, 9, 1>& q) {
        Mat3d Gq;
        contact_gradient<double>(Vec3d(q.segment<3>(0)), Vec3d(q.segment<3>(3)),
                                 Vec3d(q.segment<3>(6)), c.params(), &Gq);
        return Eigen::Matrix<double, 9, 1>(
            Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Gq.data()));
      };
      Eigen::Matrix<double, 9, 9> H;
      const double h = 1e-6 * std::max({a1.norm(), a2.norm(), 1.0});
      for (int k = 0; k < 9; ++k) {
        Eigen::Matrix<double, 9, 1> yp = y, ym = y;
        yp[k] += h;
        ym[k] -= h;
        H.col(k) = (grad(yp) - grad(ym)) / (2 * h);
      }
      H = (0.5 * (H + H.transpose())).eval();
      psd_part(H);
      H *= static_cast<double>(c.volume[p]);
      const int pr = a0 + 3 * static_cast<int>(p);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) tk.emplace_back(pr + i, pr + j, H(6 + i, 6 + j));
      // d^2 psi / dX_k da3E = sum_beta dN_k/dxi_beta d^2 psi / da_beta da3E, and the
      // tangential part d^2 psi / dX_k dX_l = sum_beta,gamma dN_k/dxi_beta dN_l/dxi_gamma
      // d^2 psi / da_beta da_gamma (a_beta = sum_k dN_k/dxi_beta X_k).
      const ShellContact::StencilWeight* w = c.weights(p);
      for (std::uint32_t k = c.off[p]; k < c.off[p + 1]; ++k) {
        const double n1 = static_cast<double>(w[k - c.off[p]].N1);
        const double n2 = static_cast<double>(w[k - c.off[p]].N2);
        const Mat3d B = n1 * H.block<3, 3>(0, 6) + n2 * H.block<3, 3>(3, 6);
        const Mat3d T1 = n1 * H.block<3, 3>(0, 0) + n2 * H.block<3, 3>(3, 0);
        const Mat3d T2 = n1 * H.block<3, 3>(0, 3) + n2 * H.block<3, 3>(3, 3);
        for (int i = 0; i < 3; ++i) {
          const int d = dof_of[s][3 * c.idx[k] + i];
          if (d < 0) continue;
          for (int j = 0; j < 3; ++j) {
            tk.emplace_back(first[s] + d, pr + j, B(i, j));
            tk.emplace_back(pr + j, first[s] + d, B(i, j));
          }
          for (std::uint32_t l = c.off[p]; l < c.off[p + 1]; ++l) {
            const double m1 = static_cast<double>(w[l - c.off[p]].N1);
            const double m2 = static_cast<double>(w[l - c.off[p]].N2);
            for (int j = 0; j < 3; ++j) {
              const int e = dof_of[s][3 * c.idx[l] + j];
              if (e < 0) continue;
              tk.emplace_back(first[s] + d, first[s] + e, T1(i, j) * m1 + T2(i, j) * m2);
            }
          }
        }
      }
    }
    if (nfree[s] == 0) continue;
    std::vector<Mat3d> Kc;
    collider_penalty(sh_[s], false, &Kc);
    for (std::size_t j = 0; j < n; ++j)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          const int da = dof_of[s][3 * j + a], db = dof_of[s][3 * j + b];
          if (da >= 0 && db >= 0 && Kc[j](a, b) != 0)
            tk.emplace_back(first[s] + da, first[s] + db, Kc[j](a, b));
        }
    // The Kirchhoff-Love part from each quadrature point's Hessian (kl_stiffness.h), made
    // positive semi-definite as the contact particles' are: K enters the quasi-definite
    // [S I; I -K] and the lumped K + S~^-1, which are what they are meant to be only for
    // K >= 0. A compressed membrane's Hessian is indefinite; with it unprojected, the
    // preconditioner turns indefinite, CG's and the preconditioned gradient's directions
    // stop descending and the solve fails (the can on sand with contact_stiffness 2e9: the
    // second step's solve, and every halving of it).
    const SparseMatrixD Kx =
        kl_stiffness_matrix(*S.kl->kl, S.X, dof_of[s], nfree[s], serial_, /*psd=*/true);
    for (Eigen::Index col = 0; col < Kx.outerSize(); ++col)
      for (SparseMatrixD::InnerIterator it(Kx, col); it; ++it)
        tk.emplace_back(first[s] + static_cast<int>(it.row()),
                        first[s] + static_cast<int>(it.col()), it.value());
  }
  K.resize(first.back(), first.back());
  K.setFromTriplets(tk.begin(), tk.end());
}

void GridShellTerms::prepare(const std::vector<PadD>& vel, const SparseMatrixD& minv) {
  SparseMatrixD K;
  // J and minv are the same at every prepare of one step (the weights, a3E^n and the
  // nodes' constraints are fixed within it): J and S = J M^-1 J^T, whose coupling of the
  // control points and contact particles that share nodes is the costly product, are
  // formed once.
  const bool first = Jall_.rows() == 0;
  joint(vel, minv.rows(), first ? &Jall_ : nullptr, K);
  if (first || Sall_.rows() == 0)
    Sall_ = (Jall_ * minv * SparseMatrixD(Jall_.transpose())).pruned();
  const SparseMatrixD& J = Jall_;
  const SparseMatrixD& S = Sall_;
  // Only the joint unknowns that reach a node and have stiffness enter J^T K J (K is
  // positive semi-definite: a zero diagonal entry is a zero row).
  const VecXd kd = K.diagonal(), sd = S.diagonal();
  std::vector<int> kept_of(static_cast<std::size_t>(J.rows()), -1);
  int m = 0;
  double kmax = 0, smax = 0;
  for (Eigen::Index r = 0; r < J.rows(); ++r)
    if (kd[r] > 0 && sd[r] > 0) {
      kept_of[static_cast<std::size_t>(r)] = m++;
      kmax = std::max(kmax, kd[r]);
      smax = std::max(smax, sd[r]);
    }
  ldlt_.reset();
  exact_ = false;
  if (m == 0) return;
  if (kept_of != kept_) {
    // The kept rows change only where a row's stiffness appears or vanishes: J's and S's
    // kept parts are formed again only then.
    kept_ = kept_of;
    std::vector<Eigen::Triplet<double>> tp;
    for (Eigen::Index r = 0; r < J.rows(); ++r)
      if (kept_of[static_cast<std::size_t>(r)] >= 0)
        tp.emplace_back(kept_of[static_cast<std::size_t>(r)], r, 1.0);
    P_.resize(m, J.rows());
    P_.setFromTriplets(tp.begin(), tp.end());
    Pt_ = P_.transpose();
    J_ = P_ * J;
    Sk_ = P_ * S * Pt_;
  }
  const SparseMatrixD& Sk = Sk_;
  const SparseMatrixD Kk = P_ * K * Pt_;
  if (m <= exact_limit_) {
    // Exact: (K^-1 + S)^-1 y = w from the quasi-definite system [S I; I -K] [w; q] =
    // [y; 0] (w = K q, q = (I + S K)^-1 y), defined where K is singular (a free sheet's
    // rigid motions). Tiny shifts on both blocks keep it quasi-definite, so LDL^T exists
    // for the fill-reducing order without pivoting (should round-off still break it,
    // the lumped coupling below takes over).
    const double es = 1e-12 * smax, ek = 1e-12 * kmax;
    std::vector<Eigen::Triplet<double>> ta;
    const auto add = [&](const SparseMatrixD& X, int off, double sign, double shift) {
      for (Eigen::Index col = 0; col < X.outerSize(); ++col) {
        for (SparseMatrixD::InnerIterator it(X, col); it; ++it)
          ta.emplace_back(off + static_cast<int>(it.row()), off + static_cast<int>(col),
                          sign * it.value());
        ta.emplace_back(off + static_cast<int>(col), off + static_cast<int>(col), sign * shift);
      }
    };
    add(Sk, 0, 1.0, es);
    add(Kk, m, -1.0, ek);
    for (int i = 0; i < m; ++i) {
      ta.emplace_back(i, m + i, 1.0);
      ta.emplace_back(m + i, i, 1.0);
    }
    SparseMatrixD A(2 * m, 2 * m);
    A.setFromTriplets(ta.begin(), ta.end());
    if (!qd_) qd_ = std::make_unique<SymmetricFactor>();
    exact_ = qd_->factorise(A);
    if (exact_) {
      // Round-off that broke the factor shows as a non-finite solve.
      VecXd probe;
      qd_->solve(VecXd::Ones(A.rows()), probe);
      exact_ = probe.allFinite();
    }
    if (exact_) return;
  }
  // Lumped: S~ = the absolute row sums of S (S~ >= S, so the approximation stays
  // positive definite), and (K^-1 + S~)^-1 = S~^-1 - S~^-1 (K + S~^-1)^-1 S~^-1.
  sinv_ = (Sk.cwiseAbs() * VecXd::Ones(m)).cwiseInverse();
  SparseMatrixD A = Kk;
  for (int k = 0; k < m; ++k) A.coeffRef(k, k) += sinv_[k];
  ldlt_ = factorise_positive(A);
}

void GridShellTerms::apply(const VecXd& r, const SparseMatrixD& minv, VecXd& z) const {
  z = minv * r;
  if (!exact_ && !ldlt_) return;
  VecXd w;
  if (exact_) {
    const Eigen::Index m = J_.rows();
    VecXd rhs = VecXd::Zero(2 * m);
    rhs.head(m) = J_ * z;
    VecXd sol;
    qd_->solve(rhs, sol);
    w = sol.head(m);
  } else {
    const VecXd y = sinv_.cwiseProduct(J_ * z);
    w = y - sinv_.cwiseProduct(ldlt_->solve(y));
  }
  z -= minv * (J_.transpose() * w);
}

void GridShellTerms::add_diagonal(const std::vector<PadD>& vel, VecXd& diag) {
  SparseMatrixD J, K;
  joint(vel, diag.size(), &J, K);
  const SparseMatrixD KJ = K * J;
  for (Eigen::Index col = 0; col < J.outerSize(); ++col) {
    double d = 0;
    SparseMatrixD::InnerIterator a(J, col), b(KJ, col);
    // sum_i J_ik (K J)_ik over the rows both columns hold.
    while (a && b) {
      if (a.row() < b.row()) {
        ++a;
      } else if (b.row() < a.row()) {
        ++b;
      } else {
        d += a.value() * b.value();
        ++a;
        ++b;
      }
    }
    diag[col] += d;
  }
}

}  // namespace shellmpm
