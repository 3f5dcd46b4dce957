// The shell guard's candidate lists (see shell_guard.h): the feature pairs that could come
// within the gap plus the motion's margin before the lists are rebuilt: vertex-triangle
// and edge-edge pairs of the shells (those near at rest left out), and bulk particles
// against triangles, each found through a grid of boxes and listed in item order.
#include "sim/contact/shell_guard.h"

#include "sim/contact/shell_guard_util.h"
#include "sim/core/parallel.h"
#include "sim/math/box_pairs.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

namespace shellmpm {
using guard_util::boxes_apart;
using guard_util::kPointGrain;
using guard_util::to_d;

namespace {

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

}  // namespace shellmpm
