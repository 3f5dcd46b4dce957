// What the integrity monitor found in one frame (sim/integrity/integrity_monitor.h):
// counts that are zero when the physics held, and one event per object that failed.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

struct IntegrityEvent {
  enum class Kind {
    BulkThroughShell,   ///< bulk particles crossed `object` (a shell) in this frame
    ShellThroughShell,  ///< control-mesh limit points of `other` crossed shell `object`
    ShellsIntersect,    ///< edges of `other` pass through triangles of `object` (frame end)
    SelfIntersect,      ///< edges of `object` pass through its own triangles (frame end)
    InsideCollider,     ///< points deeper than the limit inside collider `object`
    NonFinite,          ///< non-finite positions or velocities (`object`: bulk or a shell)
    StretchedMesh,      ///< a warning, not a failure: edges of shell `object` longer than
                        ///< 2 dx, where contact can leak between its control points
    EnergyGain,         ///< a warning (or a stop, shot.on_energy_gain): the frame gained
                        ///< energy nothing supplied (energy_audit.h); `object` gained
                        ///< most, `value` the excess [J]
  };
  Kind kind = Kind::BulkThroughShell;
  std::string object;  ///< the shell or collider concerned
  std::string other;   ///< the other shell, if any
  std::size_t count = 0;
  double value = 0;      ///< InsideCollider: deepest penetration [m]
  Vec3d where{0, 0, 0};  ///< a place where it happened (first crossing, deepest point)
};

/// Gaps between contact surfaces at the frame's end: each shell limit vertex within the
/// monitor's band (2 dx) of another body counts the gap to its nearest other surface once,
/// under that surface's kind. A gap is the distance between the surfaces (a shell's limit
/// surface offset by half its contact thickness; a bulk particle's volume, a sphere of half
/// its spacing; a collider's level set); negative where they overlap.
struct GapSummary {
  std::size_t count = 0;  ///< points within the band
  double min = 0;         ///< smallest gap [m]
  double median = 0;      ///< median gap [m]
};

/// One frame's integrity counts (all zero when nothing went wrong).
struct IntegrityReport {
  bool active = false;                    ///< false: the scene has nothing the monitor checks
  int checks = 0;                         ///< side checks made during the frame
  std::size_t bulk_crossings = 0;         ///< bulk particles that crossed a shell
  std::size_t shell_point_crossings = 0;  ///< shell points that crossed another shell
  std::size_t shell_crossing_edges = 0;   ///< edges through another shell at frame end
  std::size_t self_crossing_edges = 0;    ///< edges through their own shell at frame end
  std::size_t collider_penetrations = 0;  ///< points deeper than the limit in a collider
  double max_collider_depth = 0;          ///< deepest point inside any collider [m]
  double collider_limit = 0;              ///< the depth limit used (0.5 dx) [m]
  std::size_t non_finite = 0;             ///< non-finite positions or velocities
  bool energy_gain = false;  ///< the energy audit failed (energy_audit.h; shot.on_energy_gain)
  std::size_t stretched_edges = 0;     ///< contact-shell edges longer than 2 dx (a warning)
  double max_edge = 0;                 ///< longest contact-shell limit-mesh edge [m]
  double dx = 0;                       ///< grid spacing [m] (gaps are also written in cells)
  GapSummary shell_shell;              ///< shell vertices against other shells
  GapSummary shell_bulk;               ///< bulk particles against shells
  GapSummary shell_collider;           ///< shell vertices against colliders
  std::vector<IntegrityEvent> events;  ///< failures, then warnings

  bool failed() const {
    return bulk_crossings + shell_point_crossings + shell_crossing_edges + self_crossing_edges +
               collider_penetrations + non_finite >
           0;
  }
};

/// One line per event, e.g. "frame 4: 1600 bulk particles crossed shell 'film' (first at
/// (0.01, -0.02, 0.03))".
std::vector<std::string> describe_integrity(const IntegrityReport& r, int frame, double dx);

}  // namespace shellmpm
