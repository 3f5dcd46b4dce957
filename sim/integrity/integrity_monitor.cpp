#include "sim/integrity/integrity_monitor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

constexpr std::size_t kGrain = 2048;
constexpr double kRimCells = 2.0;    ///< points this close to a boundary (rest) are not judged
constexpr double kDeadCells = 1e-3;  ///< points this close to the surface have no side
constexpr double kColliderCells = 0.5;
constexpr double kStretchedCells = 2.0;  ///< contact-shell edges longer than this warn

// Per-chunk tallies, combined in chunk order (deterministic).
struct Tally {
  std::vector<std::size_t> count;
  std::vector<Vec3d> where;
  std::vector<int> from;
  explicit Tally(std::size_t k = 0) : count(k, 0), where(k, Vec3d::Zero()), from(k, -1) {}
  void add(int s, const Vec3d& x, int src) {
    if (count[s]++ == 0) {
      where[s] = x;
      from[s] = src;
    }
  }
};

/// Adds a chunk's tally t to the totals (the first place seen is kept).
void merge(const Tally& t, std::vector<std::size_t>& count, std::vector<Vec3d>& where,
           std::vector<int>* from) {
  for (std::size_t s = 0; s < count.size(); ++s) {
    if (t.count[s] == 0) continue;
    if (count[s] == 0) {
      where[s] = t.where[s];
      if (from) (*from)[s] = t.from[s];
    }
    count[s] += t.count[s];
  }
}

}  // namespace

void IntegrityMonitor::setup(const IntegrityView& view, double dx) {
  dx_ = dx;
  band_ = 2.0 * dx;
  shells_.clear();
  names_.clear();
  vertex_offset_.assign(1, 0);
  for (const ShellObject* sh : view.shells) {
    ShellGeom g;
    g.limit = std::make_unique<LimitMesh>(sh->basis(), sh->triangles(),
                                          std::vector<Eigen::Vector2d>{}, 0);
    const auto& T = g.limit->triangles();
    std::map<std::pair<int, int>, int> uses;
    for (const Eigen::Vector3i& t : T)
      for (int e = 0; e < 3; ++e) {
        const int a = std::min(t[e], t[(e + 1) % 3]), b = std::max(t[e], t[(e + 1) % 3]);
        ++uses[{a, b}];
      }
    std::vector<Vec3> rest_x(sh->rest.size());
    for (std::size_t i = 0; i < rest_x.size(); ++i) rest_x[i] = sh->rest[i].cast<Real>();
    std::vector<Vec3> rp, rn;
    g.limit->evaluate(rest_x.data(), rp, rn);
    std::vector<int> boundary;
    for (const auto& [e, n] : uses) {
      g.edges.push_back(e);
      if (n == 1) {
        boundary.push_back(e.first);
        boundary.push_back(e.second);
      }
    }
    std::sort(boundary.begin(), boundary.end());
    boundary.erase(std::unique(boundary.begin(), boundary.end()), boundary.end());
    g.rim.assign(rp.size(), std::numeric_limits<double>::infinity());
    for (std::size_t v = 0; v < rp.size(); ++v)
      for (int b : boundary) g.rim[v] = std::min(g.rim[v], (rp[v] - rp[b]).cast<double>().norm());
    vertex_offset_.push_back(vertex_offset_.back() + rp.size());
    shells_.push_back(std::move(g));
    names_.push_back(sh->name());
  }
  const bool colliders = view.colliders && !view.colliders->empty();
  active_ = !shells_.empty() || colliders;
  bulk_cross_.assign(shells_.size(), 0);
  point_cross_.assign(shells_.size(), 0);
}

void IntegrityMonitor::refresh(const IntegrityView& view) {
  std::vector<Vec3> p, n;
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    ShellGeom& g = shells_[s];
    g.limit->evaluate(view.shells[s]->x.data(), p, n);
    g.pos.resize(p.size());
    g.nrm.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      g.pos[i] = p[i].cast<double>();
      g.nrm[i] = n[i].cast<double>();
    }
    g.grid.build(g.pos, g.limit->triangles(), 2.0 * band_, band_, view.serial);
  }
}

Vec3d IntegrityMonitor::point(const IntegrityView& view, std::size_t i, std::size_t& s) const {
  const std::size_t nv = vertex_offset_.back();
  if (i >= nv) return view.bulk->x[i - nv].cast<double>();
  while (vertex_offset_[s + 1] <= i) ++s;
  return shells_[s].pos[i - vertex_offset_[s]];
}

IntegrityMonitor::Hit IntegrityMonitor::side_of(const Vec3d& x, int exclude) const {
  thread_local std::vector<int> cand;
  Hit best;
  double best_d2 = band_ * band_;
  Vec3d best_c = Vec3d::Zero(), best_b = Vec3d::Zero();
  int best_t = -1;
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    if (static_cast<int>(s) == exclude) continue;
    const ShellGeom& g = shells_[s];
    g.grid.query(x, cand);
    const auto& T = g.limit->triangles();
    for (int t : cand) {
      const Vec3d& a = g.pos[T[t][0]];
      const Vec3d& b = g.pos[T[t][1]];
      const Vec3d& c = g.pos[T[t][2]];
      const Vec3d bc = closest_point_barycentric(x, a, b, c);
      const Vec3d cp = bc[0] * a + bc[1] * b + bc[2] * c;
      const double d2 = (x - cp).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best.shell = static_cast<int>(s);
        best_c = cp;
        best_b = bc;
        best_t = t;
      }
    }
  }
  if (best.shell < 0) return best;  // Far
  const ShellGeom& g = shells_[best.shell];
  const Eigen::Vector3i& tri = g.limit->triangles()[best_t];
  const double rim =
      best_b[0] * g.rim[tri[0]] + best_b[1] * g.rim[tri[1]] + best_b[2] * g.rim[tri[2]];
  if (rim < kRimCells * dx_) {
    best.side = Side::Rim;
    return best;
  }
  Vec3d n = best_b[0] * g.nrm[tri[0]] + best_b[1] * g.nrm[tri[1]] + best_b[2] * g.nrm[tri[2]];
  const double sd = (x - best_c).dot(n.normalized());
  best.side = std::abs(sd) < kDeadCells * dx_ ? Side::Dead : sd > 0 ? Side::Plus : Side::Minus;
  return best;
}

bool IntegrityMonitor::compare(const IntegrityView& view, bool record_only) {
  if (shells_.empty()) return false;  // nothing to cross: no side records (no memory per particle)
  const std::size_t nb = view.bulk ? view.bulk->size() : 0;
  if (shells_.size() == 1 && nb == 0) {
    // One shell and no particles: no point can be on a side of another shell (a shell's
    // own vertices are not judged against it), so the check is done without the limit
    // surface (its evaluation and triangle grid were 18% of a cloth's step).
    ++checks_;
    return false;
  }
  refresh(view);
  const std::size_t nv = vertex_offset_.back();
  const std::size_t n = nv + nb;
  if (record_only) {
    rec_shell_.assign(n, -1);
    rec_side_.assign(n, 0);
  } else {
    rec_shell_.resize(n, -1);  // particles emitted since the last check
    rec_side_.resize(n, 0);
  }
  ++checks_;
  const std::size_t K = shells_.size();
  // Per chunk: bulk particles, then shell points, that crossed a shell.
  const std::vector<std::array<Tally, 2>> parts =
      chunk_parts(n, kGrain, view.serial, std::array<Tally, 2>{Tally(K), Tally(K)},
                  [&](std::size_t b, std::size_t e, std::array<Tally, 2>& tally) {
                    Tally& tb = tally[0];
                    Tally& tp = tally[1];
                    std::size_t s = 0;
                    for (std::size_t i = b; i < e; ++i) {
                      const Vec3d x = point(view, i, s);
                      const int own = i < nv ? static_cast<int>(s) : -1;
                      const Hit h = side_of(x, own);
                      if (h.side == Side::Far || h.side == Side::Rim) {
                        rec_shell_[i] = -1;
                        continue;
                      }
                      if (h.side == Side::Dead) continue;
                      const auto side = static_cast<std::int8_t>(h.side);
                      if (!record_only && rec_shell_[i] == h.shell && rec_side_[i] == -side) {
                        if (own < 0)
                          tb.add(h.shell, x, -1);
                        else
                          tp.add(h.shell, x, own);
                      }
                      rec_shell_[i] = static_cast<std::int16_t>(h.shell);
                      rec_side_[i] = side;
                    }
                  });
  for (const std::array<Tally, 2>& t : parts) {
    merge(t[0], bulk_cross_, bulk_where_, nullptr);
    merge(t[1], point_cross_, point_where_, &point_from_);
  }
  return true;
}

void IntegrityMonitor::begin_frame(const IntegrityView& view) {
  const std::size_t K = shells_.size();
  bulk_cross_.assign(K, 0);
  point_cross_.assign(K, 0);
  bulk_where_.assign(K, Vec3d::Zero());
  point_where_.assign(K, Vec3d::Zero());
  point_from_.assign(K, -1);
  checks_ = 0;
  if (!active_) return;
  compare(view, true);
  checks_ = 0;
}

void IntegrityMonitor::track(const IntegrityView& view) {
  if (active_) compare(view, false);
}

IntegrityReport IntegrityMonitor::end_frame(const IntegrityView& view) {
  IntegrityReport r;
  if (!active_) return r;
  if (!compare(view, false)) refresh(view);  // the frame-end checks need the limit surface
  r.checks = checks_;
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    if (bulk_cross_[s]) {
      IntegrityEvent e;
      e.kind = IntegrityEvent::Kind::BulkThroughShell;
      e.object = names_[s];
      e.count = bulk_cross_[s];
      e.where = bulk_where_[s];
      r.events.push_back(e);
      r.bulk_crossings += bulk_cross_[s];
    }
    if (point_cross_[s]) {
      IntegrityEvent e;
      e.kind = IntegrityEvent::Kind::ShellThroughShell;
      e.object = names_[s];
      e.other = point_from_[s] >= 0 ? names_[point_from_[s]] : "";
      e.count = point_cross_[s];
      e.where = point_where_[s];
      r.events.push_back(e);
      r.shell_point_crossings += point_cross_[s];
    }
  }
  frame_end_checks(view, r);
  return r;
}

IntegrityReport IntegrityMonitor::snapshot(const IntegrityView& view) {
  IntegrityReport r;
  if (!active_) return r;
  refresh(view);
  frame_end_checks(view, r);
  return r;
}

void IntegrityMonitor::frame_end_checks(const IntegrityView& view, IntegrityReport& r) const {
  r.active = true;
  r.dx = dx_;
  r.collider_limit = kColliderCells * dx_;
  measure_gaps(view, r);
  check_non_finite(view, r);
  check_crossings(view, r);
  std::vector<IntegrityEvent> warnings;
  check_stretched(r, warnings);
  if (view.colliders)
    for (const Collider& c : *view.colliders) check_collider(view, c, r);
  r.events.insert(r.events.end(), warnings.begin(), warnings.end());
}

std::pair<double, int> IntegrityMonitor::nearest_shell(const Vec3d& x, int exclude) const {
  thread_local std::vector<int> cand;
  double best = band_ * band_;
  int shell = -1;
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    if (static_cast<int>(s) == exclude) continue;
    const ShellGeom& g = shells_[s];
    g.grid.query(x, cand);
    const auto& T = g.limit->triangles();
    for (int t : cand) {
      const Vec3d& a = g.pos[T[t][0]];
      const Vec3d& b = g.pos[T[t][1]];
      const Vec3d& c = g.pos[T[t][2]];
      const Vec3d bc = closest_point_barycentric(x, a, b, c);
      const double d2 = (x - (bc[0] * a + bc[1] * b + bc[2] * c)).squaredNorm();
      if (d2 < best) {
        best = d2;
        shell = static_cast<int>(s);
      }
    }
  }
  return {std::sqrt(best), shell};
}

namespace {
/// Least and median of a list of gaps (the median of an even count is the lower middle).
GapSummary summarise(std::vector<double>& g) {
  GapSummary out;
  out.count = g.size();
  if (g.empty()) return out;
  out.min = *std::min_element(g.begin(), g.end());
  auto mid = g.begin() + static_cast<std::ptrdiff_t>((g.size() - 1) / 2);
  std::nth_element(g.begin(), mid, g.end());
  out.median = *mid;
  return out;
}
}  // namespace

/// Gaps between contact surfaces: every shell limit vertex against its nearest other
/// surface (another shell, a bulk particle's volume, a collider) within the band.
void IntegrityMonitor::measure_gaps(const IntegrityView& view, IntegrityReport& r) const {
  const std::size_t nv = vertex_offset_.back();
  if (nv == 0) return;  // no shell: nothing to measure
  const std::size_t nb = view.bulk ? view.bulk->size() : 0;
  const auto half = [&view](std::size_t s) {
    return s < view.half_thickness.size() ? view.half_thickness[s] : 0.0;
  };
  // Bulk particles by cell of the band's size (sorted keys: a deterministic lookup).
  const double cell = band_;
  const auto key_of = [cell](const Vec3d& x) {
    const auto c = [cell](double v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v / cell)) +
                                        (1 << 20)) &
             0x1fffff;
    };
    return c(x.x()) << 42 | c(x.y()) << 21 | c(x.z());
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;
  cells.reserve(nb);
  for (std::size_t p = 0; p < nb; ++p)
    if (view.bulk->x[p].allFinite())
      cells.push_back({key_of(view.bulk->x[p].cast<double>()), static_cast<std::uint32_t>(p)});
  std::sort(cells.begin(), cells.end());
  // The nearest bulk particle's surface: distance less half its spacing.
  const auto nearest_bulk = [&](const Vec3d& x) {
    double best = std::numeric_limits<double>::infinity();
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          const std::uint64_t key = key_of(x + cell * Vec3d(i, j, k));
          auto it =
              std::lower_bound(cells.begin(), cells.end(), std::make_pair(key, std::uint32_t(0)));
          for (; it != cells.end() && it->first == key; ++it) {
            const std::size_t p = it->second;
            const double d = (view.bulk->x[p].cast<double>() - x).norm() -
                             0.5 * std::cbrt(double(view.bulk->volume_of(p)));
            best = std::min(best, d);
          }
        }
    return best;
  };
  struct Lists {
    std::vector<double> ss, sb, sc;
  };
  const std::vector<Lists> parts =
      chunk_parts(nv, kGrain, view.serial, Lists(), [&](std::size_t b, std::size_t e, Lists& l) {
        std::size_t s = 0;
        for (std::size_t i = b; i < e; ++i) {
          const Vec3d x = point(view, i, s);
          if (!x.allFinite()) continue;
          const double own = half(s);
          const auto [d, other] = nearest_shell(x, static_cast<int>(s));
          const double g_shell = other >= 0 ? d - own - half(std::size_t(other))
                                            : std::numeric_limits<double>::infinity();
          const double g_bulk =
              nb ? nearest_bulk(x) - own : std::numeric_limits<double>::infinity();
          double g_coll = std::numeric_limits<double>::infinity();
          if (view.colliders)
            for (const Collider& c : *view.colliders) {
              Aabb at;
              at.lo = x.array() - band_;
              at.hi = x.array() + band_;
              if (c.bounds().overlaps(at)) g_coll = std::min(g_coll, c.phi(x) - own);
            }
          const double g = std::min({g_shell, g_bulk, g_coll});
          if (!(g < band_)) continue;
          (g == g_shell ? l.ss : g == g_bulk ? l.sb : l.sc).push_back(g);
        }
      });
  Lists all;
  for (const Lists& l : parts) {
    all.ss.insert(all.ss.end(), l.ss.begin(), l.ss.end());
    all.sb.insert(all.sb.end(), l.sb.begin(), l.sb.end());
    all.sc.insert(all.sc.end(), l.sc.begin(), l.sc.end());
  }
  r.shell_shell = summarise(all.ss);
  r.shell_bulk = summarise(all.sb);
  r.shell_collider = summarise(all.sc);
}

/// Non-finite positions or velocities of bulk particles and control points.
void IntegrityMonitor::check_non_finite(const IntegrityView& view, IntegrityReport& r) const {
  const std::size_t nb = view.bulk ? view.bulk->size() : 0;
  std::size_t bad = 0;
  for (std::size_t p = 0; p < nb; ++p)
    bad += !(view.bulk->x[p].allFinite() && view.bulk->v[p].allFinite());
  if (bad) {
    IntegrityEvent e;
    e.kind = IntegrityEvent::Kind::NonFinite;
    e.object = "bulk particles";
    e.count = bad;
    r.events.push_back(e);
    r.non_finite += bad;
  }
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    const ShellObject& sh = *view.shells[s];
    std::size_t b = 0;
    for (std::size_t j = 0; j < sh.size(); ++j) b += !(sh.x[j].allFinite() && sh.v[j].allFinite());
    if (!b) continue;
    IntegrityEvent e;
    e.kind = IntegrityEvent::Kind::NonFinite;
    e.object = names_[s];
    e.count = b;
    r.events.push_back(e);
    r.non_finite += b;
  }
}

/// Edges through triangles: every ordered pair of shells, self included.
void IntegrityMonitor::check_crossings(const IntegrityView& view, IntegrityReport& r) const {
  const std::size_t K = shells_.size();
  for (std::size_t a = 0; a < K; ++a)
    for (std::size_t b = a; b < K; ++b) {
      std::size_t count = 0;
      Vec3d where = Vec3d::Zero();
      for (int dir = 0; dir < (a == b ? 1 : 2); ++dir) {
        const ShellGeom& ea = shells_[dir ? b : a];
        const ShellGeom& tb = shells_[dir ? a : b];
        const bool self = a == b;
        const auto& T = tb.limit->triangles();
        const std::size_t ne = ea.edges.size();
        const std::vector<Tally> parts = chunk_parts(
            ne, kGrain, view.serial, Tally(1), [&](std::size_t eb, std::size_t ee, Tally& tl) {
              std::vector<int> cand;
              for (std::size_t i = eb; i < ee; ++i) {
                const auto [u, v] = ea.edges[i];
                const Vec3d& p = ea.pos[u];
                const Vec3d& q = ea.pos[v];
                tb.grid.query_box(p.cwiseMin(q), p.cwiseMax(q), cand);
                for (int t : cand) {
                  const Eigen::Vector3i& tri = T[t];
                  if (self && (tri[0] == u || tri[1] == u || tri[2] == u || tri[0] == v ||
                               tri[1] == v || tri[2] == v))
                    continue;
                  if (segment_crosses_triangle(p, q, tb.pos[tri[0]], tb.pos[tri[1]],
                                               tb.pos[tri[2]])) {
                    tl.add(0, 0.5 * (p + q), -1);
                    break;
                  }
                }
              }
            });
        for (const Tally& t : parts) {
          if (t.count[0] && count == 0) where = t.where[0];
          count += t.count[0];
        }
      }
      if (!count) continue;
      IntegrityEvent e;
      e.kind = a == b ? IntegrityEvent::Kind::SelfIntersect : IntegrityEvent::Kind::ShellsIntersect;
      e.object = names_[a];
      e.other = a == b ? "" : names_[b];
      e.count = count;
      e.where = where;
      r.events.push_back(e);
      (a == b ? r.self_crossing_edges : r.shell_crossing_edges) += count;
    }
}

/// Stretched meshes: a contact shell whose edges grew past 2 dx leaves gaps between its
/// control points' kernels, through which contact can leak (a warning, not a failure).
void IntegrityMonitor::check_stretched(IntegrityReport& r,
                                       std::vector<IntegrityEvent>& warnings) const {
  const std::size_t K = shells_.size();
  for (std::size_t s = 0; s < K; ++s) {
    const ShellGeom& g = shells_[s];
    std::size_t longer = 0;
    double longest = 0;
    Vec3d where = Vec3d::Zero();
    for (const auto& [u, v] : g.edges) {
      const double l = (g.pos[u] - g.pos[v]).norm();
      if (l > kStretchedCells * dx_) ++longer;
      if (l > longest) {
        longest = l;
        where = 0.5 * (g.pos[u] + g.pos[v]);
      }
    }
    r.max_edge = std::max(r.max_edge, longest);
    if (!longer) continue;
    IntegrityEvent e;
    e.kind = IntegrityEvent::Kind::StretchedMesh;
    e.object = names_[s];
    e.count = longer;
    e.value = longest;
    e.where = where;
    warnings.push_back(e);
    r.stretched_edges += longer;
  }
}

/// Bulk particles and shell limit vertices deeper in collider `c` than the limit.
void IntegrityMonitor::check_collider(const IntegrityView& view, const Collider& c,
                                      IntegrityReport& r) const {
  const std::size_t nb = view.bulk ? view.bulk->size() : 0;
  struct Deep {
    std::size_t count = 0;
    double depth = 0;
    Vec3d where = Vec3d::Zero();
  };
  const std::size_t nv = vertex_offset_.back();
  const std::size_t n = nv + nb;
  const std::vector<Deep> parts =
      chunk_parts(n, kGrain, view.serial, Deep(), [&](std::size_t b, std::size_t e, Deep& d) {
        std::size_t s = 0;
        for (std::size_t i = b; i < e; ++i) {
          const Vec3d x = point(view, i, s);
          Aabb at;
          at.lo = at.hi = x;
          if (!x.allFinite() || !c.bounds().overlaps(at)) continue;
          const double depth = -c.phi(x);
          if (depth > d.depth) {
            d.depth = depth;
            d.where = x;
          }
          if (depth > r.collider_limit) ++d.count;
        }
      });
  Deep total;
  for (const Deep& d : parts) {
    total.count += d.count;
    if (d.depth > total.depth) {
      total.depth = d.depth;
      total.where = d.where;
    }
  }
  r.max_collider_depth = std::max(r.max_collider_depth, total.depth);
  if (!total.count) return;
  IntegrityEvent e;
  e.kind = IntegrityEvent::Kind::InsideCollider;
  e.object = c.desc().name;
  e.count = total.count;
  e.value = total.depth;
  e.where = total.where;
  r.events.push_back(e);
  r.collider_penetrations += total.count;
}

}  // namespace shellmpm
