// The step's stages in execution order, each switched on by its own rule from the scene
// (stage.h): a scene runs only the effects it calls for.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "sim/solver/stages/stage.h"

namespace shellmpm {

/// The stages this scene needs, in execution order.
std::vector<std::unique_ptr<Stage>> make_stages(const Scene& s);
/// Their names.
std::vector<std::string> stage_names(const Scene& s);

}  // namespace shellmpm
