// Loop subdivision limit-surface basis over a triangle control mesh.
//
// References:
//  - C. Loop 1987, "Smooth subdivision surfaces based on triangles" (vertex/edge masks).
//  - J. Stam 1998, "Evaluation of Loop subdivision surfaces", appendix: the 12 quartic
//    box-spline basis functions of a regular patch in barycentric form.
//  - F. Cirak, M. Ortiz, P. Schroeder 2000, "Subdivision surfaces: a new paradigm for
//    thin-shell finite-element analysis", sec. 3: evaluation of irregular patches by
//    local subdivision until the point lies in a regular sub-patch.
//  - H. Hoppe et al. 1994 / OpenSubdiv Sdc: boundary (crease) masks.
//
// Rules (chosen to match OpenSubdiv's Loop scheme with
// Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER, no creases):
//  - Interior vertex of valence n: v' = (1 - n b) v + b sum(ring),
//    b = (5/8 - (3/8 + 1/4 cos(2 pi / n))^2) / n (Loop's original weights).
//  - Interior edge: 3/8 (a + b) + 1/8 (c + d).
//  - Boundary edge (one face): midpoint. Boundary vertex with >= 2 faces: crease rule
//    3/4 v + 1/8 (two boundary neighbours), so each boundary chain's limit is the cubic
//    B-spline of its boundary vertices. Boundary vertex with exactly one face: sharp
//    corner, v' = v (the limit interpolates it).
//  - Regular patches (every corner interior of valence 6, or on the boundary with
//    exactly 3 faces, see below) are evaluated exactly as quartic box splines (Stam's 12
//    functions). Near the boundary the missing lattice points are phantoms
//    p = a + b - c (the parallelogram reflection across a boundary edge (a, b) of the
//    real triangle (a, b, c)); with these phantoms the box-spline refinement masks
//    reproduce the crease rules above exactly. A face is boundary-regular when it has
//    one boundary corner (and no boundary edge) or two boundary corners joined by a
//    boundary edge, the boundary corners having 3 faces and the others 6.
//  - Every other face (extraordinary vertex, irregular boundary vertex, corner, strip
//    of width one) is refined locally (Cirak et al.): its one-ring neighbourhood is
//    subdivided with the masks above, the child face containing the point is kept, and
//    this repeats until the child is regular. Child parameters are +-2 xi + const, so
//    derivatives pick up a factor (+-2)^level (chain rule); values and derivatives are
//    exact for the limit surface.
//  - At an irregular vertex itself the parametric derivatives are singular in general
//    (first derivatives vanish for valence < 6 and blow up for valence > 6, second
//    derivatives blow up; the subdivision would not terminate): for a point closer than
//    1e-9 (in xi) to an irregular corner, N is the exact limit mask of that vertex (as
//    vertex_limit_weights) and the derivatives are those at the point 1e-9 from the
//    corner towards the face centroid (their directions span the tangent plane).
//  - Numerics: the local control net is carried as differences from a reference
//    vertex, so values and derivatives keep relative precision at any depth.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace shellmpm {

/// Basis functions of the limit surface at one parametric point.
struct BasisPoint {
  std::vector<int> ctrl;  ///< control point (mesh vertex) indices that influence the point
  /// Basis value and derivatives with respect to xi1, xi2; same length as ctrl.
  std::vector<double> N, N1, N2, N11, N12, N22;
};

/// Loop subdivision basis of a triangle control mesh (the mesh vertices are the control
/// points). Immutable after construction; evaluate() is thread-safe.
class LoopBasis {
 public:
  /// Builds the vertex fans. Throws std::invalid_argument (message naming the face or
  /// vertex) for meshes it cannot handle: indices out of range or repeated in a face,
  /// an edge with more than two faces, inconsistent orientation, a non-manifold vertex.
  /// Vertices used by no face are allowed (they get no basis). Run check_shell_mesh()
  /// first for user-facing errors.
  LoopBasis(int num_vertices, const std::vector<Eigen::Vector3i>& triangles);

  /// Limit surface basis at parametric point (xi1, xi2) of `face`:
  /// x(xi) = sum_k N[k] x[ctrl[k]], a_alpha = sum_k N_alpha[k] x[ctrl[k]], etc.
  /// The face's corners (v0, v1, v2) = triangles[face] sit at (0,0), (1,0), (0,1);
  /// xi1, xi2 >= 0, xi1 + xi2 <= 1 (violations beyond 1e-12 throw std::invalid_argument).
  void evaluate(int face, double xi1, double xi2, BasisPoint& out) const;

  int num_faces() const { return static_cast<int>(tris_.size()); }
  int num_vertices() const { return num_vertices_; }

  /// Limit position of control vertex v as weights: limit(v) = sum_k w[k] x[ctrl[k]].
  /// Interior: Loop's limit mask; boundary: 1/6, 2/3, 1/6 along the boundary; corner
  /// (one face) and unused vertices: the vertex itself.
  void vertex_limit_weights(int v, std::vector<int>& ctrl, std::vector<double>& w) const;

  /// Number of local subdivision levels evaluate() needed at this point (0 for a regular
  /// patch). For tests and diagnostics.
  int subdivision_depth(int face, double xi1, double xi2) const;

 private:
  int evaluate_impl(int face, double xi1, double xi2, BasisPoint* out) const;
  /// evaluate_impl() on a patch with an irregular corner: local subdivision (Cirak et al.
  /// 2000, sec. 3) until the point lies in a regular patch; returns the depth.
  int evaluate_irregular(int face, double xi1, double xi2, int exact_corner, BasisPoint* out) const;
  int num_vertices_ = 0;
  std::vector<Eigen::Vector3i> tris_;
  // Per-vertex fan, counter-clockwise: face i of vertex v is (v, ring[i], ring[i+1]),
  // with ring[i+1] wrapping to ring[0] for interior vertices.
  std::vector<int> ring_offset_;  // size num_vertices + 1
  std::vector<int> ring_;
  std::vector<int> face_offset_;  // size num_vertices + 1
  std::vector<int> vface_;        // faces around each vertex, in fan order
  std::vector<char> boundary_;
};

}  // namespace shellmpm
