// What the accuracy study measured for a quality preset, for `shellmpm check`: the preset's
// error on the reference problems nearest to a scene (shells in contact: the inclines and
// the drape; shells alone: the plate; sand: the column; elastic or snow bulk: the bar) and
// its cost relative to `production`, read from the study's results.json.
#pragma once
#include <string>
#include <vector>

#include "sim/scene/scene.h"

namespace shellmpm {

struct PresetMeasurement {
  std::string problem;  ///< reference problem name
  std::string error;    ///< "-1.2%" or "-0.0003 m"
  double cost_vs_production =
      0;  ///< this preset's cost / production's on that problem (0: unknown)
};

/// The reference problems that stand nearest to what the scene holds.
std::vector<std::string> nearest_problems(const Scene& scene);

/// The preset's measurements on `problems` from the study results at `results_json`.
/// Empty when the file is missing or holds no run of that preset.
std::vector<PresetMeasurement> preset_measurements(const std::string& results_json, Quality quality,
                                                   const std::vector<std::string>& problems);

}  // namespace shellmpm
