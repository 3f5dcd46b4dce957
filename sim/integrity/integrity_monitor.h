// The integrity monitor: finds wrong physics that the step loop itself cannot see, so
// that no run ends with a finished-looking cache and wrong results (issue 10).
//
// What it checks, per frame:
// - Bulk particles through a shell. Every point within `band` = 2 dx of a contact
//   shell's limit surface (Loop limit positions of the control vertices, the mesh the
//   shell writes at refine 0) records which side it is on: the sign of (x - c) . n, c the
//   closest point and n the interpolated vertex normal there. A point that is next seen
//   on the other side of the same shell has crossed it. Checks run whenever the
//   relative motion since the last one could reach dx (twice the largest particle,
//   shell or collider speed times the time elapsed), so no point can cross the band
//   unseen: it is within the band at both checks around its crossing. Points whose
//   closest point is within 2 dx of the shell's boundary (rest distance) are not
//   judged (they may have gone round the rim), nor are those within 1e-3 dx of the
//   surface (their side is round-off); leaving the band forgets the side.
// - Shell points through another shell: the same test for the limit vertices of every
//   contact shell against every other contact shell.
// - Shells crossing each other and themselves at the frame's end: edges of one limit
//   mesh that pass through a triangle of another, or of the same one (triangles sharing
//   a vertex with the edge excepted). This finds folds and twists that cross.
// - Colliders: bulk particles and shell limit vertices deeper than 0.5 dx inside one.
// - Non-finite positions or velocities.
// - The gaps between contact surfaces (GapSummary): a report, not a failure, so a user can
//   check that bodies rest at their real distance.
// Side records live only within a frame (a frame starts by recording every point), so
// a resumed run reports exactly what an uninterrupted one does.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/integrity/integrity_report.h"
#include "sim/math/triangle_queries.h"
#include "sim/mpm/particles.h"
#include "sim/shell/limit_mesh.h"
#include "sim/shell/shell_object.h"

namespace shellmpm {

/// What the monitor looks at (all owned by the solver).
struct IntegrityView {
  const ParticleSet* bulk = nullptr;
  std::vector<const ShellObject*> shells;  ///< shells with contact (on the grid)
  std::vector<double> half_thickness;      ///< per shell: half its contact thickness [m]
  const std::vector<Collider>* colliders = nullptr;
  bool serial = false;
};

class IntegrityMonitor {
 public:
  /// dx: grid spacing [m]. The shells' topology is fixed from here on.
  void setup(const IntegrityView& view, double dx);
  /// Whether there is anything to check (a contact shell, or a collider and particles).
  bool active() const { return active_; }
  /// Starts a frame: forgets sides and records them for the current state.
  void begin_frame(const IntegrityView& view);
  /// Compares sides with the last records (called during the frame, see above).
  void track(const IntegrityView& view);
  /// Ends the frame: a last side check plus the frame-end checks; returns the counts.
  IntegrityReport end_frame(const IntegrityView& view);
  /// Frame-end checks only, for a state that was not advanced (frame 1).
  IntegrityReport snapshot(const IntegrityView& view);
  double band() const { return band_; }

 private:
  struct ShellGeom {
    std::unique_ptr<LimitMesh> limit;
    std::vector<double> rim;                 ///< rest distance of each vertex to the boundary
    std::vector<std::pair<int, int>> edges;  ///< unique edges
    std::vector<Vec3d> pos, nrm;             ///< current limit positions and normals
    TriangleGrid grid;
  };
  enum class Side : std::int8_t { Far = 0, Minus = -1, Plus = 1, Rim = 2, Dead = 3 };
  struct Hit {
    int shell = -1;
    Side side = Side::Far;
  };
  void refresh(const IntegrityView& view);
  Hit side_of(const Vec3d& x, int exclude) const;
  /// Tracked point i: shell limit vertices first (s: the shell, advanced from its value
  /// as i grows), then the bulk particles.
  Vec3d point(const IntegrityView& view, std::size_t i, std::size_t& s) const;
  /// A side check of every point (record_only: the frame's first); false when there was
  /// nothing to compare and the limit surface was not refreshed.
  bool compare(const IntegrityView& view, bool record_only);
  void frame_end_checks(const IntegrityView& view, IntegrityReport& r) const;
  void check_non_finite(const IntegrityView& view, IntegrityReport& r) const;
  void check_crossings(const IntegrityView& view, IntegrityReport& r) const;
  void check_stretched(IntegrityReport& r, std::vector<IntegrityEvent>& warnings) const;
  void check_collider(const IntegrityView& view, const Collider& c, IntegrityReport& r) const;
  void measure_gaps(const IntegrityView& view, IntegrityReport& r) const;
  /// The nearest point of a shell other than `exclude` within the band: its distance [m]
  /// and shell, or shell -1.
  std::pair<double, int> nearest_shell(const Vec3d& x, int exclude) const;
  const std::vector<Eigen::Vector3i>& tris(std::size_t s) const {
    return shells_[s].limit->triangles();
  }

  bool active_ = false;
  double dx_ = 0, band_ = 0;
  std::vector<ShellGeom> shells_;
  std::vector<std::string> names_;
  // Side records: bulk particles, then every shell's limit vertices.
  std::vector<std::int16_t> rec_shell_;
  std::vector<std::int8_t> rec_side_;
  std::vector<std::size_t> vertex_offset_;
  // This frame's crossings: per shell crossed, by bulk and by other shells' points.
  std::vector<std::size_t> bulk_cross_, point_cross_;
  std::vector<Vec3d> bulk_where_, point_where_;
  std::vector<int> point_from_;  ///< a shell whose points crossed (for messages)
  int checks_ = 0;
};

}  // namespace shellmpm
