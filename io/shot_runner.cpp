#include "io/shot_runner.h"

#include <filesystem>
#include <sstream>

#include "io/atomic_file.h"
#include "io/checkpoint.h"
#include "io/density_vdb.h"
#include "io/particle_cache.h"
#include "io/shell_mesh_writer.h"
#include "io/stats_file.h"
#include "io/user_error.h"
#include "sim/solver/solver.h"

namespace shellmpm {
namespace {

void write_frame_outputs(const Scene& scene, const Solver& solver, int frame) {
  const OutputSettings& o = scene.output;
  const ParticleSet& p = solver.particles();
  if (o.density && !scene.sources.empty()) {
    DensityInput in{p.x.data(), p.v.data(), p.volume.data(), p.size()};
    VdbOptions vo;
    vo.voxel_size = o.voxel_size > 0 ? o.voxel_size : scene.shot.dx;
    vo.velocity = o.velocity;
    vo.half_float = o.half_float;
    vo.frame = frame;
    vo.time = solver.time();
    vo.units = scene.shot.units;
    write_density_vdb(frame_path(o.directory, o.density_pattern, frame), in, vo);
  }
  if (o.particles && !scene.sources.empty())
    write_particle_ply(frame_path(o.directory, o.particles_pattern, frame), p);
  const MeshFormat format = parse_mesh_format(o.shell_format);
  std::vector<Vec3> pos, nrm;
  for (const auto& sh : solver.shells()) {
    if (!sh->desc().write_mesh) continue;
    sh->output_mesh(pos, nrm);
    const LimitMesh& lm = sh->limit_mesh();
    MeshFrame mf;
    mf.positions = pos.data();
    mf.num_vertices = pos.size();
    mf.normals = nrm.data();
    mf.uvs = lm.uvs().empty() ? nullptr : lm.uvs().data();
    mf.triangles = lm.triangles().data();
    mf.num_triangles = lm.triangles().size();
    mf.frame = frame;
    mf.time = solver.time();
    mf.name = sh->name();
    std::string pattern = o.shell_pattern;
    const auto at = pattern.find("{name}");
    if (at != std::string::npos) pattern.replace(at, 6, sh->name());
    write_shell_mesh(frame_path(o.directory, pattern, frame), mf, format);
  }
}

}  // namespace

int run_shot(const Scene& scene, const RunOptions& opt) {
  const ShotSettings& shot = scene.shot;
  const OutputSettings& out = scene.output;
  auto log = [&](const std::string& m) {
    if (opt.log) opt.log(m);
  };
  std::error_code ec;
  std::filesystem::create_directories(out.directory, ec);
  if (ec || !std::filesystem::is_directory(out.directory))
    throw UserError(scene.path, 0, "output.directory",
                    "cannot create output directory '" + out.directory + "': " + ec.message());

  SolverOptions so;
  so.serial = opt.serial;
  int first_frame = 1;
  Checkpoint ck;
  bool resumed = false;
  if (opt.resume) {
    const std::string path = latest_checkpoint(out.directory, shot.frame_end);
    if (path.empty()) {
      log("no checkpoint in '" + out.directory + "': starting from frame 1");
    } else {
      ck = read_checkpoint(path);
      if (ck.scene_fingerprint != opt.scene_fingerprint)
        throw UserError(path, 0, "",
                        "checkpoint was written for a different scene or --set overrides; "
                        "delete it or run without --resume");
      so.fill_sources = false;
      resumed = true;
      first_frame = ck.frame + 1;
      log("resuming after frame " + std::to_string(ck.frame) + " from '" + path + "'");
    }
  }
  Solver solver(scene, so);
  nlohmann::json header;
  header["scene"] = scene.path;
  header["dx"] = shot.dx;
  header["fps"] = shot.fps;
  header["transfer"] = shot.transfer;
  header["stages"] = solver.stage_names();
  StatsFile stats(out.directory + "/" + out.stats_file, header);
  if (!resumed && scene.preroll.enabled) {
    const int steps = solver.preroll(scene.preroll);
    log("pre-roll settled the shells in " + std::to_string(steps) + " steps");
  }
  if (resumed) {
    restore_shells(solver, ck);
    solver.particles() = std::move(ck.particles);
    solver.set_time(ck.time);
    stats.set_frames(nlohmann::json::parse(ck.stats_json));
  }

  int written = 0;
  for (int frame = first_frame; frame <= shot.frame_end; ++frame) {
    const double t_end = frame_time(frame, shot.fps);
    FrameStats fs;
    if (frame == 1) {
      solver.measure(fs);  // frame 1 is the initial state
      fs.time = solver.time();
      fs.integrity = solver.integrity_snapshot();
    } else {
      fs = solver.advance_to(t_end, [&](int sub, double dt, double t) {
        if (opt.on_substep) opt.on_substep(frame, sub, dt, t, solver.particles().size());
      });
    }
    fs.frame = frame;
    if (!fs.integrity.events.empty()) {
      const std::vector<std::string> lines = describe_integrity(fs.integrity, frame, shot.dx);
      for (const std::string& l : lines)
        if (opt.warn) opt.warn(l);
      if (fs.integrity.failed() &&
          shot.on_integrity_failure == ShotSettings::OnIntegrityFailure::Stop) {
        // The frame's statistics are kept; its caches are not written (wrong physics).
        stats.add(fs);
        stats.write();
        throw SimulationError(lines.front() + " (shot.on_integrity_failure: stop)");
      }
    }
    if (frame >= shot.frame_start) {
      write_frame_outputs(scene, solver, frame);
      stats.add(fs);
      stats.write();
      ++written;
    }
    if (out.checkpoint_every > 0 && frame % out.checkpoint_every == 0) {
      Checkpoint c;
      c.scene_fingerprint = opt.scene_fingerprint;
      c.frame = frame;
      c.time = solver.time();
      c.particles = solver.particles();
      save_shells(solver, c);
      c.stats_json = stats.frames().dump();
      write_checkpoint(frame_path(out.directory, "checkpoint.####.bin", frame), c);
    }
    if (opt.on_frame) opt.on_frame(fs);
  }
  return written;
}

}  // namespace shellmpm
