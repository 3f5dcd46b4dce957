// Loop subdivision limit basis: Stam 1998 (regular box-spline patch, appendix A),
// Cirak, Ortiz, Schroeder 2000 sec. 3 (local subdivision of irregular patches).
// The rules are documented in loop_basis.h.
#include "sim/shell/loop_basis.h"

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "sim/core/check.h"
#include "sim/core/counting_sort.h"
#include "sim/shell/box_spline.h"
#include "sim/shell/loop_patch.h"

namespace shellmpm {

namespace {

LatticePoint real_point(int a) {
  LatticePoint p;
  p.n = 1;
  p.idx[0] = a;
  p.w[0] = 1;
  return p;
}
LatticePoint phantom(int a, int b, int c) {
  LatticePoint p;
  p.n = 3;
  p.idx[0] = a;
  p.idx[1] = b;
  p.idx[2] = c;
  p.w[0] = 1;
  p.w[1] = 1;
  p.w[2] = -1;
  return p;
}

}  // namespace

namespace loop_patch {

bool regular_lattice(const int c[3], const FanView fan[3], LatticePoint P[12]) {
  int nb = 0;
  for (int k = 0; k < 3; ++k) {
    if (fan[k].boundary) {
      if (fan[k].size != 4) return false;
      ++nb;
    } else if (fan[k].size != 6) {
      return false;
    }
  }
  if (nb == 3) return false;
  if (nb == 2) {
    // The two boundary corners must be joined by a boundary edge.
    int a = -1, b = -1;
    for (int k = 0; k < 3; ++k)
      if (fan[k].boundary) (a < 0 ? a : b) = k;
    const FanView& fa = fan[a];
    const int vb = c[b];
    if (fa.ring[0] != vb && fa.ring[fa.size - 1] != vb) return false;
  }
  // Six lattice neighbours of each corner, counter-clockwise, starting at the next corner.
  LatticePoint r[3][6];
  for (int k = 0; k < 3; ++k) {
    LatticePoint e[6];
    const FanView& f = fan[k];
    for (int m = 0; m < f.size; ++m) e[m] = real_point(f.ring[m]);
    if (f.boundary) {
      e[4] = phantom(c[k], f.ring[3], f.ring[2]);
      e[5] = phantom(c[k], f.ring[0], f.ring[1]);
    }
    const int next = c[(k + 1) % 3];
    int s = -1;
    for (int m = 0; m < f.size; ++m)
      if (f.ring[m] == next) s = m;
    if (s < 0) return false;
    for (int m = 0; m < 6; ++m) r[k][m] = e[(s + m) % 6];
  }
  P[7] = real_point(c[0]);  // 8
  P[3] = real_point(c[1]);  // 4
  P[6] = real_point(c[2]);  // 7
  P[10] = r[0][2];          // 11
  P[11] = r[0][3];          // 12
  P[8] = r[0][4];           // 9
  P[4] = r[0][5];           // 5
  P[1] = r[1][3];           // 2
  P[0] = r[1][4];           // 1
  P[2] = r[1][5];           // 3
  P[5] = r[2][3];           // 6
  P[9] = r[2][4];           // 10
  return true;
}

double loop_beta(int n) {
  const double b = 0.375 + 0.25 * std::cos(2.0 * M_PI / n);
  return (0.625 - b * b) / n;
}

std::string order_fan(const std::vector<std::pair<int, int>>& links, std::vector<int>& ring,
                      std::vector<int>& order, bool& boundary) {
  ring.clear();
  order.clear();
  const int n = static_cast<int>(links.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (links[i].first == links[j].first || links[i].second == links[j].second)
        return "an edge is used twice in the same direction (inconsistent orientation or "
               "non-manifold edge)";
    }
  int start = -1, nstart = 0;
  for (int i = 0; i < n; ++i) {
    bool is_to = false;
    for (int j = 0; j < n; ++j) is_to |= links[j].second == links[i].first;
    if (!is_to) {
      ++nstart;
      start = i;
    }
  }
  if (nstart > 1) return "more than one fan of faces meets at the vertex (non-manifold vertex)";
  boundary = nstart == 1;
  if (start < 0) start = 0;
  int cur = start;
  for (int step = 0; step < n; ++step) {
    ring.push_back(links[cur].first);
    order.push_back(cur);
    const int to = links[cur].second;
    int nxt = -1;
    for (int j = 0; j < n; ++j)
      if (links[j].first == to) nxt = j;
    if (nxt < 0 || nxt == start) {
      if (boundary) ring.push_back(to);
      break;
    }
    cur = nxt;
  }
  if (static_cast<int>(order.size()) != n)
    return "the faces around the vertex form more than one fan (non-manifold vertex)";
  return std::string();
}

}  // namespace loop_patch

namespace {

std::string face_str(int f, const Eigen::Vector3i& t) {
  std::ostringstream os;
  os << "face " << f << " (" << t[0] << ", " << t[1] << ", " << t[2] << ")";
  return os.str();
}

/// Throws unless (xi1, xi2) lies in the parameter triangle of `face` (tolerance 1e-12),
/// then clamps it into the triangle.
void check_and_clamp(int face, double& xi1, double& xi2) {
  const double tol = 1e-12;
  if (!(xi1 >= -tol && xi2 >= -tol && xi1 + xi2 <= 1 + tol)) {
    std::ostringstream os;
    os << "LoopBasis::evaluate: point (" << xi1 << ", " << xi2 << ") outside face " << face;
    throw std::invalid_argument(os.str());
  }
  xi1 = std::max(xi1, 0.0);
  xi2 = std::max(xi2, 0.0);
  if (xi1 + xi2 > 1) {
    const double sum = xi1 + xi2;
    xi1 /= sum;
    xi2 /= sum;
  }
}

/// Basis of a regular patch with lattice P at (xi1, xi2): the box spline's 12 functions
/// gathered onto the real vertices (phantoms spread with their weights).
void regular_basis(const LatticePoint P[12], double xi1, double xi2, BasisPoint& o) {
  double B[6][12];
  box_spline(xi1, xi2, B);
  o.ctrl.clear();
  std::vector<double>* q[6] = {&o.N, &o.N1, &o.N2, &o.N11, &o.N12, &o.N22};
  for (auto* v : q) v->clear();
  for (int k = 0; k < 12; ++k)
    for (int m = 0; m < P[k].n; ++m) {
      const int id = P[k].idx[m];
      std::size_t pos = 0;
      while (pos < o.ctrl.size() && o.ctrl[pos] != id) ++pos;
      if (pos == o.ctrl.size()) {
        o.ctrl.push_back(id);
        for (auto* v : q) v->push_back(0.0);
      }
      for (int d = 0; d < 6; ++d) (*q[d])[pos] += P[k].w[m] * B[d][k];
    }
}

/// Moves a point closer than 1e-9 to an irregular corner of fans gf that distance towards
/// the face centroid (see loop_basis.h). Returns that corner (0-2), or -1 if none.
int nudge_off_irregular_corner(const FanView gf[3], double& xi1, double& xi2) {
  const double nudge = 1e-9;
  const double corner_xi[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  int exact_corner = -1;
  for (int k = 0; k < 3; ++k) {
    const bool regular_vertex = gf[k].boundary ? gf[k].size == 4 : gf[k].size == 6;
    if (regular_vertex) continue;
    const double dx = xi1 - corner_xi[k][0], dy = xi2 - corner_xi[k][1];
    if (std::sqrt(dx * dx + dy * dy) < nudge) {
      exact_corner = k;
      const double cx = 1.0 / 3 - corner_xi[k][0], cy = 1.0 / 3 - corner_xi[k][1];
      const double len = std::sqrt(cx * cx + cy * cy);
      xi1 = corner_xi[k][0] + nudge * cx / len;
      xi2 = corner_xi[k][1] + nudge * cy / len;
    }
  }
  return exact_corner;
}

}  // namespace

LoopBasis::LoopBasis(int num_vertices, const std::vector<Eigen::Vector3i>& triangles)
    : num_vertices_(num_vertices), tris_(triangles) {
  if (num_vertices < 0) throw std::invalid_argument("LoopBasis: negative vertex count");
  const int nf = static_cast<int>(tris_.size());
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = tris_[f];
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || t[k] >= num_vertices)
        throw std::invalid_argument("LoopBasis: " + face_str(f, t) + " has vertex index " +
                                    std::to_string(t[k]) + " out of range [0, " +
                                    std::to_string(num_vertices) + ")");
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      throw std::invalid_argument("LoopBasis: " + face_str(f, t) + " repeats a vertex");
  }
  // The faces around each vertex in face order: corner entries 3 f + k sorted by vertex.
  std::vector<int> raw;
  counting_sort(
      3 * tris_.size(), static_cast<std::size_t>(num_vertices),
      [&](std::size_t e) { return tris_[e / 3][static_cast<int>(e % 3)]; }, face_offset_, raw);
  for (int& e : raw) e /= 3;
  vface_.resize(raw.size());
  ring_offset_.assign(num_vertices + 1, 0);
  boundary_.assign(num_vertices, 0);
  ring_.reserve(raw.size() + num_vertices);
  std::vector<std::pair<int, int>> links;
  std::vector<int> ring, order;
  for (int v = 0; v < num_vertices; ++v) {
    links.clear();
    for (int i = face_offset_[v]; i < face_offset_[v + 1]; ++i) {
      const Eigen::Vector3i& t = tris_[raw[i]];
      const int k = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
      links.emplace_back(t[(k + 1) % 3], t[(k + 2) % 3]);
    }
    bool bnd = false;
    if (!links.empty()) {
      const std::string err = order_fan(links, ring, order, bnd);
      if (!err.empty()) {
        std::string faces;
        for (int i = face_offset_[v]; i < face_offset_[v + 1] && i < face_offset_[v] + 8; ++i)
          faces += (faces.empty() ? "" : ", ") + std::to_string(raw[i]);
        throw std::invalid_argument("LoopBasis: vertex " + std::to_string(v) + " (faces " + faces +
                                    "): " + err);
      }
      for (std::size_t i = 0; i < order.size(); ++i)
        vface_[face_offset_[v] + i] = raw[face_offset_[v] + order[i]];
      ring_.insert(ring_.end(), ring.begin(), ring.end());
    }
    boundary_[v] = bnd;
    ring_offset_[v + 1] = static_cast<int>(ring_.size());
  }
}

void LoopBasis::evaluate(int face, double xi1, double xi2, BasisPoint& out) const {
  evaluate_impl(face, xi1, xi2, &out);
}

int LoopBasis::subdivision_depth(int face, double xi1, double xi2) const {
  return evaluate_impl(face, xi1, xi2, nullptr);
}

int LoopBasis::evaluate_impl(int face, double xi1, double xi2, BasisPoint* out) const {
  if (face < 0 || face >= num_faces())
    throw std::invalid_argument("LoopBasis::evaluate: face " + std::to_string(face) +
                                " out of range [0, " + std::to_string(num_faces()) + ")");
  check_and_clamp(face, xi1, xi2);
  const Eigen::Vector3i& T = tris_[face];
  const int c[3] = {T[0], T[1], T[2]};
  auto global_fan = [&](int v) {
    return FanView{ring_.data() + ring_offset_[v], ring_offset_[v + 1] - ring_offset_[v],
                   boundary_[v] != 0};
  };
  const FanView gf[3] = {global_fan(c[0]), global_fan(c[1]), global_fan(c[2])};
  LatticePoint P[12];
  if (regular_lattice(c, gf, P)) {
    if (out) regular_basis(P, xi1, xi2, *out);
    return 0;
  }
  // Irregular patch: nudge the point off an irregular corner (see header), then refine.
  const int exact_corner = nudge_off_irregular_corner(gf, xi1, xi2);
  return evaluate_irregular(face, xi1, xi2, exact_corner, out);
}

void LoopBasis::vertex_limit_weights(int v, std::vector<int>& ctrl, std::vector<double>& w) const {
  if (v < 0 || v >= num_vertices_)
    throw std::invalid_argument("LoopBasis::vertex_limit_weights: vertex " + std::to_string(v) +
                                " out of range");
  ctrl.assign(1, v);
  w.assign(1, 1.0);
  const int n = ring_offset_[v + 1] - ring_offset_[v];
  const int* r = ring_.data() + ring_offset_[v];
  if (n == 0) return;
  if (!boundary_[v]) {
    // Limit mask: (1 - n g) v + g sum(ring), g = 1 / (n + 3 / (8 beta)) (Loop 1987).
    const double g = 1.0 / (n + 3.0 / (8.0 * loop_beta(n)));
    w[0] = 1.0 - n * g;
    for (int i = 0; i < n; ++i) {
      ctrl.push_back(r[i]);
      w.push_back(g);
    }
  } else if (n > 2) {
    // Cubic B-spline limit of the boundary chain.
    w[0] = 2.0 / 3.0;
    ctrl.push_back(r[0]);
    w.push_back(1.0 / 6.0);
    ctrl.push_back(r[n - 1]);
    w.push_back(1.0 / 6.0);
  }
}

}  // namespace shellmpm
