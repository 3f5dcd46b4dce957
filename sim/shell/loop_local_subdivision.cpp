// Local subdivision of an irregular patch (Cirak, Ortiz, Schroeder 2000, sec. 3): the
// Loop basis at a point of a face with an irregular corner, by subdividing around it until
// the point lies in a regular patch (loop_basis.h).
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "sim/core/check.h"
#include "sim/shell/box_spline.h"
#include "sim/shell/loop_basis.h"
#include "sim/shell/loop_patch.h"

namespace shellmpm {

namespace {

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

}  // namespace shellmpm
