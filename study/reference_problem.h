// The accuracy study's reference problems: scenes in the project's own format
// (scenes/study/) whose answer is known from theory or experiment, each with the sweeps of
// settings that trade accuracy for time. docs/accuracy.md describes each one and its source.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "study/run_folder.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// One setting of a sweep: the scene as written plus these `--set` values.
struct StudySetting {
  std::string label;                   ///< short, for plots and tables ("n=16", "dx=0.01")
  std::vector<std::string> overrides;  ///< --set values
  double h = 0;                        ///< the resolution it stands for [m]; 0: not a refinement
};

/// Settings that vary one knob (or a group of keys that move together) with the rest fixed.
struct StudySweep {
  std::string name;    ///< "mesh resolution"
  std::string varied;  ///< the keys it changes, in words
  std::string held;    ///< what stays as the scene says
  bool refinement =
      false;  ///< settings run coarse to fine and carry h: a convergence order is fitted
  std::vector<StudySetting> settings;
};

struct ReferenceProblem {
  std::string name;              ///< "plate_simply_supported": also the scene file's stem
  std::string title;             ///< one line
  std::string quantity;          ///< what is measured, in words
  std::string unit;              ///< of the quantity
  std::string reference_source;  ///< the formula and where it comes from
  bool relative_error = true;    ///< false: the error is value - reference in `unit`
  bool needs_particles = false;  ///< the run writes a particle cache
  /// The reference value for the scene as run (with the setting's overrides applied).
  std::function<double(const Scene&)> reference;
  /// The measured value from the finished run.
  std::function<double(const RunFolder&, const Scene&)> measure;
  /// Why the finished run's measurement cannot be trusted ("" where it can): a flow that
  /// has not come to rest, say. Such runs are listed as doubtful with the reason, and
  /// left out of the fitted orders and the Pareto front (null: always trusted).
  std::function<std::string(const RunFolder&, const Scene&)> doubt;
  std::vector<StudySweep> sweeps;  ///< the first is the refinement shown in the convergence plot
};

/// Every reference problem, in the order the study runs them.
std::vector<ReferenceProblem> reference_problems();

}  // namespace shellmpm
