// The shell guard: keeps contact shells from passing through each other and through
// themselves where the grid cannot resolve them (issue 10).
//
// Why it exists. Grid contact (shell_fields.h, shell_contact.h) acts through node
// velocities, so two layers closer than about a cell share nodes; in a tight twist or a
// stack driven together, a dozen layers can sit in one cell and the surface between the
// control points crosses without the grid seeing it, at any contact stiffness (measured
// in the issue 10 notes). The guard works on the surface itself, like the proximity
// impulses of Bridson, Fedkiw and Anderson 2002 ("Robust treatment of collisions,
// contact and friction for cloth animation"): it never replaces the grid's contact and
// friction, it only stops the last approach closer than a gap the grid would not hold.
//
// What it does, once per step after G2P and the colliders' projection (control points
// have moved from x^n, which G2P recorded, to x^{n+1}):
// - Geometry at the start of the step: the limit mesh at refine 0 (the Loop limit
//   positions of the control points, the surface the integrity monitor judges), built
//   from x^n; the unknowns are the velocities v = (x^{n+1} - x^n) / dt (G2P's, plus the
//   projection's push where a collider moved a point), limit velocities u = S v with the
//   same sparse map S.
// - Bulk particles are points of the same kind: a bulk particle closer than the gap to a
//   limit triangle is a pair like a limit vertex (its mass from volume and density).
// - Proximity pairs at x^n within gap + reach (reach = twice the largest limit speed
//   times dt; candidates from lists rebuilt only when the motion needs it): vertex-triangle (a
//   limit vertex not on the triangle) and edge-edge (edges without a common vertex), between shells
//   and within a shell. Within a shell, pairs closer than about one mesh edge at rest are left out
//   (see Mesh::near).
// - Each pair is a one-sided constraint on the relative limit velocity along its normal
//   n (from the closest point of the second feature to the first): with distance d,
//   n . (u_1 - u_2) >= -max(d - gap, 0) / dt, i.e. the pair may close up to the gap but no
//   further within the step, and a pair already inside the gap stops closing. The
//   constraint is linear in the control velocities (a row J of S-weights), and is met by
//   mass-weighted impulses dv = M^-1 J^T lambda, lambda >= 0 (projected Gauss-Seidel in a
//   fixed order, so the result does not depend on the thread count). Pinned components
//   have zero inverse mass. The impulses are along n only (no friction: sliding stays
//   the grid's Coulomb law), they remove approach velocity (dissipative, never adding
//   energy) and sum to zero over the control points (S rows and barycentric weights
//   both sum to 1), so momentum is conserved except at pins.
// - Control points whose velocity changed move by dt (v_new - v_old), so
//   x^{n+1} = x^n + dt v_new still holds. A projection after the guard would move points
//   it had just held apart (a crushed crumple's top layer pressed through the one under
//   it), hence its place after the colliders.
// Pairs still violated after the sweep cap go to impact zones (Provot 1997, Bridson et
// al. 2002): the points of connected violated pairs move with their mean velocity, so
// those pairs stop closing; momentum is kept, energy only lost. What even that cannot
// meet (two pins driving one zone) is counted as unresolved (stats.json), and the
// integrity monitor stays the judge of whether anything crossed.
#pragma once
#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "sim/contact/shell_transfer.h"
#include "sim/math/box_pairs.h"
#include "sim/math/triangle_queries.h"
#include "sim/mpm/particles.h"
#include "sim/shell/limit_mesh.h"

namespace shellmpm {

/// The bulk particles a guard pass also keeps out of the shells (particles may be null).
struct GuardBulk {
  ParticleSet* particles = nullptr;
  const std::vector<Real>* densities = nullptr;  ///< per material [kg/m^3]
  std::uint64_t epoch = 0;                       ///< changes whenever the particles are reordered
};

/// What one guard pass did.
struct ShellGuardStats {
  std::size_t pairs = 0;       ///< proximity pairs within gap + reach
  std::size_t impulses = 0;    ///< pairs that needed an impulse
  std::size_t zoned = 0;       ///< points moved as rigid impact zones (Gauss-Seidel fell short)
  std::size_t unresolved = 0;  ///< pairs still closing faster than allowed at the end
  int sweeps = 0;              ///< Gauss-Seidel sweeps taken
  double pin_work = 0;         ///< the pins' work through the points they hold [J]
};

class ShellGuard {
 public:
  /// The shells' topology is fixed from here on. gap [m] > 0; serial: no threads.
  void setup(const std::vector<GridShell>& shells, double gap, bool serial = false);
  double gap() const { return gap_; }
  /// Coulomb friction on the pairs the guard pushes apart (off by default): each pair's
  /// tangential relative velocity loses at most c_F times its normal impulse, with c_F the
  /// geometric mean of the two shells' (a shell's own against bulk material). With contact
  /// at the surfaces the guard holds the last part of a thick contact layer (see
  /// ShellGuardStage::gap), where it must not let the bodies slide freely.
  void set_friction(bool on) { friction_on_ = on; }
  /// The gap kept between bulk particles and shells [m] (setup: the gap): a particle's
  /// centre rests half a particle spacing out from its material's surface, so with a
  /// thick contact layer the shells' gap would keep bulk material too far out.
  void set_bulk_gap(double gap) { bulk_gap_ = gap; }
  /// One pass after G2P and the colliders' projection (see the file comment): changes v
  /// and x of control points. start: each shell's control points at x^n.
  ShellGuardStats apply(std::vector<GridShell>& shells, const std::vector<std::vector<Vec3>>& start,
                        const GuardBulk& bulk, double dt);
  /// The same, with x^n = x - dt v (nothing moved the points since G2P).
  ShellGuardStats apply(std::vector<GridShell>& shells, const GuardBulk& bulk, double dt);

  /// Gauss-Seidel sweeps at most per pass.
  static constexpr int kMaxSweeps = 100;

 private:
  struct Mesh {
    std::unique_ptr<LimitMesh> limit;
    std::vector<Eigen::Vector2i> edges;  ///< unique limit-mesh edges
    std::vector<Vec3d> rest;             ///< limit vertices at rest
    /// Pairs of this shell closer than this at rest are never paired: the larger of
    /// 2 gap and the mean rest edge (neighbours within about one edge; the bending
    /// stiffness, not contact, keeps a fold that tight from crossing).
    double near = 0;
  };
  struct Entry {
    std::size_t point;  ///< control point, numbered across shells
    double w;           ///< weight in the constraint row
  };
  struct Pair {
    std::size_t begin, end;  ///< its entries in entries_
    Vec3d n;                 ///< unit normal, from the second feature to the first
    double target;           ///< lower bound on n . (u_1 - u_2) [m/s]
    double denom;            ///< J M^-1 J^T
    double lambda = 0;       ///< accumulated impulse [kg m/s]
    double mu = 0;           ///< Coulomb coefficient (set_friction)
  };
  /// Limit vertex v of shell s as entries with weight scale.
  void add_vertex(std::size_t s, int v, double scale);
  void add_pair(const Vec3d& n, double d, double gap, double dt, double mu);
  /// One Gauss-Seidel sweep of friction impulses over the pairs with a normal impulse.
  void apply_friction();
  /// Point x against limit triangle T (at pos_): closer than r? Then the closest point's
  /// barycentric weights w, the distance d and the pair's unit normal n (from the
  /// triangle to x; the triangle's own normal when x is within `tiny` of it).
  bool point_triangle_pair(const Vec3d& x, const Eigen::Vector3i& T, double r, double tiny,
                           Vec3d& w, double& d, Vec3d& n) const;
  /// n . (relative velocity) of a pair at the current v_.
  double rate(const Pair& p) const;
  /// Moves the points of pairs still violated as rigid zones; returns how many points.
  std::size_t impact_zones(double tol);
  /// Vertex-triangle and edge-edge pairs closer than radius at pos_ (sorted).
  void build_shell_candidates(double radius);
  /// Its edge-edge pairs, found cell by cell in cells of side `cell`.
  void build_edge_candidates(double radius, double cell);
  /// near_vt_, near_ee_ (once: the rest shapes are fixed).
  void build_rest_near();
  /// Bulk particle-triangle pairs closer than radius (particles at x^n, sorted).
  void build_bulk_candidates(double radius, const GuardBulk& bulk, double dt);
  double cell_size(double radius) const;
  // Steps of apply(), in order.
  /// The largest control-point speed |x - x^n| / dt (returned) and spread_.
  double point_bounds(const std::vector<GridShell>& shells,
                      const std::vector<std::vector<Vec3>>& start, double dt);
  /// x0_, v_ = v_end_ = (x - x^n) / dt and inv_mass_ of the control points.
  void load_points(const std::vector<GridShell>& shells,
                   const std::vector<std::vector<Vec3>>& start, double dt);
  /// pos_: the limit vertices at x0_.
  void limit_positions();
  /// The bulk candidates' velocities, inverse masses and x^n after the control points.
  void load_bulk(const GuardBulk& bulk, double dt);
  /// entries_, pairs_: the candidates within r (shell) and r_bulk (bulk) at x^n.
  void gather_pairs(double r, double r_bulk, double dt);
  /// Projected Gauss-Seidel on the pairs' impulses until a sweep changes less than tol
  /// [m/s]; returns the sweeps done.
  int solve_pairs(double tol);
  /// Adds the velocity changes to the shells' and particles' v, and dt times them to x.
  void write_back(std::vector<GridShell>& shells, ParticleSet* ps, double dt) const;
  /// A Verlet list's schedule: valid while the motion bound since its build stays
  /// within its margin. The bound is the smaller of two: `moved`, the steps' relative
  /// motion bounds summed, and (for the shell list) `spread`, the diagonal of the box of
  /// the control points' displacements since the build, which bounds any two points'
  /// relative displacement (and so the limit vertices', convex combinations of them)
  /// however the points moved, and is 0 for a rigid translation.
  struct ListSchedule {
    bool built = false;
    double margin = 0, moved = 0;
    bool valid(double reach, double spread = std::numeric_limits<double>::infinity()) const {
      return built && std::min(moved, spread) + reach <= margin;
    }
    void start(double gap, double reach) {
      built = true;
      margin = std::max(4.0 * gap, 4.0 * reach);
      moved = reach;  // this step's motion counts
    }
  };

  double gap_ = 0;
  double bulk_gap_ = 0;
  bool friction_on_ = false;
  std::vector<double> friction_;  ///< per shell: its contact's c_F
  bool serial_ = false;
  std::vector<Mesh> meshes_;
  std::vector<std::size_t> point_offset_;   ///< first control point of each shell
  std::vector<std::size_t> vertex_offset_;  ///< first limit vertex of each shell
  std::vector<std::size_t> vert_shell_;     ///< shell of each limit vertex
  // Candidate pairs (Verlet lists): built within gap + margin, valid until the relative
  // motion bound since then could close the margin. Which pairs are candidates
  // never changes a result: a pass acts on the pairs within gap + reach, all of which
  // are candidates, in candidate order (vertex, triangle; then edge, edge).
  std::vector<Eigen::Vector2i> vt_cand_, ee_cand_;
  std::vector<Eigen::Vector2i> bt_cand_;  ///< (index into bulk_idx_, triangle)
  std::vector<std::uint32_t> bulk_idx_;   ///< bulk particles with a candidate, ascending
  std::vector<Vec3d> bulk_x0_;            ///< their positions at x^n (per pass)
  std::uint64_t built_epoch_ = 0;
  std::size_t built_count_ = 0;
  ListSchedule shell_list_, bulk_list_;
  // Per pass (kept to reuse their memory).
  std::vector<Vec3d> pos_;       ///< limit vertices of all shells at x^n
  std::vector<Vec3d> x0_;        ///< control points at x^n
  std::vector<Vec3d> x_built_;   ///< x0_ at the shell list's last build
  double spread_ = 0;            ///< point_bounds: the displacements' box diagonal since then
  std::vector<Vec3d> v_end_;     ///< (x - x^n) / dt before the guard
  std::vector<Vec3d> v_;         ///< control velocities (double) being corrected
  std::vector<Vec3d> inv_mass_;  ///< per control point and component
  /// Per point: the pin's velocity on its held components, 0 elsewhere (empty when no
  /// pin holds a point this pass); a held component's share of an impulse is the pin's.
  std::vector<Vec3d> held_v_;
  double pin_work_ = 0;  ///< the pins' work through the held points this pass [J]
  std::vector<Eigen::Vector3i> all_tris_;
  std::vector<Vec3d> edge_tri_pos_;
  std::vector<Eigen::Vector3i> all_edges_;  ///< edges as degenerate triangles (a, b, b)
  /// The pairs a list build never takes, found once: per limit vertex the triangles of
  /// its shell within Mesh::near of it at rest (not its own), and per edge e the edges
  /// f > e likewise (no shared vertex). Ascending, as offsets into one array each.
  struct NearLists {
    std::vector<std::size_t> start;
    std::vector<int> item;
    const int* begin(std::size_t i) const { return item.data() + start[i]; }
    const int* end(std::size_t i) const { return item.data() + start[i + 1]; }
  };
  NearLists near_vt_, near_ee_;
  bool rest_near_built_ = false;
  TriangleGrid tri_grid_, bulk_grid_;  ///< used by the list builds only
  BoxPairs edge_pairs_;
  std::vector<BoxPairs::Box> edge_box_;  ///< build_edge_candidates: each edge's box
  std::vector<Entry> entries_;
  std::vector<Pair> pairs_;
};

}  // namespace shellmpm
