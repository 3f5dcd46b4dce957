#include "app/scene_loading.h"

#include <fstream>
#include <sstream>

#include "app/frame_range.h"
#include "io/checkpoint.h"
#include "io/mesh_sdf.h"
#include "io/output_folders.h"
#include "io/scene_bounds.h"
#include "io/scene_reader.h"
#include "io/shell_assets.h"
#include "io/user_error.h"
#include "shot/available_memory.h"
#include "sim/solver/integrator_choice.h"

namespace shellmpm {

LoadedScene load_scene_for_cli(const CommonArgs& a, const std::string& frames,
                               const std::string& output) {
  LoadedScene ls;
  ls.scene = read_scene(a.scene, a.overrides);
  {
    std::ifstream f(a.scene, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    std::string text = ss.str();
    for (const std::string& o : a.overrides) text += "\n--set " + o;
    ls.fingerprint = fingerprint(text);
  }
  ShotSettings& shot = ls.scene.shot;
  if (!frames.empty()) {
    const FrameRange r = parse_frames_flag(frames);
    shot.frame_start = r.first;
    shot.frame_end = r.last;
  }
  if (!output.empty()) ls.scene.output.directory = output;
  if (a.threads >= 0) shot.threads = a.threads;
  load_scene_assets(ls.scene);
  load_shell_meshes(ls.scene);
  check_scene_bounds(ls.scene);
  resolve_integrator(ls.scene);
  ls.baseline = resident_bytes();
  return ls;
}

RunMemory estimate_memory(const LoadedScene& ls) {
  return estimate_run_memory(ls.scene, ls.baseline);
}

void prepare_run(const LoadedScene& ls, bool force, bool previews) {
  const RunMemory mem = estimate_memory(ls);
  const AvailableMemory avail = available_memory();
  const double need = mem.peak - mem.baseline;  // what the run adds to this process
  if (avail.known && need > avail.bytes && !force) {
    throw UserError(ls.scene.path, 0, "",
                    "the run needs about " + format_bytes(mem.peak) + " at its peak (" +
                        format_bytes(need) + " more than now), but only " +
                        format_bytes(avail.bytes) + " is available (" + avail.source +
                        "); `shellmpm check` shows where it goes. Lower the resolution "
                        "(a larger shot.dx, fewer particles_per_cell, a coarser shell mesh), "
                        "or run with --force to try anyway");
  }
  create_output_folders(ls.scene, previews);
}

}  // namespace shellmpm
