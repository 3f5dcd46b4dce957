#include "app/scene_loading.h"

#include <fstream>
#include <regex>
#include <sstream>

#include "io/checkpoint.h"
#include "io/mesh_sdf.h"
#include "io/scene_reader.h"
#include "io/user_error.h"

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
    std::smatch m;
    const std::regex re(R"((\d+)(?:-(\d+))?)");
    if (!std::regex_match(frames, m, re))
      throw UserError("--frames " + frames, 0, "", "expected A-B or A with frame numbers >= 1");
    const int a0 = std::stoi(m[1]);
    const int b0 = m[2].matched ? std::stoi(m[2]) : a0;
    if (a0 < 1 || b0 < a0)
      throw UserError("--frames " + frames, 0, "", "need 1 <= A <= B");
    shot.frame_start = a0;
    shot.frame_end = b0;
  }
  if (!output.empty()) ls.scene.output.directory = output;
  if (a.threads >= 0) shot.threads = a.threads;
  load_scene_assets(ls.scene);
  return ls;
}

}  // namespace shellmpm
