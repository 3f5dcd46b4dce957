// Accuracy presets: `shot.quality: draft | preview | production | final` sets the knobs
// that trade accuracy for time together, on the scene document before it is validated.
//  - Relative to the scene's own (nominal) values, always: the grid spacing shot.dx is
//    multiplied by the preset's factor, and the resolution of sheet and cylinder shells is
//    divided by it, so the mesh keeps its spacing relative to the grid. Meshes and spheres
//    keep their control mesh.
//  - Absolute, only where the scene (or --set) does not give the key: shot.cfl, the shell
//    materials' quadrature_inplane, quadrature_thickness and contact_samples, and the
//    sources' particles_per_cell.
// The values were chosen on the accuracy study's Pareto front (docs/accuracy.md, "Quality
// presets", which gives each preset's measured error and cost on every reference problem).
#pragma once
#include <optional>
#include <string>

#include "io/scene_document.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// One preset's settings.
struct QualityPreset {
  double dx_factor = 1;        ///< shot.dx multiplier (> 1: coarser)
  double cfl = 0.3;            ///< shot.cfl where not given
  int quadrature_inplane = 3;  ///< shell_materials[].quadrature_inplane where not given
  int quadrature_thickness = 3;
  int contact_samples = 1;
  double particles_per_cell = 8;  ///< sources[].particles_per_cell where not given
};

/// The settings of a preset.
QualityPreset quality_preset(Quality q);

namespace scenefile {

/// Applies the preset named by the document's shot.quality (if any, and if it is one of the
/// words; a bad value is left for the schema to report). Call after the --set overrides and
/// before validation. Values it writes carry the origin of shot.quality, so a range error
/// they cause points at the preset.
void apply_quality(DocNode& root);

}  // namespace scenefile
}  // namespace shellmpm
