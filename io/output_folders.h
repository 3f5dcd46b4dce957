// The folders a run writes into: output.directory and the sub-folders that the output file
// names (patterns, stats) hold, made once before the first frame.
#pragma once
#include <string>
#include <vector>

#include "sim/scene/scene.h"

namespace shellmpm {

/// One folder a run writes into and the scene key that asks for it.
struct OutputFolder {
  std::string path;  ///< output.directory, or output.directory/sub
  std::string key;   ///< "output.directory", "output.stats", "output.shell_pattern", ...
};

/// Every folder the run of `scene` writes into, output.directory first: the folder part of
/// each output file name that is written (density and particle caches when switched on,
/// stats, each shell's mesh with `{name}` replaced, previews when `previews`). The reader
/// has checked that the names are relative and keep their `#` run in the file name.
std::vector<OutputFolder> output_folders(const Scene& scene, bool previews);

/// Creates output_folders(scene, previews).
/// @throws UserError naming the scene file and the key when a folder cannot be made.
void create_output_folders(const Scene& scene, bool previews);

}  // namespace shellmpm
