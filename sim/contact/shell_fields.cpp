#include "sim/contact/shell_fields.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

#include "sim/contact/contact_gap.h"
#include "sim/contact/field_contact.h"
#include "sim/core/check.h"
#include "sim/core/parallel.h"
#include "sim/mpm/apic_stencil.h"

namespace shellmpm {
namespace {
constexpr Real kShellOnly = Real(1e-4);  ///< below this bulk share the node is shells only
}  // namespace

void ShellFields::setup(const SparseGrid& grid, std::size_t num_shells, bool bulk, bool folds) {
  fields_.clear();
  folds_ = folds;
  active_ = num_shells >= 2 || (num_shells >= 1 && (bulk || folds));
  heights_only_ = active_ && folds && num_shells == 1 && !bulk;
  if (!active_) return;
  fields_.resize(num_shells);
  for (Field& f : fields_) {
    f.grid.setup(grid.dx(), grid.origin());
    f.grid.keep_nodes = false;  // the field's own nodes (Field::nodes) hold its sums
  }
}

ShellFields::PointShare::PointShare(const GridShell& gs, const Vec3& nj, const Vec3& f,
                                    std::uint32_t j, Real dx, Real dt, bool with_heights)
    : heights(with_heights), align(nj.dot(kAlign) >= 0 ? Real(1) : Real(-1)), fx(f), n(nj) {
  // Node lanes: m, p (3), n (3), N (3), o (3), held, hmin, hmax; the height range is kept
  // apart (add), its lanes add zero.
  const Real m = gs.shell->mass[j];
  const Mat3 A = (m * dx) * gs.contact->C[j];
  const Vec3 base = m * gs.shell->v[j] + dt * gs.force[j] - A * fx;
  const Real mh = gs.held[j] == 7 ? m : Real(0);
  L0 = NodeLanes{} + Real(0);
  Nn = L0;
  L0[0] = m;
  L0[13] = mh;
  for (int a = 0; a < 3; ++a) {
    L0[1 + a] = base[a];
    L0[7 + a] = m * n[a];    // N: the shell's own normal
    L0[10 + a] = m * fx[a];  // o: m (fx - offset)
    Nn[4 + a] = m * n[a];    // n: turned to the node's side
    Li[a] = NodeLanes{} + Real(0);
    for (int c = 0; c < 3; ++c) Li[a][1 + c] = A(c, a);
    Li[a][10 + a] = -m;
  }
}

template <class AddFn>
void ShellFields::scatter_shares(Field& F, const GridShell& gs, Real dt, bool heights, bool serial,
                                 AddFn add) {
  const ShellObject& sh = *gs.shell;
  const Real dx = static_cast<Real>(F.grid.dx());
  F.grid.for_each_block_by_colour(
      [&](std::size_t b) {
        const Vec3i bc = unpack_block(F.grid.pblock_key[b]) * kBlockSize;
        F.grid.for_each_point(b, [&](std::uint32_t j) {
          const QuadraticWeights W(F.grid.grid_coord(sh.x[j]));
          const PointShare P(gs, F.normal[j], Vec3(W.fx[0], W.fx[1], W.fx[2]), j, dx, dt, heights);
          const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
          for (int i = 0; i < 3; ++i)
            for (int jj = 0; jj < 3; ++jj) {
              PointShare::Row r;
              P.row(i, jj, r);
              const Real wxy = W.w[0][i] * W.w[1][jj];
              for (int k = 0; k < 3; ++k) {
                const auto [g, node] = F.grid.pad_to_grid(b, lx + i, ly + jj, lz + k);
                add(P, r, g, node, wxy * W.w[2][k], k);
              }
            }
        });
      },
      serial);
}

void ShellFields::normalise(Node& d) {
  if (d.m > 0)
    for (int a = 0; a < 3; ++a) {
      d.p[a] /= d.m;
      d.o[a] /= d.m;
    }
}

void ShellFields::control_normals(Field& F, const ShellObject& sh, bool serial) {
  const auto& tris = sh.triangles();
  const std::size_t n = sh.size();
  if (F.tri_start.size() != n + 1) {
    F.tri_start.assign(n + 1, 0);
    for (const Eigen::Vector3i& t : tris)
      for (int k = 0; k < 3; ++k) ++F.tri_start[static_cast<std::size_t>(t[k]) + 1];
    for (std::size_t i = 0; i < n; ++i) F.tri_start[i + 1] += F.tri_start[i];
    F.tri_of.resize(F.tri_start[n]);
    std::vector<std::uint32_t> at(F.tri_start.begin(), F.tri_start.end() - 1);
    for (std::size_t t = 0; t < tris.size(); ++t)
      for (int k = 0; k < 3; ++k)
        F.tri_of[at[static_cast<std::size_t>(tris[t][k])]++] = static_cast<std::uint32_t>(t);
  }
  // The triangles' area vectors, then each point's sum of its triangles' in ascending
  // order (the order a scatter over the triangles would add them in).
  F.tri_area.resize(tris.size());
  parallel_for_each(
      tris.size(), 4096,
      [&](std::size_t i) {
        const Eigen::Vector3i& t = tris[i];
        F.tri_area[i] = (sh.x[t[1]] - sh.x[t[0]]).cross(sh.x[t[2]] - sh.x[t[0]]);
      },
      serial);
  F.normal.resize(n);
  parallel_for_each(
      n, 4096,
      [&](std::size_t i) {
        Vec3 s = Vec3::Zero();
        for (std::uint32_t k = F.tri_start[i]; k < F.tri_start[i + 1]; ++k)
          s += F.tri_area[F.tri_of[k]];
        const Real l = s.norm();
        F.normal[i] = l > 0 ? Vec3(s / l) : Vec3::Zero();
      },
      serial);
}

FoldHeights* ShellFields::begin_p2g(const SparseGrid& combined,
                                    const std::vector<GridShell>& shells, bool serial) {
  if (!heights_only_) return nullptr;
  control_normals(fields_[0], *shells[0].shell, serial);
  heights_.normal = fields_[0].normal.data();
  heights_.align = kAlign;
  heights_.blocks.resize(combined.num_grid_blocks());  // set where points reach them
  heights_.ready.assign(combined.num_grid_blocks(), 0);
  heights_.spread.store(false);
  return &heights_;
}

bool ShellFields::any_spread() const {
  return heights_.spread.load();
}

void ShellFields::shell_p2g(Field& F, const GridShell& gs, const SparseGrid& combined, Real dt,
                            bool serial) {
  const ShellObject& sh = *gs.shell;
  if (heights_only_) {
    // The combined P2G summed the heights (begin_p2g, shell_p2g_block). Where none spreads
    // the shell has no fold: one body at every node, the field stays empty.
    F.folds.clear();
    if (!any_spread()) {
      F.fold.clear();
      return;
    }
    F.x0 = sh.x;
    F.grid.bin(sh.x, serial);
    const std::size_t ng = F.grid.num_grid_blocks();
    F.nodes.resize(ng);
    F.r.resize(ng);
    F.heights.resize(ng);
    parallel_for_each(
        ng, 16,
        [&](std::size_t g) {
          // The field's grid blocks are the combined grid's around the same points.
          const int cg = combined.find_grid_block(F.grid.gblock_key[g]);
          SHELLMPM_CHECK(cg >= 0, "a shell field's grid block is on the combined grid");
          F.heights[g] = heights_.block(static_cast<std::size_t>(cg));
        },
        serial);
    split_folds(F, gs, dt, serial);
    parallel_for_each(
        ng, 16,
        [&](std::size_t g) {
          if (F.fold[g] < 0) return;  // no relative velocity there (after_g2p)
          F.r[g].fill(Vec3::Zero());
          for (Node& d : F.nodes[g]) normalise(d);
          for (Node& d : F.folds[F.fold[g]].second) normalise(d);
        },
        serial);
    return;
  }
  F.x0 = sh.x;
  control_normals(F, sh, serial);
  F.grid.bin(sh.x, serial);
  const std::size_t ng = F.grid.num_grid_blocks();
  F.nodes.resize(ng);
  F.r.resize(ng);
  parallel_for_each(
      ng, 16,
      [&](std::size_t g) {
        Node::clear(F.nodes[g].data(), kBlockNodes);
        F.r[g].fill(Vec3::Zero());
      },
      serial);
  // Straight into the nodes, colour by colour (blocks of a colour touch disjoint nodes):
  // no buffer per block to clear and gather.
  scatter_shares(F, gs, dt, folds_, serial,
                 [&](const PointShare& P, const PointShare::Row& r, int g, int node, Real w,
                     int k) { P.add(F.nodes[g][node], w, r, k); });
  // Momentum to velocity, first moment to centroid offset: right after the sums, or,
  // with fold fields, after split_folds has used the sums.
  if (!folds_) {
    parallel_for_each(
        ng, 16,
        [&](std::size_t g) {
          for (Node& d : F.nodes[g]) normalise(d);
        },
        serial);
    F.fold.assign(ng, -1);
    F.folds.clear();
    return;
  }
  split_folds(F, gs, dt, serial);
  parallel_for_each(
      ng, 16,
      [&](std::size_t g) {
        for (Node& d : F.nodes[g]) normalise(d);
        if (F.fold[g] >= 0)
          for (Node& d : F.folds[F.fold[g]].second) normalise(d);
      },
      serial);
}

void ShellFields::bulk_moments(const SparseGrid& combined, const ParticleSet& bulk,
                               std::uint32_t first_bulk, bool serial) {
  const std::size_t nb = combined.num_particle_blocks(), ng = combined.num_grid_blocks();
  bulk_buf_.resize(nb);
  bulk_mom_.resize(ng);
  std::vector<char> touch(nb, 0);
  for (std::size_t b = 0; b < nb; ++b)
    for (int o = 0; o < 8; ++o) {
      const int g = combined.pblock_nbr[b][o];
      if (g >= 0 && fielded_[g]) touch[b] = 1;
    }
  parallel_for_each(
      nb, 1,
      [&](std::size_t b) {
        if (!touch[b]) return;
        auto& buf = bulk_buf_[b];
        std::memset(static_cast<void*>(buf.data()), 0, sizeof(buf));
        const Vec3i bc = unpack_block(combined.pblock_key[b]) * kBlockSize;
        const auto* o = combined.order().data();
        const std::uint32_t s1 = combined.pblock_start[b + 1];
        // Bulk particles follow the shell points in each block's sorted slice.
        const std::uint32_t s0 = static_cast<std::uint32_t>(
            std::lower_bound(o + combined.pblock_start[b], o + s1, first_bulk) - o);
        for (std::uint32_t q = s0; q < s1; ++q) {
          const std::uint32_t p = o[q] - first_bulk;
          const QuadraticWeights W(combined.grid_coord(bulk.x[p]));
          const Real m = bulk.volume_of(p);  // volume-weighted: the densities cancel in a centroid
          for_each_stencil_node(W, bc, [&](const StencilNode& n) {
            const Real w = n.w * m;
            Moment& nd = buf[n.pad()];
            nd.m += w;
            nd.o[0] += w * (W.fx[0] - Real(n.i));
            nd.o[1] += w * (W.fx[1] - Real(n.j));
            nd.o[2] += w * (W.fx[2] - Real(n.k));
          });
        }
      },
      serial);
  parallel_for_each(
      ng, 4,
      [&](std::size_t g) {
        if (!fielded_[g]) return;
        auto& nodes = bulk_mom_[g];
        std::memset(static_cast<void*>(nodes.data()), 0, sizeof(nodes));
        combined.for_each_buffer_node(g, [&](int dn, std::size_t src, int sn) {
          if (!touch[src]) return;
          const Moment& from = bulk_buf_[src][sn];
          Moment& d = nodes[dn];
          d.m += from.m;
          for (int a = 0; a < 3; ++a) d.o[a] += from.o[a];
        });
        for (Moment& d : nodes)
          if (d.m > 0)
            for (Real& x : d.o) x /= d.m;
      },
      serial);
}

void ShellFields::find_field_blocks(const SparseGrid& combined, bool serial) {
  const std::size_t K = fields_.size(), ng = combined.num_grid_blocks();
  fblock_.assign(ng * K, -1);
  fielded_.assign(ng, 0);
  parallel_for_each(
      ng, 16,
      [&](std::size_t g) {
        int* fb = fblock_.data() + g * K;
        for (std::size_t s = 0; s < K; ++s) {
          // Heights only, no fold this step: the field was not binned.
          if (heights_only_ && fields_[s].folds.empty()) continue;
          fb[s] = fields_[s].grid.find_grid_block(combined.gblock_key[g]);
          // Heights only: a node has two bodies only on the shell's fold blocks; elsewhere
          // the field has no full sums and the node keeps one velocity.
          if (heights_only_ && fb[s] >= 0 && fields_[s].fold[fb[s]] < 0) fb[s] = -1;
          if (fb[s] >= 0) fielded_[g] = 1;
        }
      },
      serial);
}

Real ShellFields::node_bodies(std::size_t g, int n, std::vector<Body>& bodies) {
  const int* fb = fblock_.data() + g * fields_.size();
  bodies.clear();
  Real ms = 0;
  for (std::size_t s = 0; s < fields_.size(); ++s) {
    if (fb[s] < 0) continue;
    Field& F = fields_[s];
    const auto push = [&](const Node& f, Vec3& r) {
      if (f.m <= 0) return;
      ms += f.m;
      bodies.push_back({static_cast<int>(s), &f, &r, Vec3(f.p[0], f.p[1], f.p[2]), Vec3::Zero(),
                        Vec3::Zero(), Vec3::Zero(), Real(0)});
    };
    push(F.nodes[fb[s]][n], F.r[fb[s]][n]);
    const int fi = F.fold[fb[s]];
    if (fi >= 0) push(F.folds[fi].second[n], F.folds[fi].r[n]);
  }
  return ms;
}

void ShellFields::body_geometry(Body& B) {
  const Node& f = *B.f;
  const Vec3 ns(f.n[0], f.n[1], f.n[2]), Ns(f.N[0], f.N[1], f.N[2]);
  const Real nl = ns.norm(), Nl = Ns.norm();
  B.nrm = nl > 0 ? Vec3(ns / nl) : Vec3::Zero();
  B.own = Nl > 0 ? Vec3(Ns / Nl) : Vec3::Zero();
  B.off = Vec3(f.o[0], f.o[1], f.o[2]);
  B.winv = inverse_field_mass(f.m, f.held);
}

Vec3 ShellFields::contact_normal(const Body& A, const Body& B, Real sign) {
  const Real w = A.winv + B.winv;
  if (std::isfinite(w) && w > 0) {
    const Vec3 n = (B.winv / w) * A.nrm + sign * (A.winv / w) * B.nrm;
    const Real l = n.norm();
    if (l > Real(1e-6)) return n / l;
  }
  return (A.nrm + sign * B.nrm).normalized();
}

Real ShellFields::shell_gap(const Body& A, const Body& B, Real h) const {
  // Two layers of one shell (its fold classes) meet at the stencils in either mode: its
  // contact particles hold them (self-contact is not gated by the gap).
  if (!surfaces_ || A.shell == B.shell) return -std::numeric_limits<Real>::infinity();
  return h * dx_ - (half_thickness_[A.shell] + half_thickness_[B.shell]);
}

bool ShellFields::shell_pairs(std::vector<Body>& bodies, Union* groups) const {
  bool acted = false;
  const std::size_t cnt = bodies.size();
  for (std::size_t i = 0; i < cnt; ++i)
    for (std::size_t j = i + 1; j < cnt; ++j) {
      Body &A = bodies[i], &B = bodies[j];
      const Real facing = A.nrm.dot(B.nrm);
      Vec3 nab;  // unit normal from a towards b
      Real h;    // centroid distance along nab [cells]
      if (facing < Real(-0.5)) {
        nab = contact_normal(A, B, Real(-1));
        h = nab.dot(B.off - A.off);
      } else if (facing > Real(0.5)) {
        // Both on the same side of the node: closer than a cell, no node between
        // them. The one whose centroid lies nearer the node along their common
        // normal u is in front; without this the rule let go exactly when two
        // sheets were pressed closest (hanging curtains hit at 20 m/s crossed).
        const Vec3 u = contact_normal(A, B, Real(1));
        h = u.dot(B.off - A.off);
        // Level: within 0.05 cells, or with surface contact (where sheets rest a thickness
        // apart, often below 0.05 cells) within 0.001 cells, float round-off.
        const bool gated = surfaces_ && A.shell != B.shell;
        if (std::abs(h) < (gated ? Real(0.001) : Real(0.05))) {
          if (!gated) continue;
          // Level within round-off: touching at any contact thickness; no normal to
          // choose, so the rule waits for the next step.
          acted = true;
          continue;
        }
        nab = h > 0 ? u : Vec3(-u);
        h = std::abs(h);
      } else {
        continue;
      }
      const Real gap = shell_gap(A, B, h);
      const bool ruled = field_contact(nab, std::sqrt(friction_[A.shell] * friction_[B.shell]),
                                       A.winv, A.vel, B.winv, B.vel, closing_allowance(gap, dt_));
      if ((ruled || gap <= 0) && groups) groups->join(int(i), int(j));
      acted |= ruled || gap <= 0;
    }
  return acted;
}

bool ShellFields::bulk_pairs(std::vector<Body>& bodies, const Moment* bm, Real mk, Vec3& vk,
                             Union* groups) const {
  // Which side of a shell the bulk material is on: where its mass centroid lies
  // along the shell's own normal (Nairn's multi-material contact takes the
  // normal from the mass distribution the same way). The node's side is not
  // enough: the kernel spreads a body's mass 1.5 dx past its particles, so a
  // heavy block on a light film also has mass at nodes under the film, where
  // "the node's side" reads its approach as separation and lets it through.
  // The node's side stays the fallback where the bulk centroid lies on the
  // shell (within 0.05 dx: bulk on both sides).
  Vec3 ok = Vec3::Zero();
  bool have_ok = false;
  if (bm && bm->m > 0) {
    ok = Vec3(bm->o[0], bm->o[1], bm->o[2]);
    have_ok = true;
  }
  // The bulk surface's distance from the node [cells, positive outside the material], from
  // its volume fraction there (contact_gap.h); without the sums, at the node.
  const Real s =
      have_ok && surfaces_ ? surface_distance_from_share(bm->m / (dx_ * dx_ * dx_)) : Real(0);
  bool acted = false;
  const int bulk = int(bodies.size());
  for (int i = 0; i < bulk; ++i) {
    Body& B = bodies[std::size_t(i)];
    Vec3 nb = B.nrm;
    if (have_ok && B.own.squaredNorm() > 0) {
      const Real d = B.own.dot(ok - B.off);
      if (std::abs(d) > Real(0.05)) nb = d > 0 ? B.own : Vec3(-B.own);
    }
    if (nb.squaredNorm() == 0) continue;
    // nb points from the shell to the bulk: the shell's centroid lies -nb . off cells
    // beyond the node, the material's surface s cells before it.
    const Real gap = surfaces_ && have_ok ? (s - nb.dot(B.off)) * dx_ - half_thickness_[B.shell]
                                          : -std::numeric_limits<Real>::infinity();
    const bool ruled = field_contact(nb, friction_[B.shell], B.winv, B.vel, Real(1) / mk, vk,
                                     closing_allowance(gap, dt_));
    if ((ruled || gap <= 0) && groups) groups->join(i, bulk);
    acted |= ruled || gap <= 0;
  }
  return acted;
}

void ShellFields::resolve_node(const GridNode& cn, std::size_t g, int n, bool moments,
                               std::vector<Body>& bodies) {
  const Real ms = node_bodies(g, n, bodies);
  const Real mk = cn.m - ms;  // the bulk material's share
  const bool bulk = mk >= kBulkMin * cn.m;
  const std::size_t cnt = bodies.size();
  if (cnt == 0 || cnt + (bulk ? 1 : 0) < 2) return;
  if (!bulk && mk > kShellOnly * cn.m) return;  // a sliver of bulk: one velocity
  const Vec3 p(cn.v[0], cn.v[1], cn.v[2]);
  const Vec3 v0 = p / cn.m;
  Vec3 ps = Vec3::Zero();
  for (const Body& B : bodies) ps += B.f->m * B.vel;
  Vec3 vk = bulk ? Vec3((p - ps) / mk) : Vec3::Zero();
  for (Body& B : bodies) body_geometry(B);
  // Shell against shell (facing across the node, or stacked on one side of it),
  // then each shell against the bulk field: Bardenhagen's rule.
  Union groups(int(cnt) + 1);
  Union* uf = implicit_ ? &groups : nullptr;
  bool met = shell_pairs(bodies, uf);
  if (bulk) met |= bulk_pairs(bodies, moments ? &bulk_mom_[g][n] : nullptr, mk, vk, uf);
  if (uf) {
    // Each body's group as the index of its first body, 4 bits a body; more bodies than
    // fit: one group (zero).
    std::uint64_t code = 0;
    if (cnt + 1 <= std::size_t(kMaxGroupBodies))
      for (std::size_t i = 0; i <= cnt; ++i) code |= std::uint64_t(groups.find(int(i))) << (4 * i);
    group_[g][n] = code;
  }
  for (const Body& B : bodies) *B.r = B.vel - v0;
  if (met) met_[g] |= std::uint64_t(1) << n;
  if (bulk) r_bulk_[g][n] = vk - v0;
  shared_[g] |= std::uint64_t(1) << n;
  // Another body than the shell's own layers: another shell, or the bulk field.
  bool others = bulk;
  for (std::size_t i = 1; i < cnt && !others; ++i) others = bodies[i].shell != bodies[0].shell;
  if (others) others_[g] |= std::uint64_t(1) << n;
  if (bulk) bulk_at_[g] |= std::uint64_t(1) << n;
}

void ShellFields::p2g(const SparseGrid& combined, const std::vector<GridShell>& shells, Real dt,
                      const ParticleSet* bulk_particles, std::uint32_t first_bulk, bool serial) {
  const std::size_t K = fields_.size();
  friction_.resize(K);
  for (std::size_t s = 0; s < K; ++s) {
    shell_p2g(fields_[s], shells[s], combined, dt, serial);
    friction_[s] = shells[s].contact->params().friction;
  }
  const std::size_t ng = combined.num_grid_blocks();
  find_field_blocks(combined, serial);
  r_bulk_.resize(ng);
  shared_.assign(ng, 0);
  others_.assign(ng, 0);
  bulk_at_.assign(ng, 0);
  met_.assign(ng, 0);
  dt_ = dt;
  dx_ = static_cast<Real>(combined.dx());
  slotted_ = false;
  slot_bits_.assign(ng, 0);
  one_bits_.clear();
  if (implicit_) group_.resize(ng);
  const bool moments = bulk_particles && bulk_particles->size() > 0;
  if (moments) bulk_moments(combined, *bulk_particles, first_bulk, serial);
  parallel_for(
      ng, 4,
      [&](std::size_t gb, std::size_t ge) {
        std::vector<Body> bodies;
        for (std::size_t g = gb; g < ge; ++g) {
          if (!fielded_[g]) continue;
          r_bulk_[g].fill(Vec3::Zero());
          for (int n = 0; n < kBlockNodes; ++n) {
            const GridNode& cn = combined.gblock_nodes[g][n];
            if (cn.m > 0) resolve_node(cn, g, n, moments, bodies);
          }
        }
      },
      serial);
}

std::size_t ShellFields::met_nodes() const {
  if (!active_) return 0;
  std::size_t n = 0;
  for (std::uint64_t bits : met_) n += static_cast<std::size_t>(__builtin_popcountll(bits));
  return n;
}

void ShellFields::apart_sites(const SparseGrid& combined, const ShellPointTable& table,
                              const std::vector<Vec3>& points,
                              std::vector<std::vector<std::uint8_t>>& release, bool serial) const {
  const std::uint32_t first_site = table.num_control_points(), end = std::uint32_t(table.size());
  parallel_for_each(
      combined.num_particle_blocks(), 1,
      [&](std::size_t b) {
        const auto& nbr = combined.pblock_nbr[b];
        // Nothing shared around this block: its sites keep their state.
        if (std::none_of(nbr.begin(), nbr.end(),
                         [&](int g) { return g >= 0 && others_[std::size_t(g)] != 0; }))
          return;
        const Vec3i bc = unpack_block(combined.pblock_key[b]) * kBlockSize;
        combined.for_each_point(b, [&](std::uint32_t i) {
          if (i < first_site || i >= end) return;  // control points; bulk particles
          const QuadraticWeights W(combined.grid_coord(points[i]));
          const std::size_t s = table.shell(i);
          // Apart from the grid's own rule: some node of the stencil is shared with another
          // body (another shell, or bulk material). Not with the shell's own other fold
          // class: its contact particles hold its layers apart, as at the stencils (the
          // heights split a fold into classes only a cell apart; released, a fold sank
          // onto its cloth, shared its velocity and slid at a ninth of Coulomb's rate).
          bool apart = false;
          for_each_stencil_node(W, bc, [&](const StencilNode& n) {
            const int g = nbr[(n.px >> 2) * 4 + (n.py >> 2) * 2 + (n.pz >> 2)];
            if (apart || g < 0) return;
            apart = others_[std::size_t(g)] >> block_node(n.px & 3, n.py & 3, n.pz & 3) & 1;
          });
          if (apart) release[s][table.local(i)] = 1;
        });
      },
      serial);
}

void ShellFields::keep_free_velocities(const SparseGrid& combined, bool serial) {
  const std::size_t ng = combined.num_grid_blocks();
  free_slot_.assign(ng, -1);
  int slots = 0;
  for (std::size_t g = 0; g < ng; ++g)
    if (g < shared_.size() && shared_[g]) free_slot_[g] = slots++;
  free_.resize(std::size_t(slots));
  parallel_for_each(
      ng, 16,
      [&](std::size_t g) {
        if (free_slot_[g] < 0) return;
        auto& f = free_[std::size_t(free_slot_[g])];
        for (int n = 0; n < kBlockNodes; ++n) {
          const GridNode& nd = combined.gblock_nodes[g][n];
          f[n] = Vec3(nd.v[0], nd.v[1], nd.v[2]);
        }
      },
      serial);
}

double ShellFields::gate_collider_node(GridNode& nd, std::size_t g, int n, const Vec3& node_pos,
                                       const ColliderGate& gate) {
  const std::size_t K = fields_.size();
  const int* fb = fblock_.data() + g * K;
  const Vec3 vf = free_[std::size_t(free_slot_[g])][n];
  const Real dt = dt_;
  // The work: each body's impulse times the collider's velocity, less the node's own
  // (counted by the colliders' stage).
  const Vec3d vc = gate.velocity ? gate.velocity(g, n) : Vec3d::Zero();
  const bool moving = vc.squaredNorm() > 0;
  double work = 0;
  if (moving)
    work -= double(nd.m) * Vec3d(nd.v[0] - vf[0], nd.v[1] - vf[1], nd.v[2] - vf[2]).dot(vc);
  // A body's velocity, its own (vf + r), meets the collider's condition where its contact
  // surface (at `gap` [m] from the collider) comes within reach in the step.
  const auto body = [&](Real gap, const Vec3& r, Real m) -> Vec3 {
    Vec3 own = vf + r;
    if (gap <= gate.reach + dt * own.norm()) {
      const Vec3 before = own;
      gate.apply(g, n, own);
      if (moving) work += double(m) * (own - before).cast<double>().dot(vc);
    }
    return own;
  };
  const auto shell_gap = [&](const Node& f, int s) {
    const Vec3 c = node_pos + dx_ * Vec3(f.o[0], f.o[1], f.o[2]);
    return Real(gate.phi(c.cast<double>())) - half_thickness_[std::size_t(s)];
  };
  // The bulk field: its surface along the collider's normal lies s cells beyond the node
  // (its volume fraction there, contact_gap.h).
  Vec3 node_v(nd.v[0], nd.v[1], nd.v[2]);  // with the collider's condition
  if (bulk_at_[g] >> n & 1) {
    const Moment& bm = bulk_mom_[g][n];
    const Real sk = bm.m > 0 ? surface_distance_from_share(bm.m / (dx_ * dx_ * dx_)) : Real(0);
    node_v = body(Real(gate.phi(node_pos.cast<double>())) + sk * dx_, r_bulk_[g][n], bm.m);
  }
  for (std::size_t s = 0; s < K; ++s) {
    if (fb[s] < 0) continue;
    Field& F = fields_[s];
    Node& f = F.nodes[fb[s]][n];
    Vec3& r = F.r[fb[s]][n];
    if (f.m > 0) r = body(shell_gap(f, int(s)), r, f.m) - node_v;
    const int fi = F.fold[fb[s]];
    if (fi < 0) continue;
    Node& f2 = F.folds[fi].second[n];
    Vec3& r2 = F.folds[fi].r[n];
    if (f2.m > 0) r2 = body(shell_gap(f2, int(s)), r2, f2.m) - node_v;
  }
  for (int a = 0; a < 3; ++a) nd.v[a] = node_v[a];
  return work;
}

void ShellFields::before_g2p(SparseGrid& combined, const SkipFn& skip, bool serial,
                             const ColliderGate* gate) {
  const std::size_t K = fields_.size();
  gate_block_work_.assign(gate ? combined.num_grid_blocks() : 0, 0.0);
  parallel_for_each(
      combined.num_grid_blocks(), 4,
      [&](std::size_t g) {
        if (!shared_[g]) return;
        const int* fb = fblock_.data() + g * K;
        const Vec3i c = unpack_block(combined.gblock_key[g]) * kBlockSize;
        for (int n = 0; n < kBlockNodes; ++n) {
          if (!(shared_[g] >> n & 1)) continue;
          if (slot_bits_[g] >> n & 1) continue;  // the implicit solve moved its bodies
          if (g < one_bits_.size() && (one_bits_[g] >> n & 1)) continue;  // one velocity
          const Vec3i node = c + Vec3i(n >> 4, (n >> 2) & 3, n & 3);
          const bool one = skip && skip(node);
          if (!one && gate && gate->engaged(g, n)) {
            gate_block_work_[g] +=
                gate_collider_node(combined.gblock_nodes[g][n], g, n,
                                   combined.node_position(node).cast<Real>(), *gate);
            continue;
          }
          const Vec3 rk = r_bulk_[g][n];
          for (std::size_t s = 0; s < K; ++s) {
            if (fb[s] < 0) continue;
            Field& F = fields_[s];
            Vec3& r = F.r[fb[s]][n];
            r = one ? Vec3::Zero() : Vec3(r - rk);
            const int fi = F.fold[fb[s]];
            if (fi < 0) continue;
            Vec3& r2 = F.folds[fi].r[n];
            r2 = one ? Vec3::Zero() : Vec3(r2 - rk);
          }
          if (one) continue;
          GridNode& nd = combined.gblock_nodes[g][n];
          for (int a = 0; a < 3; ++a) nd.v[a] += rk[a];
        }
      },
      serial);
  gate_work_ = 0;
  for (const double w : gate_block_work_) gate_work_ += w;
}

void ShellFields::each_relative(const Field& F, bool serial, const RelativeFn& fn) const {
  const bool folded = !F.folds.empty();
  if (heights_only_ && !folded) return;  // relative velocities exist on fold blocks only
  parallel_for_each(
      F.grid.num_particle_blocks(), 1,
      [&](std::size_t b) {
        const Vec3i bc = unpack_block(F.grid.pblock_key[b]) * kBlockSize;
        const auto& nbr = F.grid.pblock_nbr[b];
        // Heights only: relative velocities exist on fold blocks only.
        if (heights_only_ &&
            std::none_of(nbr.begin(), nbr.end(), [&](int g) { return g >= 0 && F.fold[g] >= 0; }))
          return;
        for (std::uint32_t q = F.grid.pblock_start[b]; q < F.grid.pblock_start[b + 1]; ++q) {
          const std::uint32_t j = F.grid.order()[q];
          const QuadraticWeights W(F.grid.grid_coord(F.x0[j]));
          const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
          Vec3 dv = Vec3::Zero();
          Mat3 B = Mat3::Zero();
          bool any = false;
          for_each_stencil_node(W, bc, [&](const StencilNode& n) {
            const int o = (n.px >> 2) * 4 + (n.py >> 2) * 2 + (n.pz >> 2);
            const int bn = block_node(n.px & 3, n.py & 3, n.pz & 3);
            const int fi = folded ? F.fold[nbr[o]] : -1;
            // Where the shell folds, the control point reads its own class.
            const bool second = fi >= 0 && is_split(F.folds[fi], bn) &&
                                fold_height(F.normal[j], fx, n.i, n.j, n.k) >= F.folds[fi].cut[bn];
            // Heights only: F.r is kept on fold blocks alone, zero elsewhere.
            if (heights_only_ && fi < 0) return;
            const Vec3& rn = second ? F.folds[fi].r[bn] : F.r[nbr[o]][bn];
            if (rn.isZero()) return;
            any = true;
            dv += n.w * rn;
            B += (n.w * rn) * (Vec3(Real(n.i), Real(n.j), Real(n.k)) - fx).transpose();
          });
          if (any) fn(j, dv, B);
        }
      },
      serial);
}

void ShellFields::after_g2p(std::vector<GridShell>& shells, Real dt, bool serial) {
  // Control points read their shell's relative velocity.
  for (std::size_t s = 0; s < fields_.size(); ++s) {
    GridShell& gs = shells[s];
    ShellObject& sh = *gs.shell;
    const Real c_scale = Real(4) / static_cast<Real>(fields_[s].grid.dx());
    each_relative(fields_[s], serial, [&](std::uint32_t j, const Vec3& sum, const Mat3& B) {
      Vec3 dv = sum;
      // Pinned components keep their prescribed velocity, but their affine matrix still
      // becomes the gradient of this shell's own field: left at the shared node's, a
      // pinned sheet under a sliding block would carry the block's shear and the contact
      // would see it moving.
      const std::uint8_t held = gs.held[j];
      for (int a = 0; a < 3; ++a)
        if (held & (1u << a)) {
          gs.pin_impulse[j][a] -= sh.mass[j] * dv[a];  // the pin holds it against dv too
          dv[a] = 0;
        }
      sh.v[j] += dv;
      sh.x[j] += dt * dv;
      gs.contact->C[j] += c_scale * B;
    });
  }
}

}  // namespace shellmpm
