// Independent judges of a run's written caches (issue 10's stress suite): they use only
// the meshes and particle caches on disk and the scene's analytic collider shapes, never
// the tool's integrity monitor (sim/integrity), so a test built on them can catch the
// monitor being wrong.
//
// - Shells crossing: brute force, every edge of a mesh against every triangle of another
//   mesh (or of the same mesh, skipping triangles that share a vertex with the edge).
// - Points through a shell: for each point (bulk particle by id, or a vertex of another
//   shell), in each of two consecutive frames, the closest point on the mesh (brute force
//   over all triangles) and the sign of the offset along the normal of the closest feature
//   (the face normal, or the pseudo-normal of an edge or a vertex: Baerentzen & Aanaes
//   2005, so the sign is right at creases too). A point whose sign flips between the frames
//   crossed the shell. Not judged: points farther than `band` from the mesh, points whose
//   closest point lies within `rim` (rest distance) of the mesh boundary (they may have
//   gone round the edge), points within `dead` of the surface (no side), and pairs of
//   frames whose closest points are more than `locality` apart in the rest mesh (the point
//   came close to another fold of the shell rather than passing through one place).
// - Colliders: signed distance of the analytic shape (plane, box, sphere, cylinder) at
//   the pose of that frame's time (keyframes: translation linear, rotation slerped, held
//   outside the keys).
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "tests/support/ply_cache.h"

namespace shellmpm_test {

using V3 = Eigen::Vector3d;

// ------------------------------------------------------------------ segment x triangle

enum class Crossing { None, Clear, Borderline };

namespace detail {
inline double orient(const V3& a, const V3& b, const V3& c, const V3& d) {
  return (b - a).cross(c - a).dot(d - a);
}
}  // namespace detail

/// Whether the segment pq passes through the triangle abc. `Clear`: it does, with the
/// crossing at least `eps` (relative: of the segment parameter and of each barycentric
/// coordinate) inside both; `Borderline`: within eps of touching (an endpoint on the
/// plane, the crossing on an edge; round-off in float caches decides those). A segment in
/// the triangle's plane (within 1e-9 of its length) does not cross it.
inline Crossing segment_triangle(const V3& p, const V3& q, const V3& a, const V3& b, const V3& c,
                                 double eps = 1e-5) {
  const double dp = detail::orient(a, b, c, p), dq = detail::orient(a, b, c, q);
  // Parallel to the plane, or in it up to round-off (a rotated flat sheet is not exactly
  // flat): no crossing. |dp| / |n| is p's distance to the plane.
  const double n = (b - a).cross(c - a).norm();
  if (dp == dq || std::max(std::abs(dp), std::abs(dq)) <= 1e-9 * n * (q - p).norm())
    return Crossing::None;
  const double t = dp / (dp - dq);  // where the line meets the plane
  if (t < -eps || t > 1 + eps) return Crossing::None;
  const double s1 = detail::orient(p, q, a, b), s2 = detail::orient(p, q, b, c),
               s3 = detail::orient(p, q, c, a);
  const double sum = s1 + s2 + s3;
  if (sum == 0) return Crossing::None;
  const double la = s2 / sum, lb = s3 / sum, lc = s1 / sum;  // barycentric coordinates
  const double lmin = std::min({la, lb, lc});
  if (lmin < -eps) return Crossing::None;
  if (t > eps && t < 1 - eps && lmin > eps) return Crossing::Clear;
  return Crossing::Borderline;
}

// ------------------------------------------------------------------ edge crossings

struct EdgeCrossings {
  std::size_t clear = 0;       ///< edges with a clear crossing
  std::size_t borderline = 0;  ///< edges with only borderline ones
  V3 where{0, 0, 0};           ///< midpoint of the first crossing edge
  std::size_t any() const { return clear + borderline; }
};

/// The unique edges of a triangle list, as (low, high) vertex pairs, with use counts.
inline std::map<std::pair<int, int>, int> edge_uses(const std::vector<Eigen::Vector3i>& tri) {
  std::map<std::pair<int, int>, int> uses;
  for (const Eigen::Vector3i& t : tri)
    for (int e = 0; e < 3; ++e) {
      const int a = std::min(t[e], t[(e + 1) % 3]), b = std::max(t[e], t[(e + 1) % 3]);
      ++uses[{a, b}];
    }
  return uses;
}

namespace detail {
struct Box {
  V3 lo, hi;
  bool overlaps(const Box& o) const {
    return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
  }
};
inline std::vector<Box> triangle_boxes(const TriMesh& m, double pad) {
  std::vector<Box> boxes(m.tri.size());
  for (std::size_t t = 0; t < m.tri.size(); ++t) {
    const V3& a = m.x[m.tri[t][0]];
    const V3& b = m.x[m.tri[t][1]];
    const V3& c = m.x[m.tri[t][2]];
    boxes[t].lo = a.cwiseMin(b).cwiseMin(c).array() - pad;
    boxes[t].hi = a.cwiseMax(b).cwiseMax(c).array() + pad;
  }
  return boxes;
}

/// Edges of `em` through triangles of `tm`; `self`: the same mesh, skipping triangles
/// that share a vertex with the edge.
inline void edges_through(const TriMesh& em, const TriMesh& tm, bool self, EdgeCrossings& out) {
  const std::vector<Box> boxes = triangle_boxes(tm, 1e-9);
  for (const auto& [e, n] : edge_uses(em.tri)) {
    (void)n;
    const V3& p = em.x[e.first];
    const V3& q = em.x[e.second];
    const Box eb{p.cwiseMin(q), p.cwiseMax(q)};
    Crossing worst = Crossing::None;
    for (std::size_t t = 0; t < tm.tri.size() && worst != Crossing::Clear; ++t) {
      const Eigen::Vector3i& tr = tm.tri[t];
      if (self && (tr[0] == e.first || tr[1] == e.first || tr[2] == e.first || tr[0] == e.second ||
                   tr[1] == e.second || tr[2] == e.second))
        continue;
      if (!eb.overlaps(boxes[t])) continue;
      const Crossing c = segment_triangle(p, q, tm.x[tr[0]], tm.x[tr[1]], tm.x[tr[2]]);
      if (c == Crossing::Clear || (c == Crossing::Borderline && worst == Crossing::None)) worst = c;
    }
    if (worst == Crossing::None) continue;
    if (out.any() == 0) out.where = 0.5 * (p + q);
    (worst == Crossing::Clear ? out.clear : out.borderline) += 1;
  }
}
}  // namespace detail

/// Edges of a mesh that pass through its own triangles (those sharing a vertex with the
/// edge excepted).
inline EdgeCrossings self_crossings(const TriMesh& m) {
  EdgeCrossings out;
  detail::edges_through(m, m, true, out);
  return out;
}

/// Edges of `a` through triangles of `b`, plus edges of `b` through triangles of `a`.
inline EdgeCrossings pair_crossings(const TriMesh& a, const TriMesh& b) {
  EdgeCrossings out;
  detail::edges_through(a, b, false, out);
  detail::edges_through(b, a, false, out);
  return out;
}

// ------------------------------------------------------------------ closest point, sides

/// Closest point on triangle abc to x (Ericson, Real-Time Collision Detection, 5.1.5):
/// barycentric coordinates, exactly zero on the feature's other corners (a vertex region
/// has two zeros, an edge region one).
inline V3 closest_barycentric(const V3& x, const V3& a, const V3& b, const V3& c) {
  const V3 ab = b - a, ac = c - a, ax = x - a;
  const double d1 = ab.dot(ax), d2 = ac.dot(ax);
  if (d1 <= 0 && d2 <= 0) return V3(1, 0, 0);
  const V3 bx = x - b;
  const double d3 = ab.dot(bx), d4 = ac.dot(bx);
  if (d3 >= 0 && d4 <= d3) return V3(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return V3(1 - v, v, 0);
  }
  const V3 cx = x - c;
  const double d5 = ab.dot(cx), d6 = ac.dot(cx);
  if (d6 >= 0 && d5 <= d6) return V3(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return V3(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return V3(0, 1 - w, w);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return V3(1 - v - w, v, w);
}

/// Where a point is relative to one shell's surface in one frame.
struct SideSample {
  enum class State { Far, Rim, Dead, Side } state = State::Far;
  int sign = 0;         ///< +1 on the normal's side, -1 behind (State::Side only)
  double distance = 0;  ///< to the closest point [m]
  V3 rest{0, 0, 0};     ///< the closest point, mapped to the rest mesh [m]
};

/// A shell's surface: its rest mesh (frame 1) for the boundary and for locality, and the
/// current frame's positions for the sides.
class ShellSurface {
 public:
  /// rest: the mesh at frame 1; band, rim, dead [m] as in the file comment.
  ShellSurface(const TriMesh& rest, double band, double rim, double dead)
      : rest_(rest), band_(band), rim_(rim), dead_(dead) {
    for (const auto& [e, n] : edge_uses(rest.tri))
      if (n == 1) boundary_.push_back(e);
    set_frame(rest);
  }

  /// Positions of a frame (same vertices and triangles as the rest mesh).
  void set_frame(const TriMesh& m) {
    cur_ = m;
    const std::size_t nt = m.tri.size();
    face_n_.assign(nt, V3::Zero());
    vert_n_.assign(m.x.size(), V3::Zero());
    edge_n_.clear();
    for (std::size_t t = 0; t < nt; ++t) {
      const Eigen::Vector3i& tr = m.tri[t];
      V3 n = (m.x[tr[1]] - m.x[tr[0]]).cross(m.x[tr[2]] - m.x[tr[0]]);
      const double len = n.norm();
      face_n_[t] = len > 0 ? V3(n / len) : V3::Zero();
      for (int k = 0; k < 3; ++k) {
        // Angle-weighted vertex pseudo-normal; edge pseudo-normal: sum of the faces'.
        const V3 e1 = m.x[tr[(k + 1) % 3]] - m.x[tr[k]], e2 = m.x[tr[(k + 2) % 3]] - m.x[tr[k]];
        const double c = e1.dot(e2) / std::max(e1.norm() * e2.norm(), 1e-300);
        vert_n_[tr[k]] += std::acos(std::clamp(c, -1.0, 1.0)) * face_n_[t];
        const int a = std::min(tr[k], tr[(k + 1) % 3]), b = std::max(tr[k], tr[(k + 1) % 3]);
        const auto [it, fresh] = edge_n_.try_emplace({a, b}, V3::Zero());  // Eigen does not zero
        (void)fresh;
        it->second += face_n_[t];
      }
    }
    boxes_ = detail::triangle_boxes(m, band_);
  }

  /// The side of x in the current frame.
  SideSample sample(const V3& x) const {
    SideSample s;
    double best = band_ * band_;
    int bt = -1;
    V3 bb(0, 0, 0);
    for (std::size_t t = 0; t < cur_.tri.size(); ++t) {
      const detail::Box& b = boxes_[t];
      if ((x.array() < b.lo.array()).any() || (x.array() > b.hi.array()).any()) continue;
      const Eigen::Vector3i& tr = cur_.tri[t];
      const V3 w = closest_barycentric(x, cur_.x[tr[0]], cur_.x[tr[1]], cur_.x[tr[2]]);
      const V3 cp = w[0] * cur_.x[tr[0]] + w[1] * cur_.x[tr[1]] + w[2] * cur_.x[tr[2]];
      const double d2 = (x - cp).squaredNorm();
      if (d2 < best) {
        best = d2;
        bt = static_cast<int>(t);
        bb = w;
      }
    }
    if (bt < 0) return s;  // Far
    const Eigen::Vector3i& tr = cur_.tri[bt];
    s.distance = std::sqrt(best);
    s.rest = bb[0] * rest_.x[tr[0]] + bb[1] * rest_.x[tr[1]] + bb[2] * rest_.x[tr[2]];
    if (rest_boundary_distance(s.rest) < rim_) {
      s.state = SideSample::State::Rim;
      return s;
    }
    const V3 cp = bb[0] * cur_.x[tr[0]] + bb[1] * cur_.x[tr[1]] + bb[2] * cur_.x[tr[2]];
    const int zeros = (bb[0] == 0) + (bb[1] == 0) + (bb[2] == 0);
    V3 n = face_n_[bt];
    if (zeros == 2) {
      n = vert_n_[tr[bb[0] != 0 ? 0 : bb[1] != 0 ? 1 : 2]];
    } else if (zeros == 1) {
      const int k = bb[0] == 0 ? 1 : bb[1] == 0 ? 2 : 0;  // the edge from corner k to k+1
      const int a = std::min(tr[k], tr[(k + 1) % 3]), b = std::max(tr[k], tr[(k + 1) % 3]);
      n = edge_n_.at({a, b});
    }
    const double off = (x - cp).dot(n);
    if (s.distance < dead_ || off == 0) {
      s.state = SideSample::State::Dead;
      return s;
    }
    s.state = SideSample::State::Side;
    s.sign = off > 0 ? 1 : -1;
    return s;
  }

  const TriMesh& rest() const { return rest_; }

 private:
  double rest_boundary_distance(const V3& r) const {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& [a, b] : boundary_) {
      const V3& p = rest_.x[a];
      const V3 e = rest_.x[b] - p;
      const double t = std::clamp((r - p).dot(e) / std::max(e.squaredNorm(), 1e-300), 0.0, 1.0);
      d = std::min(d, (r - p - t * e).norm());
    }
    return d;
  }

  TriMesh rest_, cur_;
  double band_, rim_, dead_;
  std::vector<std::pair<int, int>> boundary_;
  std::vector<V3> face_n_, vert_n_;
  std::map<std::pair<int, int>, V3> edge_n_;
  std::vector<detail::Box> boxes_;
};

/// Whether a point sampled as `before` and then `after` (next frame) passed through the
/// surface: on opposite sides, with closest points within `locality` in the rest mesh.
inline bool crossed(const SideSample& before, const SideSample& after, double locality) {
  return before.state == SideSample::State::Side && after.state == SideSample::State::Side &&
         before.sign != after.sign && (before.rest - after.rest).norm() <= locality;
}

/// The side samples of many points against one surface (one frame).
inline std::vector<SideSample> sample_all(const ShellSurface& surf, const std::vector<V3>& x) {
  std::vector<SideSample> out(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) out[i] = surf.sample(x[i]);
  return out;
}

/// How many points crossed a surface between two frames, from their samples in each
/// (`before` with ids `ids_before`, `after` with `ids_after`; points are matched by id,
/// those in one frame only are skipped). `which`: (index before, index after) of each;
/// `judged` is increased by the points that had a side in both frames (the ones the test
/// could judge at all).
template <class Id>
std::size_t count_flips(const std::vector<SideSample>& before, const std::vector<Id>& ids_before,
                        const std::vector<SideSample>& after, const std::vector<Id>& ids_after,
                        double locality,
                        std::vector<std::pair<std::size_t, std::size_t>>* which = nullptr,
                        std::size_t* judged = nullptr) {
  std::map<Id, std::size_t> index;
  for (std::size_t i = 0; i < ids_before.size(); ++i) index[ids_before[i]] = i;
  std::size_t n = 0;
  for (std::size_t j = 0; j < after.size(); ++j) {
    const auto it = index.find(ids_after[j]);
    if (it == index.end()) continue;
    if (judged && before[it->second].state == SideSample::State::Side &&
        after[j].state == SideSample::State::Side)
      ++*judged;
    if (!crossed(before[it->second], after[j], locality)) continue;
    if (which) which->emplace_back(it->second, j);
    ++n;
  }
  return n;
}

/// Points (`before` -> `after`, matched by id) that crossed a surface whose positions in
/// the two frames are `surf_before` and `surf_after`.
template <class Id>
std::size_t count_crossings(const ShellSurface& surf_before, const ShellSurface& surf_after,
                            const std::vector<V3>& before, const std::vector<Id>& ids_before,
                            const std::vector<V3>& after, const std::vector<Id>& ids_after,
                            double locality) {
  return count_flips(sample_all(surf_before, before), ids_before, sample_all(surf_after, after),
                     ids_after, locality);
}

// ------------------------------------------------------------------ colliders

/// One key of a rigid motion x' = R x + T, R = Rz Ry Rx from XYZ Euler angles [deg].
struct PoseKey {
  double time = 0;
  V3 translate{0, 0, 0};
  V3 rotate_deg{0, 0, 0};
};

/// An analytic collider shape in its own frame, with its keyframed motion.
struct ColliderShape {
  enum class Kind { Plane, Box, Sphere, Cylinder } kind = Kind::Plane;
  V3 point{0, 0, 0}, normal{0, 1, 0};  ///< plane (normal: the outside)
  V3 min{0, 0, 0}, max{0, 0, 0};       ///< box
  V3 center{0, 0, 0};                  ///< sphere, cylinder
  double radius = 0, height = 0;       ///< sphere, cylinder
  V3 axis{0, 1, 0};                    ///< cylinder
  std::vector<PoseKey> keys;           ///< empty: static at the identity
};

namespace detail {
inline Eigen::Quaterniond euler_xyz(const V3& deg) {
  const V3 r = deg * (M_PI / 180.0);
  return Eigen::AngleAxisd(r.z(), V3::UnitZ()) * Eigen::AngleAxisd(r.y(), V3::UnitY()) *
         Eigen::AngleAxisd(r.x(), V3::UnitX());
}
}  // namespace detail

/// The pose (rotation, translation) of a keyframed motion at time t.
inline std::pair<Eigen::Matrix3d, V3> pose_at(const std::vector<PoseKey>& keys, double t) {
  if (keys.empty()) return {Eigen::Matrix3d::Identity(), V3::Zero()};
  if (keys.size() == 1 || t <= keys.front().time)
    return {detail::euler_xyz(keys.front().rotate_deg).toRotationMatrix(), keys.front().translate};
  if (t >= keys.back().time)
    return {detail::euler_xyz(keys.back().rotate_deg).toRotationMatrix(), keys.back().translate};
  std::size_t k = 1;
  while (keys[k].time < t) ++k;
  const PoseKey& a = keys[k - 1];
  const PoseKey& b = keys[k];
  const double s = (t - a.time) / (b.time - a.time);
  const Eigen::Quaterniond q =
      detail::euler_xyz(a.rotate_deg).slerp(s, detail::euler_xyz(b.rotate_deg));
  return {q.toRotationMatrix(), (1 - s) * a.translate + s * b.translate};
}

/// Signed distance of world point x to the collider at time t: negative inside [m].
inline double collider_distance(const ColliderShape& c, const V3& x, double t) {
  const auto [R, T] = pose_at(c.keys, t);
  const V3 p = R.transpose() * (x - T);
  switch (c.kind) {
    case ColliderShape::Kind::Plane:
      return (p - c.point).dot(c.normal.normalized());
    case ColliderShape::Kind::Sphere:
      return (p - c.center).norm() - c.radius;
    case ColliderShape::Kind::Box: {
      const V3 q = (p - 0.5 * (c.min + c.max)).cwiseAbs() - 0.5 * (c.max - c.min);
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case ColliderShape::Kind::Cylinder: {
      const V3 ax = c.axis.normalized();
      const V3 d = p - c.center;
      const double along = d.dot(ax), radial = (d - along * ax).norm();
      const double qr = radial - c.radius, qa = std::abs(along) - 0.5 * c.height;
      return std::hypot(std::max(qr, 0.0), std::max(qa, 0.0)) + std::min(std::max(qr, qa), 0.0);
    }
  }
  return 0;
}

}  // namespace shellmpm_test
