#include "sim/contact/shell_guard.h"

#include "sim/contact/shell_guard_util.h"
#include "sim/core/parallel.h"
#include "sim/math/box_pairs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace shellmpm {
using guard_util::boxes_apart;
using guard_util::kPointGrain;
using guard_util::to_d;

namespace {

/// Unique undirected edges of a triangle list, sorted.
std::vector<Eigen::Vector2i> unique_edges(const std::vector<Eigen::Vector3i>& tris) {
  std::vector<Eigen::Vector2i> e;
  e.reserve(tris.size() * 3);
  for (const Eigen::Vector3i& t : tris)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      e.emplace_back(std::min(a, b), std::max(a, b));
    }
  const auto less = [](const Eigen::Vector2i& x, const Eigen::Vector2i& y) {
    return x[0] != y[0] ? x[0] < y[0] : x[1] < y[1];
  };
  std::sort(e.begin(), e.end(), less);
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return e;
}

}  // namespace

void ShellGuard::setup(const std::vector<GridShell>& shells, double gap, bool serial) {
  gap_ = gap;
  bulk_gap_ = gap;
  serial_ = serial;
  meshes_.clear();
  friction_.clear();
  point_offset_.assign(1, 0);
  vertex_offset_.assign(1, 0);
  for (const GridShell& g : shells) {
    const ShellObject& sh = *g.shell;
    Mesh m;
    m.limit =
        std::make_unique<LimitMesh>(sh.basis(), sh.triangles(), std::vector<Eigen::Vector2d>{}, 0);
    m.edges = unique_edges(m.limit->triangles());
    std::vector<Vec3> rest_x(sh.rest.size());
    for (std::size_t i = 0; i < rest_x.size(); ++i) rest_x[i] = sh.rest[i].cast<Real>();
    std::vector<Vec3> rp, rn;
    m.limit->evaluate(rest_x.data(), rp, rn);
    m.rest.resize(rp.size());
    for (std::size_t i = 0; i < rp.size(); ++i) m.rest[i] = to_d(rp[i]);
    double edge_sum = 0;
    for (const Eigen::Vector2i& e : m.edges) edge_sum += (m.rest[e[0]] - m.rest[e[1]]).norm();
    m.near = std::max(2.0 * gap, m.edges.empty() ? 0.0 : edge_sum / m.edges.size());
    point_offset_.push_back(point_offset_.back() + sh.size());
    vertex_offset_.push_back(vertex_offset_.back() + m.limit->num_vertices());
    meshes_.push_back(std::move(m));
    friction_.push_back(g.contact ? static_cast<double>(g.contact->params().friction)
                                  : sh.material().friction);
  }
  vert_shell_.clear();
  for (std::size_t s = 0; s < meshes_.size(); ++s) vert_shell_.resize(vertex_offset_[s + 1], s);
  shell_list_ = {};
  near_vt_ = {};
  near_ee_ = {};
  rest_near_built_ = false;
  x_built_.clear();
  bulk_list_ = {};
  all_tris_.clear();
  all_edges_.clear();
  for (std::size_t s = 0; s < meshes_.size(); ++s) {
    const int o = static_cast<int>(vertex_offset_[s]);
    for (const Eigen::Vector3i& t : meshes_[s].limit->triangles())
      all_tris_.emplace_back(t[0] + o, t[1] + o, t[2] + o);
    for (const Eigen::Vector2i& e : meshes_[s].edges)
      all_edges_.emplace_back(e[0] + o, e[1] + o, e[1] + o);
  }
}

void ShellGuard::add_vertex(std::size_t s, int v, double scale) {
  const LimitMesh& L = *meshes_[s].limit;
  const std::vector<int>& pts = L.row_points(static_cast<std::size_t>(v));
  const std::vector<Real>& w = L.row_weights(static_cast<std::size_t>(v));
  for (std::size_t k = 0; k < pts.size(); ++k)
    entries_.push_back(
        {point_offset_[s] + static_cast<std::size_t>(pts[k]), scale * static_cast<double>(w[k])});
}

void ShellGuard::add_pair(const Vec3d& n, double d, double gap, double dt, double mu) {
  Pair p;
  p.mu = mu;
  p.begin = pairs_.empty() ? 0 : pairs_.back().end;
  // Merge the entries of one control point (sorted by point, so the sums have a fixed
  // order).
  std::sort(entries_.begin() + static_cast<std::ptrdiff_t>(p.begin), entries_.end(),
            [](const Entry& a, const Entry& b) { return a.point < b.point; });
  std::size_t out = p.begin;
  for (std::size_t i = p.begin; i < entries_.size(); ++i) {
    if (out > p.begin && entries_[out - 1].point == entries_[i].point)
      entries_[out - 1].w += entries_[i].w;
    else
      entries_[out++] = entries_[i];
  }
  entries_.resize(out);
  p.end = out;
  p.n = n;
  p.target = -std::max(d - gap, 0.0) / dt;
  p.denom = 0;
  for (std::size_t i = p.begin; i < p.end; ++i) {
    const Vec3d& im = inv_mass_[entries_[i].point];
    p.denom += entries_[i].w * entries_[i].w * (n.cwiseProduct(n)).dot(im);
  }
  pairs_.push_back(p);
}

bool ShellGuard::point_triangle_pair(const Vec3d& x, const Eigen::Vector3i& T, double r,
                                     double tiny, Vec3d& w, double& d, Vec3d& n) const {
  const Vec3d &a = pos_[T[0]], &b = pos_[T[1]], &c = pos_[T[2]];
  if (boxes_apart<1, 3>({&x}, {&a, &b, &c}, r)) return false;
  w = closest_point_barycentric(x, a, b, c);
  const Vec3d diff = x - (w[0] * a + w[1] * b + w[2] * c);
  d = diff.norm();
  if (!(d < r)) return false;
  if (d > tiny) {
    n = diff / d;
    return true;
  }
  n = (b - a).cross(c - a);  // on the triangle: its own normal
  if (!(n.norm() > 0)) return false;
  n.normalize();
  return true;
}

double ShellGuard::rate(const Pair& p) const {
  double u = 0;
  for (std::size_t i = p.begin; i < p.end; ++i) u += entries_[i].w * p.n.dot(v_[entries_[i].point]);
  return u;
}

std::size_t ShellGuard::impact_zones(double tol) {
  // Union-find over the points of the pairs still closing too fast; each zone then moves
  // as one (the mass-weighted mean velocity, per component; a held component sets the
  // zone's). A zone's pairs then have zero relative velocity (their weights sum to 0),
  // which meets every target (all <= 0). Zones grow while new pairs fail, a few rounds.
  const std::size_t n = v_.size();
  std::vector<std::size_t> parent;
  const auto find = [&](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::vector<char> in_zone;
  std::size_t zoned = 0;
  for (int round = 0; round < 8; ++round) {
    bool any = false;
    for (const Pair& p : pairs_) {
      if (!(p.target - rate(p) > tol)) continue;
      if (!any && parent.empty()) {
        parent.resize(n);
        for (std::size_t i = 0; i < n; ++i) parent[i] = i;
        in_zone.assign(n, 0);
      }
      any = true;
      const std::size_t root = find(entries_[p.begin].point);
      for (std::size_t i = p.begin; i < p.end; ++i) {
        in_zone[entries_[i].point] = 1;
        const std::size_t r = find(entries_[i].point);
        if (r != root) parent[std::max(r, root)] = std::min(r, root);
      }
    }
    if (!any) break;
    // Zone velocities, summed in point order.
    std::vector<Vec3d> mom(n, Vec3d::Zero()), mass(n, Vec3d::Zero());
    std::vector<Eigen::Vector3i> held(n, Eigen::Vector3i::Constant(-1));
    for (std::size_t i = 0; i < n; ++i) {
      if (!in_zone[i]) continue;
      const std::size_t r = find(i);
      for (int a = 0; a < 3; ++a) {
        if (inv_mass_[i][a] > 0) {
          mom[r][a] += v_[i][a] / inv_mass_[i][a];
          mass[r][a] += 1.0 / inv_mass_[i][a];
        } else if (held[r][a] < 0) {
          held[r][a] = static_cast<int>(i);
        }
      }
    }
    zoned = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!in_zone[i]) continue;
      ++zoned;
      const std::size_t r = find(i);
      for (int a = 0; a < 3; ++a) {
        if (inv_mass_[i][a] == 0) continue;  // held: keeps its prescribed value
        if (held[r][a] >= 0) {
          const auto h = static_cast<std::size_t>(held[r][a]);
          if (!held_v_.empty())  // the pin's impulse to bring the point to its velocity
            pin_work_ += (v_[h][a] - v_[i][a]) / inv_mass_[i][a] * held_v_[h][a];
          v_[i][a] = v_[h][a];
        } else if (mass[r][a] > 0)
          v_[i][a] = mom[r][a] / mass[r][a];
      }
    }
  }
  return zoned;
}

ShellGuardStats ShellGuard::apply(std::vector<GridShell>& shells, const GuardBulk& bulk,
                                  double dt) {
  std::vector<std::vector<Vec3>> start(shells.size());
  for (std::size_t s = 0; s < shells.size(); ++s) {
    const ShellObject& sh = *shells[s].shell;
    start[s].resize(sh.size());
    for (std::size_t j = 0; j < sh.size(); ++j)
      start[s][j] = sh.x[j] - static_cast<Real>(dt) * sh.v[j];
  }
  return apply(shells, start, bulk, dt);
}

double ShellGuard::point_bounds(const std::vector<GridShell>& shells,
                                const std::vector<std::vector<Vec3>>& start, double dt) {
  // The largest speed, and the box of the points' displacements since the shell list's
  // build (where it was built for these points): reads only, every step.
  const std::size_t np = point_offset_.back();
  struct Bounds {
    double vmax = 0;  // squared, until the end
    Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  };
  const bool since_build = x_built_.size() == np;
  Bounds all;
  for (std::size_t s = 0; s < shells.size(); ++s) {
    const ShellObject& sh = *shells[s].shell;
    const auto parts = chunk_parts(
        sh.size(), kPointGrain, serial_, Bounds(), [&](std::size_t b, std::size_t e, Bounds& m) {
          for (std::size_t j = b; j < e; ++j) {
            const Vec3d x0 = to_d(start[s][j]);
            // The squared speed: its square root once at the end is the same number
            // (the square root is monotone and correctly rounded).
            m.vmax = std::max(m.vmax, ((to_d(sh.x[j]) - x0) / dt).squaredNorm());
            if (since_build) {
              const Vec3d d = x0 - x_built_[point_offset_[s] + j];
              m.lo = m.lo.cwiseMin(d);
              m.hi = m.hi.cwiseMax(d);
            }
          }
        });
    for (const Bounds& m : parts) {
      all.vmax = std::max(all.vmax, m.vmax);
      all.lo = all.lo.cwiseMin(m.lo);
      all.hi = all.hi.cwiseMax(m.hi);
    }
  }
  // Two points' relative displacement is within the box's diagonal (a rigid motion has
  // none); a non-finite one (or no build yet) bounds nothing.
  const double spread = (all.hi - all.lo).norm();
  spread_ = since_build && np > 0 && std::isfinite(spread)
                ? spread
                : std::numeric_limits<double>::infinity();
  return std::sqrt(all.vmax);
}

void ShellGuard::load_points(const std::vector<GridShell>& shells,
                             const std::vector<std::vector<Vec3>>& start, double dt) {
  const std::size_t np = point_offset_.back();
  v_.resize(np);
  v_end_.resize(np);
  inv_mass_.resize(np);
  x0_.resize(np);
  held_v_.clear();
  pin_work_ = 0;
  bool any_held = false;
  for (const GridShell& g : shells)
    for (const std::uint8_t h : g.held) any_held = any_held || h != 0;
  if (any_held) held_v_.assign(np, Vec3d::Zero());
  for (std::size_t s = 0; s < shells.size(); ++s) {
    const ShellObject& sh = *shells[s].shell;
    parallel_for_each(
        sh.size(), kPointGrain,
        [&](std::size_t j) {
          const std::size_t g = point_offset_[s] + j;
          x0_[g] = to_d(start[s][j]);
          v_[g] = v_end_[g] = (to_d(sh.x[j]) - x0_[g]) / dt;
          const double im = sh.mass[j] > 0 ? 1.0 / static_cast<double>(sh.mass[j]) : 0.0;
          const std::uint8_t held = j < shells[s].held.size() ? shells[s].held[j] : 0;
          for (int a = 0; a < 3; ++a) {
            inv_mass_[g][a] = (held & (1u << a)) ? 0.0 : im;
            if (any_held && (held & (1u << a)) && im > 0) held_v_[g][a] = v_[g][a];
          }
        },
        serial_);
  }
}

void ShellGuard::limit_positions() {
  pos_.assign(vertex_offset_.back(), Vec3d::Zero());
  for (std::size_t s = 0; s < meshes_.size(); ++s) {
    const LimitMesh& L = *meshes_[s].limit;
    parallel_for_each(
        L.num_vertices(), kPointGrain,
        [&](std::size_t row) {
          const std::size_t g = vertex_offset_[s] + row;
          const std::vector<int>& pts = L.row_points(row);
          const std::vector<Real>& w = L.row_weights(row);
          for (std::size_t k = 0; k < pts.size(); ++k)
            pos_[g] += static_cast<double>(w[k]) *
                       x0_[point_offset_[s] + static_cast<std::size_t>(pts[k])];
        },
        serial_);
  }
}

void ShellGuard::load_bulk(const GuardBulk& bulk, double dt) {
  const ParticleSet& ps = *bulk.particles;
  const std::size_t np = point_offset_.back(), nbk = bulk_idx_.size();
  v_.resize(np + nbk);
  inv_mass_.resize(np + nbk);
  if (!held_v_.empty()) held_v_.resize(np + nbk, Vec3d::Zero());
  bulk_x0_.resize(nbk);
  for (std::size_t k = 0; k < nbk; ++k) {
    const std::size_t p = bulk_idx_[k];
    v_[np + k] = to_d(ps.v[p]);
    bulk_x0_[k] = to_d(ps.x[p]) - dt * v_[np + k];
    const double m = static_cast<double>(ps.volume_of(p)) *
                     static_cast<double>((*bulk.densities)[ps.material_of(p)]);
    inv_mass_[np + k] = Vec3d::Constant(m > 0 ? 1.0 / m : 0.0);
  }
}

void ShellGuard::gather_pairs(double r, double r_bulk, double dt) {
  const std::size_t np = point_offset_.back();
  entries_.clear();
  pairs_.clear();
  const auto local = [&](std::size_t g) {
    return static_cast<int>(g - vertex_offset_[vert_shell_[g]]);
  };
  const double tiny = 1e-12 * gap_;
  // Vertex-triangle pairs.
  for (const Eigen::Vector2i& c : vt_cand_) {
    const std::size_t p = static_cast<std::size_t>(c[0]);
    const Eigen::Vector3i& T = all_tris_[static_cast<std::size_t>(c[1])];
    Vec3d w, n;
    double d;
    if (!point_triangle_pair(pos_[p], T, r, tiny, w, d, n)) continue;
    add_vertex(vert_shell_[p], local(p), 1.0);
    for (int k = 0; k < 3; ++k) add_vertex(vert_shell_[T[k]], local(T[k]), -w[k]);
    add_pair(n, d, gap_, dt, std::sqrt(friction_[vert_shell_[p]] * friction_[vert_shell_[T[0]]]));
  }
  // Edge-edge pairs.
  for (const Eigen::Vector2i& c : ee_cand_) {
    const Eigen::Vector3i& E = all_edges_[static_cast<std::size_t>(c[0])];
    const Eigen::Vector3i& F = all_edges_[static_cast<std::size_t>(c[1])];
    const Vec3d &p0 = pos_[E[0]], &p1 = pos_[E[1]], &q0 = pos_[F[0]], &q1 = pos_[F[1]];
    if (boxes_apart<2, 2>({&p0, &p1}, {&q0, &q1}, r)) continue;
    const Eigen::Vector2d st2 = closest_segment_params(p0, p1, q0, q1);
    const Vec3d diff = (p0 + st2[0] * (p1 - p0)) - (q0 + st2[1] * (q1 - q0));
    const double d = diff.norm();
    if (!(d < r)) continue;
    Vec3d n;
    if (d > tiny) {
      n = diff / d;
    } else {
      n = (p1 - p0).cross(q1 - q0);
      if (!(n.norm() > 0)) continue;
      n.normalize();
    }
    const std::size_t s = vert_shell_[E[0]], s2 = vert_shell_[F[0]];
    add_vertex(s, local(E[0]), 1.0 - st2[0]);
    add_vertex(s, local(E[1]), st2[0]);
    add_vertex(s2, local(F[0]), -(1.0 - st2[1]));
    add_vertex(s2, local(F[1]), -st2[1]);
    add_pair(n, d, gap_, dt, std::sqrt(friction_[s] * friction_[s2]));
  }
  // Bulk particle-triangle pairs.
  for (const Eigen::Vector2i& c : bt_cand_) {
    const std::size_t k = static_cast<std::size_t>(c[0]);
    const Eigen::Vector3i& T = all_tris_[static_cast<std::size_t>(c[1])];
    Vec3d w, n;
    double d;
    if (!point_triangle_pair(bulk_x0_[k], T, r_bulk, tiny, w, d, n)) continue;
    entries_.push_back({np + k, 1.0});
    for (int q = 0; q < 3; ++q) add_vertex(vert_shell_[T[q]], local(T[q]), -w[q]);
    add_pair(n, d, bulk_gap_, dt, friction_[vert_shell_[T[0]]]);
  }
}

int ShellGuard::solve_pairs(double tol) {
  int sweeps = 0;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    sweeps = sweep + 1;
    double change = 0;
    for (Pair& p : pairs_) {
      if (!(p.denom > 0)) continue;
      const double lam = std::max(0.0, p.lambda + (p.target - rate(p)) / p.denom);
      const double dl = lam - p.lambda;
      if (dl == 0) continue;
      p.lambda = lam;
      for (std::size_t i = p.begin; i < p.end; ++i) {
        const Entry& en = entries_[i];
        v_[en.point] += (en.w * dl) * p.n.cwiseProduct(inv_mass_[en.point]);
        if (!held_v_.empty()) pin_work_ -= (en.w * dl) * p.n.dot(held_v_[en.point]);
      }
      change = std::max(change, std::abs(dl) * p.denom);
    }
    if (change <= tol) break;
  }
  return sweeps;
}

void ShellGuard::apply_friction() {
  for (const Pair& p : pairs_) {
    if (!(p.lambda > 0) || !(p.mu > 0)) continue;
    Vec3d rel = Vec3d::Zero();
    for (std::size_t i = p.begin; i < p.end; ++i) rel += entries_[i].w * v_[entries_[i].point];
    const Vec3d vt = rel - p.n.dot(rel) * p.n;
    const double s = vt.norm();
    if (!(s > 0)) continue;
    const Vec3d t = vt / s;
    double denom = 0;
    for (std::size_t i = p.begin; i < p.end; ++i) {
      const Entry& en = entries_[i];
      denom += en.w * en.w * t.dot(t.cwiseProduct(inv_mass_[en.point]));
    }
    if (!(denom > 0)) continue;
    // The impulse that stops the sliding, capped at c_F times the normal one.
    const double j = std::min(s / denom, p.mu * p.lambda);
    for (std::size_t i = p.begin; i < p.end; ++i) {
      const Entry& en = entries_[i];
      v_[en.point] -= (en.w * j) * t.cwiseProduct(inv_mass_[en.point]);
      if (!held_v_.empty()) pin_work_ += (en.w * j) * t.dot(held_v_[en.point]);
    }
  }
}

void ShellGuard::write_back(std::vector<GridShell>& shells, ParticleSet* ps, double dt) const {
  // The change of each velocity, and the position moves by dt times it.
  for (std::size_t s = 0; s < shells.size(); ++s) {
    ShellObject& sh = *shells[s].shell;
    for (std::size_t j = 0; j < sh.size(); ++j) {
      const std::size_t g = point_offset_[s] + j;
      for (int a = 0; a < 3; ++a) {
        const double dv = v_[g][a] - v_end_[g][a];
        if (dv == 0) continue;
        sh.x[j][a] += static_cast<Real>(dt * dv);
        sh.v[j][a] += static_cast<Real>(dv);
      }
    }
  }
  const std::size_t np = point_offset_.back();
  for (std::size_t k = 0; k < bulk_idx_.size(); ++k) {
    const std::size_t p = bulk_idx_[k];
    const Vec3 vn = v_[np + k].cast<Real>();
    for (int a = 0; a < 3; ++a) {
      if (vn[a] == ps->v[p][a]) continue;
      ps->x[p][a] += static_cast<Real>(dt) * (vn[a] - ps->v[p][a]);
      ps->v[p][a] = vn[a];
    }
  }
}

ShellGuardStats ShellGuard::apply(std::vector<GridShell>& shells,
                                  const std::vector<std::vector<Vec3>>& start,
                                  const GuardBulk& bulk, double dt) {
  ShellGuardStats st;
  if (meshes_.empty() || !(dt > 0)) return st;
  // Control points: start-of-step positions, and the velocity that takes them to where
  // they are now ((x - x^n) / dt: G2P's velocity, plus a collider's projection where one
  // moved the point), which the constraints act on.
  const double vmax = point_bounds(shells, start, dt);
  // Speed bounds: the limit vertices are convex combinations of the control points (Loop
  // limit weights are positive), so the largest control-point speed bounds theirs.
  ParticleSet* const ps = bulk.particles;
  const std::size_t nb = ps ? ps->size() : 0;
  double vbulk = 0;
  for (std::size_t p = 0; p < nb; ++p)
    vbulk = std::max(vbulk, static_cast<double>(ps->v[p].norm()));
  if (!std::isfinite(vmax) || !std::isfinite(vbulk)) return st;  // diverged: the solver says so
  // Relative motion bounds this step: shell against shell, bulk against shell.
  const double reach = 2.0 * vmax * dt, reach_bulk = dt * (vmax + vbulk);
  const double r = gap_ + reach, r_bulk = bulk_gap_ + reach_bulk;
  // Candidate lists, rebuilt when the motion since the last build could bring a pair
  // left out within reach (a pair left out was at least gap + margin apart then), and
  // the bulk list also when the particles were reordered or added.
  const bool shell_rebuild = !shell_list_.valid(reach, spread_);
  const bool bulk_rebuild =
      nb > 0 && (!bulk_list_.valid(reach_bulk) || bulk.epoch != built_epoch_ || nb != built_count_);
  if (nb == 0) bt_cand_.clear(), bulk_idx_.clear();
  shell_list_.moved += reach;
  bulk_list_.moved += reach_bulk;
  if (!shell_rebuild && !bulk_rebuild && vt_cand_.empty() && ee_cand_.empty() && bt_cand_.empty())
    return st;  // nothing near, and the lists still hold
  load_points(shells, start, dt);
  limit_positions();  // at x^n
  if (shell_rebuild) {
    shell_list_.start(gap_, reach);
    build_shell_candidates(gap_ + shell_list_.margin);
    x_built_ = x0_;
  }
  if (bulk_rebuild) {
    bulk_list_.start(bulk_gap_, reach_bulk);
    build_bulk_candidates(bulk_gap_ + bulk_list_.margin, bulk, dt);
    built_epoch_ = bulk.epoch;
    built_count_ = nb;
  }
  if (nb > 0) load_bulk(bulk, dt);  // the bulk candidates join the unknowns
  gather_pairs(r, r_bulk, dt);
  st.pairs = pairs_.size();
  if (pairs_.empty()) return st;

  // Projected Gauss-Seidel on the accumulated impulses (lambda >= 0).
  const double tol = 1e-4 * gap_ / dt;
  st.sweeps = solve_pairs(tol);
  if (friction_on_) {
    // Friction from the normal impulses, then the normal constraints again (friction
    // changes velocities other pairs share).
    apply_friction();
    st.sweeps += solve_pairs(tol);
  }
  for (const Pair& p : pairs_)
    if (p.lambda > 0) ++st.impulses;
  st.zoned = impact_zones(tol);
  for (const Pair& p : pairs_)
    if (p.target - rate(p) > tol) ++st.unresolved;
  if (st.impulses == 0 && st.zoned == 0) return st;
  st.pin_work = pin_work_;
  write_back(shells, ps, dt);
  return st;
}

}  // namespace shellmpm
