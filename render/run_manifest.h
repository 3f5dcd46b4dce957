// run.json: what `shellmpm run` leaves in its output directory so that `shellmpm render
// OUTDIR` can draw the caches later without the user naming the scene again: the scene
// file's text (a copy, so later edits of the file do not change old renders), its
// absolute path (for relative mesh paths and messages), the --set overrides and the
// frames written.
#pragma once
#include <string>
#include <vector>

#include "sim/scene/scene.h"

namespace shellmpm {

struct RunManifest {
  std::string scene_path;              ///< absolute path of the scene file at run time
  std::string scene_text;              ///< its contents at run time
  std::vector<std::string> overrides;  ///< --set values, in order
  int frame_start = 1, frame_end = 1;  ///< the frames the run writes
};

/// The manifest's path in `outdir`.
std::string run_manifest_path(const std::string& outdir);

/// Writes `outdir`/run.json atomically. @throws std::system_error on I/O failure.
void write_run_manifest(const std::string& outdir, const RunManifest& m);

/// Reads `outdir`/run.json. @throws UserError naming the file when it is missing (with a
/// hint: run the scene first, or pass --scene) or is not a shellmpm run manifest.
RunManifest read_run_manifest(const std::string& outdir);

/// The scene of a manifest, with `extra` overrides applied after the recorded ones;
/// scene.output.directory becomes `outdir`, shot.frames the recorded ones.
/// @throws UserError as read_scene does (messages name the scene file).
Scene scene_from_manifest(const RunManifest& m, const std::string& outdir,
                          const std::vector<std::string>& extra);

}  // namespace shellmpm
