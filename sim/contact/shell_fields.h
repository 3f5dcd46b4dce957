// A velocity field per shell, and one for all bulk material, on grid nodes that they
// share, so that bodies in contact slide as Coulomb says (multi-field MPM, Bardenhagen et
// al. 2000, "Contact algorithm for granular materials").
//
// With one velocity per node, two sheets resting ~2 dx apart share the nodes between
// them and every transfer averages their velocities there: an inelastic, no-slip drag
// on top of the contact friction, which made a frictionless sheet slide at a third of
// g sin on another and dragged blocks off with a pulled table cloth (README, "Contact").
// Here each shell also transfers its control points to its own grid (mass, the same
// APIC momentum with its forces, and its normal turned to each node's side); the bulk
// material's share is the rest of the node. At a shared node each body b reads its own
// velocity plus everything the grid update added there (gravity, the contact particles'
// normal forces):
//   v_b = v + (v_b^0 - v^0),
// v^0 and v the node's velocity before and after the update, v_b^0 = p_b / m_b, after
// Bardenhagen's rule between every pair of bodies there (two shells on opposite sides of
// the node, or a shell and the bulk field), with n the shell normals: when they approach,
// they share the normal velocity, and their relative tangential velocity drops by c_F
// times the normal one (sticking at zero); when they separate, each keeps its own. c_F
// is the shell material's friction (the geometric mean of two shells'). The changes are
// equal and opposite, with a shell's pinned share counted as infinitely heavy, so
// momentum is unchanged except through pins. The contact particles' elasticity and
// return mapping act as before, through the grid forces.
//
// Bulk materials share one field (sand on snow stays single-field MPM). The folds of one
// shell get two fields where they meet (shell_folds.cpp): at a node whose stencil holds
// two layers of it, its control points are split by the node's height over their tangent
// planes, and the two classes meet by the same rule as two shells, with the shell's c_F.
// Without the split a fold slid over the rest of its cloth at a quarter of Coulomb's
// acceleration; the shell guard (shell_guard.h) stays the backstop against crossing where
// a crumple has more than two layers at a node. Nodes on colliders or walls, and nodes
// where the bulk share is too small to separate from round-off (under 1e-3 of the mass),
// keep one velocity.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "sim/contact/field_slots.h"
#include "sim/contact/shell_transfer.h"
#include "sim/core/types.h"
#include "sim/mpm/particles.h"
#include "sim/mpm/sparse_grid.h"

namespace shellmpm {

class ShellFields {
 public:
  /// skip(node): true where a node must keep a single velocity (a collider acts on it, or
  /// a wall).
  using SkipFn = std::function<bool(const Vec3i& node)>;

  /// Grid geometry, the number of grid shells, whether there is bulk material and whether
  /// a shell's folds are bodies of their own (shot.fold_fields): fields are kept when
  /// there are two bodies or more (two shells, a shell and bulk, or a folding shell).
  void setup(const SparseGrid& grid, std::size_t num_shells, bool bulk, bool folds);
  bool active() const { return active_; }
  /// Contact at the bodies' surfaces (contact_gap.h): the rule between two bodies at a
  /// node lets them close by the gap between their contact surfaces, half_thickness[s]
  /// [m] on each side of shell s's surface, and bulk material's surface where its volume
  /// fraction puts it. Off: they stop closing wherever they share a node (the paper).
  void set_contact_surfaces(bool on, std::vector<Real> half_thickness) {
    surfaces_ = on;
    half_thickness_ = std::move(half_thickness);
  }
  /// With contact at the surfaces: marks the contact particles whose stencil holds a node
  /// that their shell shares with another body (or its other fold class): release[s][p] =
  /// 1 for site p of grid shell s, others 0. A site reads the node's common velocity, so it
  /// was squeezed by the other body's motion across the gap between them, and its normal
  /// force, applied to the node, pushed that body away a cell early (a sheet falling on a
  /// pile stopped 0.75 dx above it; with a contact thickness of a cell, two). The return
  /// mapping treats it as separated: between bodies, contact is the gated pair rule's
  /// (Bardenhagen's Coulomb friction once it acts; the shell guard below the contact
  /// distance as the backstop), and the paper's contact elasticity acts where no other
  /// body shares the stencil (self-contact within a layer, colliders). points: the combined
  /// binning's shell points (control points, then contact particles).
  void apart_sites(const SparseGrid& combined, const ShellPointTable& table,
                   const std::vector<Vec3>& points, std::vector<std::vector<std::uint8_t>>& release,
                   bool serial) const;
  bool contact_at_surfaces() const { return active_ && surfaces_; }
  /// Grid nodes where the last p2g's rule found two bodies in contact (closing on each
  /// other, or within the contact distance): stats.json's contact_nodes.
  std::size_t met_nodes() const;

  /// Before the combined P2G: where one shell alone has fields (its folds' heights only),
  /// its control-point normals and the heights for shell_p2g_block to sum; else null.
  FoldHeights* begin_p2g(const SparseGrid& combined, const std::vector<GridShell>& shells,
                         bool serial);
  /// Right after the combined P2G (the combined grid holds mass and momentum): each
  /// shell's own P2G, and the relative velocities v_b^0 - v^0 of every body at the nodes
  /// two bodies share.
  /// bulk: the bulk particles, binned in `combined` as first_bulk + index (null: none).
  void p2g(const SparseGrid& combined, const std::vector<GridShell>& shells, Real dt,
           const ParticleSet* bulk, std::uint32_t first_bulk, bool serial);
  /// With contact at the surfaces, which bodies at a shared node a collider's condition
  /// applies to: a node inside a collider stands for everything within 1.5 dx, and a thin
  /// sheet on the ground engages it, so a block resting on that sheet read the ground's
  /// velocity there and floated a cell above the sheet. Only bodies whose contact surface
  /// at the node lies within `reach` of a collider (plus their step's travel) take it;
  /// the others keep the velocity the grid update gave them.
  struct ColliderGate {
    /// Whether node n of combined grid block g takes a collider's condition.
    std::function<bool(std::size_t g, int n)> engaged;
    /// Signed distance [m] from world x to the nearest collider (positive outside).
    std::function<double(const Vec3d& x)> phi;
    /// Applies the conditions of the colliders that node n of block g takes to a body's
    /// velocity v there.
    std::function<void(std::size_t g, int n, Vec3& v)> apply;
    /// The velocity of the (first) moving collider node n of block g takes [m/s]; zero
    /// where none moves (the colliders' work, sim/integrity/energy_audit.h).
    std::function<Vec3d(std::size_t g, int n)> velocity;
    Real reach = 0;  ///< [m]
  };
  /// Before the colliders' conditions (with a gate): keeps the shared nodes' velocities.
  void keep_free_velocities(const SparseGrid& combined, bool serial);
  /// After the grid update, before G2P: drops the relative velocities where skip() says
  /// so, and gives shared nodes the bulk field's velocity (bulk particles, contact
  /// particles and the shells' plain G2P then read it). With a gate (and
  /// keep_free_velocities called), skip() names the walls only, and collider nodes give
  /// each body the collider's velocity or its own (ColliderGate).
  void before_g2p(SparseGrid& combined, const SkipFn& skip, bool serial,
                  const ColliderGate* gate = nullptr);
  /// The moving colliders' work in the last before_g2p beyond what the colliders' node
  /// conditions did (each body's impulse under the gate, less the node's) [J].
  double gate_work() const { return gate_work_; }
  /// After G2P: each control point gets v += sum w r, x += dt sum w r and C += the
  /// matching APIC term, r its shell's velocity relative to the node's (held components
  /// unchanged).
  void after_g2p(std::vector<GridShell>& shells, Real dt, bool serial);

  /// The implicit grid step (field_slots.h). p2g then records which bodies Bardenhagen's
  /// rule brought together at each node.
  void set_implicit(bool on) { implicit_ = on; }
  /// Before the solve (once a step, after p2g): the groups' unknowns and offsets at the
  /// shared nodes that skip() and the gate leave to the fields (the gate's colliders posed
  /// for the step).
  void slots(const SparseGrid& combined, const std::vector<GridShell>& shells, const SkipFn& skip,
             const ColliderGate* gate, FieldSlots& out, bool serial);
  bool has_slots() const { return slotted_; }
  /// After the solve (the combined grid holds its node velocities u): each shell's velocity
  /// at the slotted nodes, relative to u, from its group's unknown (slot_vel per slot).
  /// before_g2p leaves those nodes as they are.
  void take_solution(const SparseGrid& combined, const FieldSlots& fs,
                     const std::vector<Vec3>& slot_vel);
  /// After a solve (the combined grid holds its node velocities; `before`: its nodes as
  /// P2G left them): the rule again on the solved velocities at the slotted nodes. Where
  /// two groups close on each other faster than their gap allows, they are joined, with
  /// the rule's outcome on the solved velocities as the offsets, and true is returned:
  /// restore the grid, call slots() again and solve again (an active set: bodies apart
  /// when the step began, that the step's forces drive together, meet inside it).
  bool regroup(const SparseGrid& combined,
               const std::vector<std::array<GridNode, kBlockNodes>>& before,
               const std::vector<Vec3>& slot_vel);

 private:
  struct Node {
    Real m;
    Real p[3];  ///< momentum; velocity after p2g()
    Real n[3];  ///< sum of w m n_j, n_j the shell normal turned to the node's side
    Real N[3];  ///< sum of w m n_j, n_j the shell's own (oriented) normal
    Real o[3];  ///< sum of w m (x_j - x_node) / dx; the centroid offset after p2g()
    Real held;  ///< mass of fully pinned control points
    /// Least and greatest height of the node over the control points' tangent planes, in
    /// cells, along their normals aligned to kAlign (fold_height): two layers differ.
    Real hmin, hmax;
    /// Zero sums, empty height range.
    static void clear(Node* d, std::size_t count) {
      std::memset(static_cast<void*>(d), 0, count * sizeof(Node));
      for (std::size_t k = 0; k < count; ++k) {
        d[k].hmin = std::numeric_limits<Real>::max();
        d[k].hmax = std::numeric_limits<Real>::lowest();
      }
    }
    void operator+=(const Node& b) {
      m += b.m;
      held += b.held;
      for (int a = 0; a < 3; ++a) {
        p[a] += b.p[a];
        n[a] += b.n[a];
        N[a] += b.N[a];
        o[a] += b.o[a];
      }
      hmin = std::min(hmin, b.hmin);
      hmax = std::max(hmax, b.hmax);
    }
  };
  /// Bulk volume sum w V and first moment sum w V (x_p - x_node) / dx at a node (the
  /// centroid offset after bulk_moments).
  struct Moment {
    Real m;
    Real o[3];
  };
  struct Classes {
    Node c[2];  ///< fold_height below and above the cut
  };
  /// A fixed direction no flat layer of a usual scene is perpendicular to (normals along
  /// the axes, or tilted in one plane, all have a clear sign against it).
  static inline const Vec3 kAlign = Vec3(Real(0.8), Real(0.5), Real(0.33)).normalized();
  /// The second class of a shell's control points on the grid blocks where it folds.
  struct FoldBlock {
    std::array<std::uint8_t, kBlockNodes> split;  ///< 1: the node has two classes
    std::array<Real, kBlockNodes> cut;            ///< class 1: fold_height >= cut
    std::array<Node, kBlockNodes> second;         ///< class 1
    std::array<Vec3, kBlockNodes> r;              ///< its velocity relative to the node
  };
  /// The height of node offset (i, j, k) over the tangent plane of a control point with
  /// unit normal n at grid coordinate fx within its stencil, in cells, along n turned to
  /// kAlign's side: every point of one flat layer gives the same, whatever the layer's
  /// orientation, and two layers differ by their distance.
  static Real fold_height(const Vec3& n, const Vec3& fx, int i, int j, int k) {
    const Real h = side_of(n, fx, i, j, k);
    return n.dot(kAlign) >= 0 ? h : -h;
  }
  /// n . ((i, j, k) - fx), summed in this order (PointShare's rows give the same bits).
  static Real side_of(const Vec3& n, const Vec3& fx, int i, int j, int k) {
    return (n[0] * (Real(i) - fx[0]) + n[1] * (Real(j) - fx[1])) + n[2] * (Real(k) - fx[2]);
  }
  static bool is_split(const FoldBlock& fb, int bn) { return fb.split[bn] != 0; }
  struct Field {
    SparseGrid grid;  ///< binning of this shell's control points (no grid nodes)
    /// The shell, or its first class (heights_only_: set on fold blocks only).
    std::vector<std::array<Node, kBlockNodes>> nodes;
    /// heights_only_, where the shell folds: the combined P2G's heights on this grid.
    std::vector<std::array<NodeHeights, kBlockNodes>> heights;
    std::vector<std::array<Vec3, kBlockNodes>> r;  ///< velocity relative to the node
    std::vector<Vec3> x0;                          ///< control points at p2g time
    std::vector<Vec3> normal;                      ///< control-point unit normals
    /// The shell's triangles at each control point, ascending: tri_of[tri_start[i] ..
    /// tri_start[i + 1]) (built once).
    std::vector<std::uint32_t> tri_start, tri_of;
    std::vector<Vec3> tri_area;    ///< per triangle: twice its area times its unit normal
    std::vector<int> fold;         ///< per grid block: index into folds, -1: no fold
    std::vector<FoldBlock> folds;  ///< grid blocks where the shell folds, in block order
    std::vector<int> touched;      ///< per particle block: index into the fold buffers
    std::vector<std::array<Classes, kPadNodes>> class_buf;
  };
  /// A node's 16 scalars (Node's layout) as one vector: one AVX-512 register, four SSE.
  typedef Real NodeLanes __attribute__((vector_size(16 * sizeof(Real))));
  static_assert(sizeof(Node) == sizeof(NodeLanes), "a node is sixteen scalars");
  /// One control point's share of its 27 stencil nodes in a field's P2G. The share at
  /// stencil offset (i, j, k) is w (L0 + i Li[0] + j Li[1] + k Li[2] +- Nn), linear in the
  /// offset but for the normal turned to the node's side (the sign of side_of), computed
  /// once per stencil row (i, j) and then per node along k.
  struct PointShare {
    bool heights;  ///< keep the nodes' height range (fold fields on)
    Real align;    ///< +1 or -1: n turned to kAlign's side
    Vec3 fx, n;
    NodeLanes L0, Li[3], Nn;
    /// Row (i, j) of the stencil: L0 + i Li[0] + j Li[1], and side_of's first two terms.
    struct Row {
      NodeLanes L;
      Real side;
    };
    PointShare(const GridShell& gs, const Vec3& n, const Vec3& fx, std::uint32_t j, Real dx,
               Real dt, bool with_heights);
    [[gnu::always_inline]] void row(int i, int j, Row& r) const {
      r.L = (L0 + Real(i) * Li[0]) + Real(j) * Li[1];
      r.side = n[0] * (Real(i) - fx[0]) + n[1] * (Real(j) - fx[1]);
    }
    /// Adds the weight-w share at node k of row r to d.
    [[gnu::always_inline]] void add(Node& d, Real w, const Row& r, int k) const {
      const Real side = r.side + n[2] * (Real(k) - fx[2]);
      NodeLanes v = r.L + Real(k) * Li[2];
      if (side > 0) v = v + Nn;
      if (side < 0) v = v - Nn;
      NodeLanes a;
      std::memcpy(&a, &d, sizeof a);
      a = a + w * v;
      std::memcpy(&d, &a, sizeof a);
      if (heights && w > 0) {
        const Real h = align * side;  // fold_height
        d.hmin = std::min(d.hmin, h);
        d.hmax = std::max(d.hmax, h);
      }
    }
    /// The same at stencil offset (i, j, k).
    void add(Node& d, Real w, int i, int j, int k) const {
      Row r;
      row(i, j, r);
      add(d, w, r, k);
    }
  };
  /// F's control-point normals: the area-weighted normals of the control mesh's triangles.
  static void control_normals(Field& F, const ShellObject& sh, bool serial);
  void shell_p2g(Field& F, const GridShell& gs, const SparseGrid& combined, Real dt, bool serial);
  /// Walks F's control points colour by colour (blocks of a colour touch disjoint nodes)
  /// and calls add(P, row, grid block, node, w, k) for each of their 27 stencil nodes, P
  /// the point's PointShare.
  template <class AddFn>
  void scatter_shares(Field& F, const GridShell& gs, Real dt, bool heights, bool serial, AddFn add);
  /// heights_only_: whether a node of the combined P2G's heights spreads (a fold).
  bool any_spread() const;
  /// Momentum to velocity, first moment to centroid offset.
  static void normalise(Node& d);
  /// Between the sums and their normalisation in shell_p2g: finds the nodes where F's
  /// shell folds and splits its control points there into two classes (shell_folds.cpp).
  void split_folds(Field& F, const GridShell& gs, Real dt, bool serial);
  /// split_folds' steps: the nodes whose heights spread (F.fold, F.folds with their cuts);
  /// both classes scattered from the particle blocks next to split nodes (F.touched,
  /// F.class_buf); their sums gathered into F.nodes and the second fields.
  static void mark_split_nodes(Field& F, bool heights_only);
  void scatter_classes(Field& F, const GridShell& gs, Real dt, bool serial);
  static void gather_classes(Field& F, bool serial);
  /// A body at a node: a shell there, or one of its two classes where it folds.
  struct Body {
    int shell;
    const Node* f;
    Vec3* r;                  ///< where its relative velocity goes
    Vec3 vel, nrm, own, off;  ///< velocity, normal to the node, own normal, centroid
    Real winv;                ///< inverse effective mass (pinned share: infinite)
  };
  /// The rule's groups at a node (implicit_): 4 bits per body in node_bodies' order, the
  /// bulk field last, each the index of its group's first body; all zero: one group.
  static constexpr int kMaxGroupBodies = 16;
  struct Union {
    std::uint8_t up[kMaxGroupBodies];
    explicit Union(int n) {
      for (int i = 0; i < n && i < kMaxGroupBodies; ++i) up[i] = std::uint8_t(i);
    }
    int find(int i) const {
      while (up[i] != i) i = up[i];
      return i;
    }
    void join(int a, int b) {
      if (a >= kMaxGroupBodies || b >= kMaxGroupBodies) return;
      a = find(a);
      b = find(b);
      if (a != b) up[std::max(a, b)] = std::uint8_t(std::min(a, b));
    }
  };
  // Steps of p2g().
  /// fblock_, fielded_: each field's block at each combined grid block.
  void find_field_blocks(const SparseGrid& combined, bool serial);
  /// The bodies with mass at node n of combined grid block g (velocities only); returns
  /// their total mass.
  Real node_bodies(std::size_t g, int n, std::vector<Body>& bodies);
  /// A body's normals, centroid offset and inverse effective mass from its sums.
  static void body_geometry(Body& B);
  /// The contact normal of two bodies at a node, from a towards b when they face each
  /// other (sign -1: a's normal minus b's, both turned to the node) or their common side
  /// (sign +1): the normals weighted by the other body's inverse mass, so that a pinned or
  /// much heavier body's surface is the contact plane, as a collider's is, and two equal
  /// bodies share the mean. With the plain mean a sliding sheet that pitched forward on a
  /// pinned one tilted the normal with it, and the normal impulse pushed it on down the
  /// slope: 16% faster than Coulomb at dx 0.028 (issue 13's incline_sheet).
  static Vec3 contact_normal(const Body& A, const Body& B, Real sign);
  /// Shell against shell at one node (facing across it, or stacked on one side); returns
  /// whether the rule acted on a pair.
  bool shell_pairs(std::vector<Body>& bodies, Union* groups) const;
  /// Each shell against the bulk field (mass mk, velocity vk; bm its centroid and volume
  /// sum, or null); returns whether the rule acted on a pair.
  bool bulk_pairs(std::vector<Body>& bodies, const Moment* bm, Real mk, Vec3& vk,
                  Union* groups) const;
  /// The gap [m] between shells a and b at a node whose centroids lie h cells apart along
  /// the normal from a to b; -inf where contact is at the stencils.
  Real shell_gap(const Body& A, const Body& B, Real h) const;
  /// Bardenhagen's rule at node n of combined grid block g (combined node cn): the
  /// bodies' and the bulk field's velocities relative to the node's, and its shared_ bit.
  void resolve_node(const GridNode& cn, std::size_t g, int n, bool moments,
                    std::vector<Body>& bodies);
  /// Bulk mass centroids on the grid blocks where shells have fields.
  void bulk_moments(const SparseGrid& combined, const ParticleSet& bulk, std::uint32_t first_bulk,
                    bool serial);
  bool active_ = false;
  bool folds_ = false;                ///< split_folds on
  bool surfaces_ = false;             ///< contact at the surfaces (set_contact_surfaces)
  std::vector<Real> half_thickness_;  ///< per shell [m]
  Real dt_ = 0, dx_ = 0;              ///< of the last p2g [s], [m]
  /// One shell and no bulk material: a node holds two bodies only where the shell folds
  /// (its two classes), so only mass and heights are summed, in the combined P2G
  /// (heights_), and full sums (Field::nodes) exist on fold blocks only, from the classes.
  /// Every other node keeps one velocity, as it would with the full sums (one body
  /// there). Where no node's heights spread, the field is not even binned (no blocks).
  bool heights_only_ = false;
  FoldHeights heights_;
  std::vector<Field> fields_;
  std::vector<Real> friction_;  ///< per shell: c_F against bulk material
  // Per combined grid block: the fields' block indices (-1: absent), the bulk field's
  // relative velocity and a bit per node that has relative velocities.
  std::vector<int> fblock_;
  std::vector<std::array<Vec3, kBlockNodes>> r_bulk_;
  std::vector<char> fielded_;  ///< per combined grid block: a shell field is present
  std::vector<std::array<Moment, kPadNodes>> bulk_buf_;    ///< per combined particle block
  std::vector<std::array<Moment, kBlockNodes>> bulk_mom_;  ///< per combined grid block
  std::vector<std::uint64_t> shared_;
  std::vector<std::uint64_t> bulk_at_;  ///< per combined grid block: the bulk field is there
  /// Per combined grid block: a bit per node shared with another body (another shell or
  /// the bulk field, not only the shell's own fold classes): apart_sites.
  std::vector<std::uint64_t> others_;
  std::vector<std::uint64_t> met_;  ///< per combined grid block: the rule acted at the node
  /// Shared nodes' velocities before the colliders' conditions (keep_free_velocities), per
  /// combined grid block with shared nodes: free_[free_slot_[g]].
  std::vector<int> free_slot_;
  std::vector<std::array<Vec3, kBlockNodes>> free_;
  /// Calls fn(j, dv, B) for each control point j of field F whose stencil holds relative
  /// velocities: dv = sum w r, B = sum w r (x_n - x_j)^T / dx (in cells).
  using RelativeFn = std::function<void(std::uint32_t, const Vec3&, const Mat3&)>;
  void each_relative(const Field& F, bool serial, const RelativeFn& fn) const;
  /// The bulk share of a node's mass that gets a field of its own.
  static constexpr Real kBulkMin = Real(1e-3);
  bool implicit_ = false;
  bool slotted_ = false;                                       ///< slots() ran since the last p2g
  std::vector<std::array<std::uint64_t, kBlockNodes>> group_;  ///< per combined grid block
  std::vector<std::uint64_t> slot_bits_;  ///< per combined grid block: slotted nodes
  /// Per combined grid block: nodes under a collider gate that slots() gave one velocity.
  std::vector<std::uint64_t> one_bits_;
  /// The relative velocities of the bodies in slots, and their slot (take_solution).
  std::vector<std::pair<Vec3*, int>> slot_r_;
  /// The groups of the bodies at a slotted node, as slots() reads them: the rule's (code),
  /// a shell's fold classes together, a sliver of bulk in the base group.
  static Union node_groups(std::uint64_t code, const std::vector<Body>& bodies, bool bulk);
  /// Node n of combined grid block g under a collider gate: each body keeps its own
  /// velocity, with the collider's condition applied to it where it is near the collider.
  /// Returns the colliders' work there beyond the node condition's (gate_work).
  double gate_collider_node(GridNode& nd, std::size_t g, int n, const Vec3& node_pos,
                            const ColliderGate& gate);
  std::vector<double> gate_block_work_;  ///< per combined grid block (before_g2p)
  double gate_work_ = 0;
};

}  // namespace shellmpm
