#include "shot/shot_runner.h"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "io/atomic_file.h"
#include "io/checkpoint.h"
#include "io/density_vdb.h"
#include "io/particle_cache.h"
#include "io/shell_mesh_writer.h"
#include "io/stats_file.h"
#include "io/user_error.h"
#include "sim/scene/scene_words.h"
#include "sim/solver/solver.h"

namespace shellmpm {
namespace {

void write_frame_outputs(const Scene& scene, const Solver& solver, int frame) {
  const OutputSettings& o = scene.output;
  const ParticleSet& p = solver.particles();
  if (o.density && !scene.sources.empty()) {
    DensityInput in{p.x.data(), p.v.data(), p.kind_volume.data(), p.size(), p.kind.data()};
    VdbOptions vo;
    vo.voxel_size = o.voxel_size > 0 ? o.voxel_size : scene.shot.dx;
    vo.velocity = o.velocity;
    vo.half_float = o.half_float;
    vo.frame = frame;
    vo.time = solver.time();
    vo.units = scene.shot.units;
    vo.up_axis = o.up_axis;
    write_density_vdb(frame_path(o.directory, o.density_pattern, frame), in, vo);
  }
  if (o.particles && !scene.sources.empty())
    write_particle_ply(frame_path(o.directory, o.particles_pattern, frame), p, o.up_axis);
  const MeshFormat format = o.shell_format;
  std::vector<Vec3> pos, nrm, vel;
  for (const auto& sh : solver.shells()) {
    if (!sh->desc().write_mesh) continue;
    sh->output_mesh(pos, nrm);
    const LimitMesh& lm = sh->limit_mesh();
    MeshFrame mf;
    mf.positions = pos.data();
    mf.num_vertices = pos.size();
    mf.normals = nrm.data();
    mf.uvs = lm.uvs().empty() ? nullptr : lm.uvs().data();
    if (o.velocity) {
      sh->output_velocity(vel);
      mf.velocities = vel.data();
    }
    mf.triangles = lm.triangles().data();
    mf.num_triangles = lm.triangles().size();
    mf.frame = frame;
    mf.time = solver.time();
    mf.name = sh->name();
    mf.up_axis = o.up_axis;
    std::string pattern = o.shell_pattern;
    const auto at = pattern.find("{name}");
    if (at != std::string::npos) pattern.replace(at, 6, sh->name());
    write_shell_mesh(frame_path(o.directory, pattern, frame), mf, format);
  }
}

/// The folders a run writes into: the output directory and those the file patterns
/// name below it (a shell pattern "meshes/{name}.####.ply").
std::vector<std::string> output_folders(const Scene& scene) {
  const OutputSettings& o = scene.output;
  std::vector<std::string> patterns = {o.density_pattern, o.particles_pattern,
                                       scene.render.pattern};
  for (const ShellDesc& sh : scene.shells) {
    std::string pattern = o.shell_pattern;
    const auto at = pattern.find("{name}");
    if (at != std::string::npos) pattern.replace(at, 6, sh.name);
    patterns.push_back(pattern);
  }
  std::vector<std::string> files = {o.directory + "/" + o.stats_file};
  for (const std::string& p : patterns) {
    try {
      files.push_back(frame_path(o.directory, p, 1));
    } catch (const std::invalid_argument&) {
      // a pattern the writer would refuse names no folder
    }
  }
  std::vector<std::string> dirs = {o.directory};
  for (const std::string& f : files) {
    const std::string d = std::filesystem::path(f).parent_path().string();
    if (!d.empty() && std::find(dirs.begin(), dirs.end(), d) == dirs.end()) dirs.push_back(d);
  }
  return dirs;
}

/// The newest intact checkpoint in the output directory. Damaged ones are skipped with
/// a warning and listed in `resume_note`. Returns false when there is none at all.
bool find_resume_checkpoint(const Scene& scene, const RunOptions& opt, Checkpoint& ck,
                            std::string& path, nlohmann::json& resume_note) {
  const OutputSettings& out = scene.output;
  auto warn = [&](const std::string& m) {
    if (opt.warn) opt.warn(m);
  };
  std::vector<std::string> warnings;
  const std::vector<CheckpointFile> files =
      list_checkpoints(out.directory, scene.shot.frame_end, &warnings);
  for (const std::string& w : warnings) warn(w);
  if (files.empty()) return false;
  nlohmann::json damaged = nlohmann::json::array();
  std::string reasons;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const CheckpointFile& f = files[i];
    std::string why;
    try {
      ck = read_checkpoint(f.path);
      if (ck.frame == f.frame) {
        path = f.path;
        break;
      }
      why = f.path + ": holds frame " + std::to_string(ck.frame) + ", its name says " +
            std::to_string(f.frame);
    } catch (const CheckpointDamaged& e) {
      why = e.what();
    }
    warn(why + (i + 1 < files.size() ? "; trying an older checkpoint" : "; no older checkpoint"));
    damaged.push_back({{"file", f.path}, {"error", why}});
    reasons += "\n  " + why;
  }
  if (path.empty())
    throw UserError(out.directory, 0, "",
                    "no intact checkpoint to resume from (" + std::to_string(files.size()) +
                        " damaged):" + reasons +
                        "\ndelete them to start again from frame 1, or run without --resume");
  resume_note = {{"checkpoint", path}, {"frame", ck.frame}};
  if (!damaged.empty()) {
    resume_note["damaged"] = damaged;
    warn("resuming from the older checkpoint '" + path + "' (frame " + std::to_string(ck.frame) +
         "): " + std::to_string(damaged.size()) + " newer one(s) damaged");
  }
  return true;
}

Checkpoint capture(const Solver& solver, const StatsFile& stats, int frame, std::uint64_t fp) {
  Checkpoint c;
  c.scene_fingerprint = fp;
  c.frame = frame;
  c.time = solver.time();
  c.particles = solver.particles();
  save_shells(solver, c);
  c.stats_json = stats.frames().dump();
  return c;
}

/// Where a run starts: frame 1, or after the checkpoint `--resume` found.
struct ResumePoint {
  bool resumed = false;
  int first_frame = 1;
  Checkpoint ck;
  std::string ck_path;
  nlohmann::json note;  ///< stats.json's "resume" entry
};

/// With --resume: removes a killed run's temporary files and finds the checkpoint to go on
/// from (refusing one written for another scene).
ResumePoint find_resume_point(const Scene& scene, const RunOptions& opt,
                              const std::function<void(const std::string&)>& log) {
  ResumePoint rp;
  if (!opt.resume) return rp;
  int removed = 0;
  for (const std::string& d : output_folders(scene)) removed += remove_atomic_temps(d);
  if (removed > 0)
    log("removed " + std::to_string(removed) + " temporary file(s) left by a killed run");
  if (!find_resume_checkpoint(scene, opt, rp.ck, rp.ck_path, rp.note)) {
    log("no checkpoint in '" + scene.output.directory + "': starting from frame 1");
    return rp;
  }
  if (rp.ck.scene_fingerprint != opt.scene_fingerprint)
    throw UserError(rp.ck_path, 0, "",
                    "checkpoint was written for a different scene or --set overrides; "
                    "delete it or run without --resume");
  rp.resumed = true;
  rp.first_frame = rp.ck.frame + 1;
  log("resuming after frame " + std::to_string(rp.ck.frame) + " from '" + rp.ck_path + "'");
  return rp;
}

/// Simulates up to frame `frame` (frame 1: measures the initial state).
FrameStats simulate_frame(Solver& solver, int frame, const RunOptions& opt) {
  FrameStats fs;
  if (frame == 1) {
    solver.measure(fs);  // frame 1 is the initial state
    fs.time = solver.time();
    fs.integrity = solver.integrity_snapshot();
  } else {
    fs = solver.advance_to(frame_time(frame, solver.scene().shot.fps),
                           [&](int sub, double dt, double t) {
                             if (opt.on_substep)
                               opt.on_substep(frame, sub, dt, t, solver.particles().size());
                           });
  }
  fs.frame = frame;
  return fs;
}

/// Says what the frame's integrity check found; with on_integrity_failure: stop, a failed
/// frame ends the run (its statistics kept, its caches not written: wrong physics).
void report_integrity(const Scene& scene, const FrameStats& fs, const RunOptions& opt,
                      StatsFile& stats) {
  if (fs.integrity.events.empty()) return;
  const std::vector<std::string> lines = describe_integrity(fs.integrity, fs.frame, scene.shot.dx);
  for (const std::string& l : lines)
    if (opt.warn) opt.warn(l);
  if (fs.integrity.failed() &&
      scene.shot.on_integrity_failure == ShotSettings::OnIntegrityFailure::Stop) {
    stats.add(fs);
    stats.write();
    throw SimulationError(lines.front() + " (shot.on_integrity_failure: stop)");
  }
  if (fs.integrity.energy_gain &&
      scene.shot.on_energy_gain == ShotSettings::OnEnergyGain::Stop) {
    stats.add(fs);
    stats.write();
    for (const IntegrityEvent& e : fs.integrity.events)
      if (e.kind == IntegrityEvent::Kind::EnergyGain) {
        IntegrityReport one;
        one.events = {e};
        throw SimulationError(describe_integrity(one, fs.frame, scene.shot.dx).front() +
                              " (shot.on_energy_gain: stop)");
      }
  }
}

}  // namespace

RunResult run_shot(const Scene& scene, const RunOptions& opt) {
  const ShotSettings& shot = scene.shot;
  const OutputSettings& out = scene.output;
  auto log = [&](const std::string& m) {
    if (opt.log) opt.log(m);
  };
  auto stop = [&]() { return opt.stop_requested ? opt.stop_requested() : 0; };
  std::error_code ec;
  std::filesystem::create_directories(out.directory, ec);
  if (ec || !std::filesystem::is_directory(out.directory))
    throw UserError(scene.path, 0, "output.directory",
                    "cannot create output directory '" + out.directory + "': " + ec.message());
  ResumePoint rp = find_resume_point(scene, opt, log);
  SolverOptions so;
  so.serial = opt.serial;
  so.fill_sources = !rp.resumed;
  Solver solver(scene, so);
  nlohmann::json header;
  header["scene"] = scene.path;
  header["dx"] = shot.dx;
  header["fps"] = shot.fps;
  header["transfer"] = word_of(shot.transfer);
  header["stages"] = solver.stage_names();
  if (rp.resumed) header["resume"] = rp.note;
  StatsFile stats(out.directory + "/" + out.stats_file, header);
  if (!rp.resumed && scene.preroll.enabled) {
    const int steps = solver.preroll(scene.preroll);
    log("pre-roll settled the shells in " + std::to_string(steps) + " steps");
  }
  if (rp.resumed) {
    stats.set_frames(nlohmann::json::parse(rp.ck.stats_json));
    restore_checkpoint(solver, std::move(rp.ck), rp.ck_path);
  }

  RunResult result;
  for (int frame = rp.first_frame; frame <= shot.frame_end; ++frame) {
    const FrameStats fs = simulate_frame(solver, frame, opt);
    result.last_frame = frame;
    report_integrity(scene, fs, opt, stats);
    if (frame >= shot.frame_start) {
      write_frame_outputs(scene, solver, frame);
      stats.add(fs);
      stats.write();
      ++result.frames_written;
    }
    const int signal = stop();
    const bool periodic = out.checkpoint_every > 0 && frame % out.checkpoint_every == 0;
    if (periodic || (signal != 0 && frame < shot.frame_end)) {
      const std::string path = frame_path(out.directory, "checkpoint.####.bin", frame);
      write_checkpoint(path, capture(solver, stats, frame, opt.scene_fingerprint));
      if (signal != 0) result.checkpoint = path;
    }
    if (opt.on_frame) opt.on_frame(fs);
    if (signal != 0 && frame < shot.frame_end) {
      result.stopped_by = signal;
      break;
    }
  }
  return result;
}

}  // namespace shellmpm
