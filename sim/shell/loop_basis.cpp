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

namespace shellmpm {

namespace {

/// A lattice point of a regular patch: a real vertex (n = 1) or a phantom a + b - c.
struct LatticePoint {
  int n = 0;
  int idx[3] = {-1, -1, -1};
  double w[3] = {0, 0, 0};
};
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

/// A vertex fan: ring[i], ring[i+1] span face i; `boundary` when the fan is open.
struct FanView {
  const int* ring;
  int size;
  bool boundary;
};

/// If the face with corners c[0..2] (counter-clockwise) is a regular patch, writes its
/// 12 lattice points (Stam's numbering, 0-based) and returns true. See loop_basis.h for
/// the definition of a (boundary-)regular patch and the phantom rule.
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

/// Orders the faces around v into a fan. links: (a, b) for each face (v, a, b).
/// Returns an empty string on success, else a description of the problem.
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

// ---------------------------------------------------------------------------------
// Local subdivision of an irregular patch (Cirak et al. 2000, sec. 3).
// Local vertex i = (ref + D.row(i)) . (initial control points). Keeping the rows as
// differences D from a reference row keeps their relative precision as the patch
// shrinks (rows of D are O(lambda^level)); storing the rows themselves would lose it,
// and the derivatives, scaled by 2^level, would pick up round-off 2^level * eps.
struct LocalMesh {
  std::vector<std::array<int, 3>> faces;
  int target = 0;  // the face that contains the point
  Eigen::RowVectorXd ref;
  Eigen::MatrixXd D;
  int rows() const { return static_cast<int>(D.rows()); }
};

/// Buffers reused across the levels of one evaluation (avoids allocations per level).
struct Scratch {
  std::vector<std::pair<int, int>> links;
  std::vector<int> order;
  std::vector<int> ring[3];  // fans of the target face's corners
  bool boundary[3] = {false, false, false};
  std::vector<std::pair<int, double>> mask;  // all masks, flat
  std::vector<int> mask_begin;               // mask of new vertex i: [begin[i], begin[i+1])
  std::vector<int> vp, remap, used, opp;
  std::vector<std::array<int, 3>> edges;  // (min, max, new index)
  LocalMesh next;
};

void local_fan(const LocalMesh& m, int v, Scratch& w, std::vector<int>& ring, bool& boundary) {
  w.links.clear();
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      if (f[k] == v) w.links.emplace_back(f[(k + 1) % 3], f[(k + 2) % 3]);
  const std::string err = order_fan(w.links, ring, w.order, boundary);
  SHELLMPM_CHECK(err.empty(), << "local fan of vertex " << v << ": " << err);
}

/// Fans of the target face's corners into w.ring / w.boundary.
void target_fans(const LocalMesh& m, Scratch& w) {
  for (int k = 0; k < 3; ++k) local_fan(m, m.faces[m.target][k], w, w.ring[k], w.boundary[k]);
}

int edge_index(const Scratch& w, int a, int b) {
  if (a > b) std::swap(a, b);
  for (const auto& e : w.edges)
    if (e[0] == a && e[1] == b) return e[2];
  return -1;
}

/// Ends the mask being written and returns the new vertex's index.
int close_mask(Scratch& w) {
  w.mask_begin.push_back(static_cast<int>(w.mask.size()));
  return static_cast<int>(w.mask_begin.size()) - 2;
}

/// Loop's vertex mask of corner c with fan `ring` (interior, boundary or sharp corner).
void vertex_mask(int c, const std::vector<int>& ring, bool boundary, Scratch& w) {
  const int n = static_cast<int>(ring.size());
  if (!boundary) {
    const double b = loop_beta(n);
    w.mask.emplace_back(c, 1.0 - n * b);
    for (int x : ring) w.mask.emplace_back(x, b);
  } else if (n == 2) {  // one face: sharp corner
    w.mask.emplace_back(c, 1.0);
  } else {
    w.mask.emplace_back(c, 0.75);
    w.mask.emplace_back(ring.front(), 0.125);
    w.mask.emplace_back(ring.back(), 0.125);
  }
}

/// Loop's edge mask of edge (c, x): 3/8, 3/8, 1/8, 1/8 inside, 1/2, 1/2 on the boundary.
void edge_mask(const LocalMesh& m, int c, int x, Scratch& w) {
  w.opp.clear();
  for (const auto& f : m.faces)
    for (int q = 0; q < 3; ++q)
      if (f[q] == c && (f[(q + 1) % 3] == x || f[(q + 2) % 3] == x))
        w.opp.push_back(f[(q + 1) % 3] == x ? f[(q + 2) % 3] : f[(q + 1) % 3]);
  SHELLMPM_CHECK(w.opp.size() == 1 || w.opp.size() == 2,
                 << "edge with " << w.opp.size() << " faces");
  if (w.opp.size() == 1) {
    w.mask.emplace_back(c, 0.5);
    w.mask.emplace_back(x, 0.5);
  } else {
    w.mask.emplace_back(c, 0.375);
    w.mask.emplace_back(x, 0.375);
    w.mask.emplace_back(w.opp[0], 0.125);
    w.mask.emplace_back(w.opp[1], 0.125);
  }
}

/// Masks of the new vertices around target face T: each corner's vertex point, then the
/// edge points of its fan (each edge once). Writes w.mask, w.mask_begin, w.vp, w.edges.
void target_masks(const LocalMesh& m, const std::array<int, 3>& T, Scratch& w) {
  w.mask.clear();
  w.mask_begin.assign(1, 0);
  w.vp.assign(m.rows(), -1);
  w.edges.clear();
  for (int k = 0; k < 3; ++k) {
    const int c = T[k];
    vertex_mask(c, w.ring[k], w.boundary[k], w);
    w.vp[c] = close_mask(w);
    for (int x : w.ring[k]) {
      if (edge_index(w, c, x) >= 0) continue;
      edge_mask(m, c, x, w);
      w.edges.push_back({std::min(c, x), std::max(c, x), close_mask(w)});
    }
  }
}

/// Children of a parent face (-1 where a vertex was not computed), counter-clockwise,
/// ordered so that child parameters are +-2 xi + const (see descend()).
void face_children(const Scratch& w, const std::array<int, 3>& f, std::array<int, 3> ch[4]) {
  const int va = w.vp[f[0]], vb = w.vp[f[1]], vc = w.vp[f[2]];
  const int eab = edge_index(w, f[0], f[1]), ebc = edge_index(w, f[1], f[2]),
            eca = edge_index(w, f[2], f[0]);
  ch[0] = {va, eab, eca};
  ch[1] = {eab, vb, ebc};
  ch[2] = {eca, ebc, vc};
  ch[3] = {ebc, eca, eab};
}

/// The child (0-3, see face_children()) that contains (s, t); maps (s, t) to its
/// parameters and multiplies scale by d(child xi) / d(parent xi).
int descend(double& s, double& t, double& scale) {
  if (s >= 0.5) {
    s = 2 * s - 1;
    t = 2 * t;
    scale *= 2;
    return 1;
  }
  if (t >= 0.5) {
    s = 2 * s;
    t = 2 * t - 1;
    scale *= 2;
    return 2;
  }
  if (s + t <= 0.5) {
    s = 2 * s;
    t = 2 * t;
    scale *= 2;
    return 0;
  }
  s = 1 - 2 * s;
  t = 1 - 2 * t;
  scale *= -2;
  return 3;
}

/// The child faces that touch `target` into w.next.faces (renumbered; w.remap, w.used
/// map old mask index <-> new vertex). Returns the number of new vertices.
int collect_children(const LocalMesh& m, const std::array<int, 3>& target, Scratch& w) {
  LocalMesh& out = w.next;
  out.faces.clear();
  const int nmasks = static_cast<int>(w.mask_begin.size()) - 1;
  w.remap.assign(nmasks, -1);
  w.used.clear();
  int nnew = 0;
  for (const auto& f : m.faces) {
    std::array<int, 3> ch[4];
    face_children(w, f, ch);
    for (const auto& cf : ch) {
      if (cf[0] < 0 || cf[1] < 0 || cf[2] < 0) continue;
      bool touches = false;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) touches |= cf[a] == target[b];
      if (!touches) continue;
      std::array<int, 3> nf;
      for (int a = 0; a < 3; ++a) {
        if (w.remap[cf[a]] < 0) {
          w.remap[cf[a]] = nnew++;
          w.used.push_back(cf[a]);
        }
        nf[a] = w.remap[cf[a]];
      }
      if (cf == target) out.target = static_cast<int>(out.faces.size());
      out.faces.push_back(nf);
    }
  }
  return nnew;
}

/// Rows of the nnew kept vertices into w.next.ref / w.next.D. Masks sum to one, so
/// sum_k m_ik W_k - ref' = sum_k m_ik D_k - sum_k m_0k D_k with ref' = ref + sum_k m_0k D_k
/// the row of new vertex 0.
void apply_masks(const LocalMesh& m, int nnew, Scratch& w) {
  LocalMesh& out = w.next;
  auto mask_of = [&](int i) {
    return std::make_pair(w.mask.begin() + w.mask_begin[w.used[i]],
                          w.mask.begin() + w.mask_begin[w.used[i] + 1]);
  };
  Eigen::RowVectorXd shift = Eigen::RowVectorXd::Zero(m.D.cols());
  for (auto [it, end] = mask_of(0); it != end; ++it) shift += it->second * m.D.row(it->first);
  out.ref = m.ref + shift;
  out.D.setZero(nnew, m.D.cols());
  for (int i = 1; i < nnew; ++i) {
    for (auto [it, end] = mask_of(i); it != end; ++it)
      out.D.row(i) += it->second * m.D.row(it->first);
    out.D.row(i) -= shift;
  }
}

/// One level of local Loop subdivision; keeps the child of the target face that contains
/// (s, t) and the child faces around its corners, and maps (s, t) to the child.
/// Needs target_fans(m, w) computed.
void subdivide_local(LocalMesh& m, Scratch& w, double& s, double& t, double& scale) {
  const std::array<int, 3> T = m.faces[m.target];
  target_masks(m, T, w);
  std::array<int, 3> tc[4];
  face_children(w, T, tc);
  const std::array<int, 3> target = tc[descend(s, t, scale)];
  const int nnew = collect_children(m, target, w);
  apply_masks(m, nnew, w);
  std::swap(m, w.next);
}

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

/// Local index of global vertex g in ctrl, appending it if new.
int local_index(std::vector<int>& ctrl, int g) {
  for (std::size_t i = 0; i < ctrl.size(); ++i)
    if (ctrl[i] == g) return static_cast<int>(i);
  ctrl.push_back(g);
  return static_cast<int>(ctrl.size()) - 1;
}

/// The local mesh of `faces` (global ids, repeats skipped) with `face` as target;
/// ctrl receives local -> global vertex. Rows start as the identity, as differences from
/// local vertex 0.
LocalMesh local_patch(const std::vector<Eigen::Vector3i>& tris, const std::vector<int>& faces,
                      int face, std::vector<int>& ctrl) {
  LocalMesh m;
  for (const int f : faces) {
    bool seen = false;
    std::array<int, 3> lf = {local_index(ctrl, tris[f][0]), local_index(ctrl, tris[f][1]),
                             local_index(ctrl, tris[f][2])};
    for (const auto& g : m.faces) seen |= g == lf;
    if (seen) continue;
    if (f == face) m.target = static_cast<int>(m.faces.size());
    m.faces.push_back(lf);
  }
  const int nctrl = static_cast<int>(ctrl.size());
  m.ref = Eigen::RowVectorXd::Zero(nctrl);
  m.ref[0] = 1;
  m.D.setIdentity(nctrl, nctrl);
  m.D.col(0).array() -= 1.0;
  return m;
}

/// True when the target face of m (fans in w) is a regular patch; writes its lattice P.
bool local_regular_lattice(const LocalMesh& m, const Scratch& w, LatticePoint P[12]) {
  const std::array<int, 3>& lt = m.faces[m.target];
  const int lc[3] = {lt[0], lt[1], lt[2]};
  FanView lf[3];
  for (int k = 0; k < 3; ++k)
    lf[k] = FanView{w.ring[k].data(), static_cast<int>(w.ring[k].size()), w.boundary[k]};
  return regular_lattice(lc, lf, P);
}

/// Value and 5 derivatives (columns) of the initial control points' basis (rows) at
/// (s, t) of m's regular target patch P; derivatives scaled back to the original face.
Eigen::Matrix<double, Eigen::Dynamic, 6> local_basis(const LocalMesh& m, const LatticePoint P[12],
                                                     double s, double t, double scale) {
  double B[6][12];
  box_spline(s, t, B);
  const double fac[6] = {1, scale, scale, scale * scale, scale * scale, scale * scale};
  Eigen::Matrix<double, Eigen::Dynamic, 6> local =
      Eigen::Matrix<double, Eigen::Dynamic, 6>::Zero(m.rows(), 6);
  for (int k = 0; k < 12; ++k)
    for (int q = 0; q < P[k].n; ++q)
      for (int d = 0; d < 6; ++d) local(P[k].idx[q], d) += P[k].w[q] * B[d][k] * fac[d];
  // sum_i local(i, d) is 1 for the value and exactly 0 for the derivatives (partition
  // of unity), so the reference row enters the value only.
  Eigen::Matrix<double, Eigen::Dynamic, 6> global = m.D.transpose() * local;
  global.col(0) += m.ref.transpose();
  return global;
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

int LoopBasis::evaluate_irregular(int face, double xi1, double xi2, int exact_corner,
                                  BasisPoint* out) const {
  const Eigen::Vector3i& c = tris_[face];
  std::vector<int> around;  // the faces around the corners, in fan order
  for (int k = 0; k < 3; ++k)
    for (int i = face_offset_[c[k]]; i < face_offset_[c[k] + 1]; ++i) around.push_back(vface_[i]);
  std::vector<int> ctrl;  // local index -> global vertex
  LocalMesh m = local_patch(tris_, around, face, ctrl);
  double s = xi1, t = xi2, scale = 1.0;
  Scratch w;
  target_fans(m, w);
  LatticePoint P[12];
  for (int level = 1;; ++level) {
    SHELLMPM_CHECK(level <= 80, << "local subdivision did not reach a regular patch (face " << face
                                << ", xi " << xi1 << ", " << xi2 << ")");
    subdivide_local(m, w, s, t, scale);
    target_fans(m, w);
    if (!local_regular_lattice(m, w, P)) continue;
    if (!out) return level;
    Eigen::Matrix<double, Eigen::Dynamic, 6> global = local_basis(m, P, s, t, scale);
    if (exact_corner >= 0) {
      // At an irregular vertex the value is its exact limit (see header); derivatives
      // are those of the nudged point.
      global.col(0).setZero();
      std::vector<int> lim_ctrl;
      std::vector<double> lim_w;
      vertex_limit_weights(c[exact_corner], lim_ctrl, lim_w);
      for (std::size_t k = 0; k < lim_ctrl.size(); ++k)
        global(local_index(ctrl, lim_ctrl[k]), 0) += lim_w[k];
    }
    BasisPoint& o = *out;
    o.ctrl = ctrl;
    std::vector<double>* qv[6] = {&o.N, &o.N1, &o.N2, &o.N11, &o.N12, &o.N22};
    for (int d = 0; d < 6; ++d) {
      qv[d]->resize(ctrl.size());
      for (std::size_t i = 0; i < ctrl.size(); ++i) (*qv[d])[i] = global(i, d);
    }
    return level;
  }
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
