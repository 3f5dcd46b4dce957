#include "app/scene_loading.h"

#include <fstream>
#include <regex>
#include <sstream>

#include "io/checkpoint.h"
#include "io/mesh_sdf.h"
#include "io/scene_reader.h"
#include "io/shell_assets.h"
#include "io/user_error.h"
#include "sim/solver/source_sampler.h"

namespace shellmpm {

namespace {

// Particles outside the domain would be clamped onto its boundary: refuse such scenes.
void check_sources_inside_domain(const Scene& scene) {
  const ShotSettings& s = scene.shot;
  // Particles must stay one cell inside the domain (the grid stencil needs it).
  const Vec3d lo = s.domain_min.array() + s.dx, hi = s.domain_max.array() - s.dx;
  for (std::size_t i = 0; i < scene.sources.size(); ++i) {
    const SourceDesc& src = scene.sources[i];
    const std::string where =
        src.shape.where.empty() ? scene.path + ": sources[" + std::to_string(i) + "].shape"
                                : src.shape.where;
    Vec3d bad;
    bool outside = false;
    auto test = [&](const Vec3d& p) {
      if (!outside && ((p.array() < lo.array()).any() || (p.array() > hi.array()).any())) {
        outside = true;
        bad = p;
      }
    };
    if (src.emit) {
      const Aabb b = shape_bounds(src.shape);
      test(b.lo);
      test(b.hi);
    } else {
      SourceSampler(src, s.dx, s.fps).fill(test);
    }
    if (outside) {
      std::ostringstream os;
      os << "source reaches outside shot.domain (less one cell, dx = " << s.dx << "): e.g. ("
         << bad.x() << ", " << bad.y() << ", " << bad.z() << "); enlarge the domain or move the source";
      throw UserError(where, 0, "", os.str());
    }
  }
}

}  // namespace

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
  load_shell_meshes(ls.scene);
  check_sources_inside_domain(ls.scene);
  return ls;
}

}  // namespace shellmpm
