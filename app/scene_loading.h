// Reading a scene for a subcommand: parse, apply command-line options, load meshes.
#pragma once
#include <cstdint>

#include "app/commands.h"
#include "sim/scene/scene.h"

namespace shellmpm {

struct LoadedScene {
  Scene scene;
  std::uint64_t fingerprint = 0;  ///< scene text and overrides
};

/// Parses the scene (with --set overrides) and builds mesh level sets. `frames`
/// ("A-B" or "A", may be empty) and `output` replace the scene's values.
LoadedScene load_scene_for_cli(const CommonArgs& a, const std::string& frames,
                               const std::string& output);

}  // namespace shellmpm
