// Reading a scene for a subcommand: parse, apply command-line options, load meshes, check
// the bounds that need them; before a run, the memory guard and the output folders.
#pragma once
#include <cstdint>

#include "app/commands.h"
#include "shot/run_memory.h"
#include "sim/scene/scene.h"

namespace shellmpm {

struct LoadedScene {
  Scene scene;
  std::uint64_t fingerprint = 0;  ///< scene text and overrides
  double baseline = 0;            ///< resident bytes of the process once the scene is loaded
};

/// Parses the scene (with --set overrides), builds mesh level sets and checks the bounds
/// that need the meshes (io/scene_bounds.h). `frames` ("A-B" or "A", may be empty) and
/// `output` replace the scene's values.
LoadedScene load_scene_for_cli(const CommonArgs& a, const std::string& frames,
                               const std::string& output);

/// The memory estimate of running the loaded scene (shot/run_memory.h).
RunMemory estimate_memory(const LoadedScene& ls);

/// Before `run` builds anything: refuses (UserError, exit 2) a scene whose estimated peak
/// exceeds the available memory (shot/available_memory.h), unless `force`; then creates the
/// output folders (io/output_folders.h). `previews`: preview images will be written.
void prepare_run(const LoadedScene& ls, bool force, bool previews);

}  // namespace shellmpm
