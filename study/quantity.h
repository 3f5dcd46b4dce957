// Quantities of interest read off a finished run (study/run_folder.h), named by a short
// path, for `shellmpm converge` and the study:
//   shell.NAME.lowest | highest             min / max height (y) of a shell's surface [m]
//   shell.NAME.centroid.x|y|z               mean of its surface vertices [m]
//   shell.NAME.vertex.I.x|y|z               one surface vertex (index of the control point) [m]
//   shell.NAME.max_displacement             largest vertex displacement since the run's first
//                                           frame [m] (a dent's depth, a sag)
//   bulk.centroid.x|y|z, bulk.max.x|y|z, bulk.min.x|y|z
//                                           over all bulk particles [m] (bulk.max.x: a run-out
//                                           front; bulk.max.y: a pile's height)
//   stats.KEY[.KEY]                         a number in the frame's stats.json object
//                                           (stats.kinetic_energy,
//                                           stats.integrity.max_collider_depth)
// A leading "max:" or "min:" takes the extreme over every frame of the run instead of the
// value at the measured frame (max:stats.integrity.max_collider_depth is the deepest
// penetration of the run).
#pragma once
#include <string>
#include <vector>

#include "study/run_folder.h"
#include "sim/scene/scene.h"

namespace shellmpm {

struct Quantity {
  enum class Source { Shell, Bulk, Stats };
  enum class What { Lowest, Highest, Centroid, Vertex, MaxDisplacement, Max, Min, Value };
  enum class Over { Frame, MaxOverFrames, MinOverFrames };
  std::string text;  ///< as the user wrote it
  Source source = Source::Stats;
  What what = What::Value;
  Over over = Over::Frame;
  std::string shell;                    ///< Source::Shell
  int axis = 1;                         ///< 0, 1, 2 for x, y, z
  int vertex = -1;                      ///< What::Vertex
  std::vector<std::string> stats_path;  ///< Source::Stats: keys below the frame object
  /// Whether the run must write a particle cache.
  bool needs_particles() const { return source == Source::Bulk; }
};

/// Parses `text` and checks it against the scene (the shell exists, the vertex index is in
/// range for procedural sheets, the scene has bulk sources for bulk quantities).
/// @param where the flag it came from, for messages ("--measure")
/// @throws UserError naming `where`, the text and what is wrong (with the known names).
Quantity parse_quantity(const std::string& text, const Scene& scene, const std::string& where);

/// The quantity's value in a run (at `frame`, or over all frames for max:/min:).
/// @throws std::runtime_error naming the file when the run lacks what it needs (a stats key
///         that is not there names stats.json and the key).
double evaluate_quantity(const Quantity& q, const RunFolder& run, int frame);

}  // namespace shellmpm
