#include "sim/contact/shell_guard.h"

#include "sim/core/parallel.h"
#include "sim/math/box_pairs.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

namespace shellmpm {
namespace {

constexpr std::size_t kPointGrain = 4096;  ///< control points or limit vertices per chunk

Vec3d to_d(const Vec3& v) {
  return v.cast<double>();
}

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

/// Whether the boxes of the point sets a and b are farther apart than r on some axis (a
/// cheap test before an exact distance).
template <std::size_t NA, std::size_t NB>
bool boxes_apart(const std::array<const Vec3d*, NA>& a, const std::array<const Vec3d*, NB>& b,
                 double r) {
  for (int ax = 0; ax < 3; ++ax) {
    double alo = (*a[0])[ax], ahi = alo, blo = (*b[0])[ax], bhi = blo;
    for (std::size_t i = 1; i < NA; ++i) {
      alo = std::min(alo, (*a[i])[ax]);
      ahi = std::max(ahi, (*a[i])[ax]);
    }
    for (std::size_t i = 1; i < NB; ++i) {
      blo = std::min(blo, (*b[i])[ax]);
      bhi = std::max(bhi, (*b[i])[ax]);
    }
    if (blo - ahi >= r || alo - bhi >= r) return true;
  }
  return false;
}

double distance_to_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d w = closest_point_barycentric(p, a, b, c);
  return (p - (w[0] * a + w[1] * b + w[2] * c)).norm();
}

/// "Seen for item i" marks over n features, neither cleared between items nor allocated
/// per chunk: a thread's array, each mark the pass's number and the item's. Passes are
/// numbered process-wide, so no mark of an earlier pass (or another guard's) matches.
class Stamps {
 public:
  static std::uint32_t new_pass() {
    static std::atomic<std::uint32_t> next{0};
    return ++next;
  }
  Stamps(std::size_t n, std::uint32_t pass)
      : marks_(thread_marks()), pass_(static_cast<std::uint64_t>(pass) << 32) {
    if (marks_.size() < n) marks_.resize(n, 0);
  }
  /// Marks feature f for item i; false where it was marked for i already.
  bool first(int f, std::size_t i) {
    const std::uint64_t m = pass_ | static_cast<std::uint32_t>(i);
    std::uint64_t& at = marks_[static_cast<std::size_t>(f)];
    if (at == m) return false;
    at = m;
    return true;
  }

 private:
  static std::vector<std::uint64_t>& thread_marks() {
    thread_local std::vector<std::uint64_t> marks;
    return marks;
  }
  std::vector<std::uint64_t>& marks_;
  std::uint64_t pass_;
};

double distance_of_segments(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0, const Vec3d& q1) {
  const Eigen::Vector2d st = closest_segment_params(p0, p1, q0, q1);
  return ((p0 + st[0] * (p1 - p0)) - (q0 + st[1] * (q1 - q0))).norm();
}

/// Per item i < n, the features visit(i, stamp, out) appends (each item's sorted), run in
/// chunks on the threads with a Stamps over `stamps` features per chunk and joined in
/// item order: the same lists on any thread count.
template <class Visit>
void item_lists(std::size_t n, std::size_t stamps, bool serial, const Visit& visit,
                std::vector<std::size_t>& start, std::vector<int>& item) {
  struct Part {
    std::vector<int> item;
    std::vector<std::size_t> count;
  };
  const std::uint32_t pass = Stamps::new_pass();
  const auto parts =
      chunk_parts(n, 512, serial, Part(), [&](std::size_t b, std::size_t e, Part& part) {
        Stamps stamp(stamps, pass);
        for (std::size_t i = b; i < e; ++i) {
          const std::size_t at = part.item.size();
          visit(i, stamp, part.item);
          std::sort(part.item.begin() + static_cast<std::ptrdiff_t>(at), part.item.end());
          part.count.push_back(part.item.size() - at);
        }
      });
  start.assign(1, 0);
  item.clear();
  for (const Part& part : parts) {
    item.insert(item.end(), part.item.begin(), part.item.end());
    for (std::size_t c : part.count) start.push_back(start.back() + c);
  }
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

double ShellGuard::cell_size(double radius) const {
  // About one mesh edge, at least the radius: each feature is binned by its own box and
  // a query looks in the box grown by the radius.
  double edge_sum = 0;
  for (const Eigen::Vector3i& e : all_edges_) edge_sum += (pos_[e[0]] - pos_[e[1]]).norm();
  return std::max(radius, all_edges_.empty() ? radius : edge_sum / all_edges_.size());
}

void ShellGuard::build_rest_near() {
  rest_near_built_ = true;
  // All shells' rest limit vertices in one array, binned in cells of the largest near.
  std::vector<Vec3d> rest;
  double cell = 0;
  for (const Mesh& m : meshes_) {
    rest.insert(rest.end(), m.rest.begin(), m.rest.end());
    cell = std::max(cell, m.near);
  }
  if (rest.empty() || !(cell > 0)) return;
  TriangleGrid grid;
  const auto local = [&](std::size_t g) {
    return static_cast<int>(g - vertex_offset_[vert_shell_[g]]);
  };
  const auto lists = [&](std::size_t n, std::size_t stamps, NearLists& out, const auto& visit) {
    item_lists(n, stamps, serial_, visit, out.start, out.item);
  };
  // The same tests, in the same order of arguments, as the list builds' rest test used
  // to make per pair: distance_to_triangle(vertex, triangle), distance_of_segments(e, f).
  grid.build(rest, all_tris_, cell, 0.0, serial_);
  lists(rest.size(), all_tris_.size(), near_vt_,
        [&](std::size_t p, Stamps& stamp, std::vector<int>& out) {
          const int pi = static_cast<int>(p);
          const std::size_t s = vert_shell_[p];
          const Mesh& m = meshes_[s];
          const Vec3d pad = Vec3d::Constant(m.near * (1 + 1e-6));
          grid.for_each_in_box(rest[p] - pad, rest[p] + pad, [&](int t) {
            if (!stamp.first(t, p)) return;
            const Eigen::Vector3i& T = all_tris_[static_cast<std::size_t>(t)];
            if (T[0] == pi || T[1] == pi || T[2] == pi || vert_shell_[T[0]] != s) return;
            const std::vector<Vec3d>& R = m.rest;
            if (distance_to_triangle(R[local(p)], R[local(T[0])], R[local(T[1])], R[local(T[2])]) <
                m.near)
              out.push_back(t);
          });
        });
  grid.build(rest, all_edges_, cell, 0.0, serial_);
  lists(all_edges_.size(), all_edges_.size(), near_ee_,
        [&](std::size_t e, Stamps& stamp, std::vector<int>& out) {
          const Eigen::Vector3i& E = all_edges_[e];
          const int ei = static_cast<int>(e);
          const std::size_t s = vert_shell_[E[0]];
          const Mesh& m = meshes_[s];
          const Vec3d pad = Vec3d::Constant(m.near * (1 + 1e-6));
          const Vec3d &p0 = rest[E[0]], &p1 = rest[E[1]];
          grid.for_each_in_box(p0.cwiseMin(p1) - pad, p0.cwiseMax(p1) + pad, [&](int f) {
            if (f <= ei || !stamp.first(f, e)) return;
            const Eigen::Vector3i& F = all_edges_[static_cast<std::size_t>(f)];
            if (F[0] == E[0] || F[0] == E[1] || F[1] == E[0] || F[1] == E[1]) return;
            if (vert_shell_[F[0]] != s) return;
            const std::vector<Vec3d>& R = m.rest;
            if (distance_of_segments(R[local(E[0])], R[local(E[1])], R[local(F[0])],
                                     R[local(F[1])]) < m.near)
              out.push_back(f);
          });
        });
}

void ShellGuard::build_shell_candidates(double radius) {
  vt_cand_.clear();
  ee_cand_.clear();
  if (!rest_near_built_) build_rest_near();
  const double cell = cell_size(radius);
  tri_grid_.build(pos_, all_tris_, cell, 0.0, serial_);
  const Vec3d pad = Vec3d::Constant(radius);
  // Vertices: each vertex's candidates as item_lists finds them, as pairs.
  std::vector<std::size_t> start;
  std::vector<int> item;
  item_lists(
      pos_.size(), all_tris_.size(), serial_,
      [&](std::size_t p, Stamps& stamp, std::vector<int>& cand) {
        const int pi = static_cast<int>(p);
        // The triangles near p at rest are never taken: marked seen before the walk.
        for (const int* t = near_vt_.begin(p); t != near_vt_.end(p); ++t) stamp.first(*t, p);
        tri_grid_.for_each_in_box(pos_[p] - pad, pos_[p] + pad, [&](int t) {
          if (!stamp.first(t, p)) return;
          const Eigen::Vector3i& T = all_tris_[static_cast<std::size_t>(t)];
          if (T[0] == pi || T[1] == pi || T[2] == pi) return;
          if (boxes_apart<1, 3>({&pos_[p]}, {&pos_[T[0]], &pos_[T[1]], &pos_[T[2]]}, radius))
            return;
          if (!(distance_to_triangle(pos_[p], pos_[T[0]], pos_[T[1]], pos_[T[2]]) < radius)) return;
          cand.push_back(t);
        });
      },
      start, item);
  vt_cand_.reserve(item.size());
  for (std::size_t i = 0; i + 1 < start.size(); ++i)
    for (std::size_t k = start[i]; k < start[i + 1]; ++k)
      vt_cand_.emplace_back(static_cast<int>(i), item[k]);
  // (Cells twice the vertex walk's: fewer listings per edge against more pairs per cell,
  // the fastest of 1, 1.5, 2 and 3 times in bench/contact_throughput.)
  build_edge_candidates(radius, 2 * cell);
}

void ShellGuard::build_edge_candidates(double radius, double cell) {
  // The pairs of edges whose boxes come within the radius (boxes_apart<2, 2>, the same
  // operations: the boxes are its), cell by cell (BoxPairs); then the tests of a walk.
  const std::size_t ne = all_edges_.size();
  edge_box_.resize(ne);
  parallel_for_each(
      ne, kPointGrain,
      [&](std::size_t e) {
        const Vec3d &p0 = pos_[all_edges_[e][0]], &p1 = pos_[all_edges_[e][1]];
        edge_box_[e] = {std::min(p0[0], p1[0]), std::min(p0[1], p1[1]), std::min(p0[2], p1[2]),
                        std::max(p0[0], p1[0]), std::max(p0[1], p1[1]), std::max(p0[2], p1[2])};
      },
      serial_);
  ee_cand_ = edge_pairs_.find(edge_box_, radius, cell, serial_, [&](int ei, int f) {
    const Eigen::Vector3i& E = all_edges_[static_cast<std::size_t>(ei)];
    const Eigen::Vector3i& F = all_edges_[static_cast<std::size_t>(f)];
    if (F[0] == E[0] || F[0] == E[1] || F[1] == E[0] || F[1] == E[1]) return false;
    const auto e = static_cast<std::size_t>(ei);
    if (std::binary_search(near_ee_.begin(e), near_ee_.end(e), f)) return false;  // near at rest
    return distance_of_segments(pos_[E[0]], pos_[E[1]], pos_[F[0]], pos_[F[1]]) < radius;
  });
}

void ShellGuard::build_bulk_candidates(double radius, const GuardBulk& bulk, double dt) {
  bt_cand_.clear();
  bulk_idx_.clear();
  // Bulk particles (at x^n) near a triangle; only those inside the shells' padded box
  // are looked up.
  const ParticleSet* ps = bulk.particles;
  if (!ps || ps->size() == 0 || pos_.empty()) return;
  bulk_grid_.build(pos_, all_tris_, cell_size(radius), 0.0, serial_);
  const Vec3d pad = Vec3d::Constant(radius);
  Vec3d lo = pos_[0], hi = pos_[0];
  for (const Vec3d& q : pos_) {
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  lo.array() -= radius;
  hi.array() += radius;
  // Chunks of particles on the threads, each with its own (particle, triangle) pairs,
  // joined in order.
  const std::size_t grain = 4096, n = ps->size();
  using Pairs = std::vector<std::pair<std::uint32_t, int>>;
  const std::uint32_t pass = Stamps::new_pass();
  const std::vector<Pairs> parts =
      chunk_parts(n, grain, serial_, Pairs(), [&](std::size_t b, std::size_t e, Pairs& out) {
        Stamps stamp(all_tris_.size(), pass);
        std::vector<int> cand;
        for (std::size_t p = b; p < e; ++p) {
          const Vec3d x = to_d(ps->x[p]) - dt * to_d(ps->v[p]);
          if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
          cand.clear();
          bulk_grid_.for_each_in_box(x - pad, x + pad, [&](int t) {
            if (!stamp.first(t, p)) return;
            const Eigen::Vector3i& T = all_tris_[static_cast<std::size_t>(t)];
            if (boxes_apart<1, 3>({&x}, {&pos_[T[0]], &pos_[T[1]], &pos_[T[2]]}, radius)) return;
            if (distance_to_triangle(x, pos_[T[0]], pos_[T[1]], pos_[T[2]]) < radius)
              cand.push_back(t);
          });
          std::sort(cand.begin(), cand.end());
          for (int t : cand) out.emplace_back(static_cast<std::uint32_t>(p), t);
        }
      });
  for (const auto& part : parts)
    for (const auto& [p, t] : part) {
      if (bulk_idx_.empty() || bulk_idx_.back() != p) bulk_idx_.push_back(p);
      bt_cand_.emplace_back(static_cast<int>(bulk_idx_.size() - 1), t);
    }
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
        if (held[r][a] >= 0)
          v_[i][a] = v_[static_cast<std::size_t>(held[r][a])][a];
        else if (mass[r][a] > 0)
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
          for (int a = 0; a < 3; ++a) inv_mass_[g][a] = (held & (1u << a)) ? 0.0 : im;
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
  write_back(shells, ps, dt);
  return st;
}

}  // namespace shellmpm
