#include "io/stats_file.h"

#include "io/atomic_file.h"

namespace shellmpm {

nlohmann::json frame_stats_json(const FrameStats& s) {
  nlohmann::json j;
  j["frame"] = s.frame;
  j["time"] = s.time;
  j["substeps"] = s.substeps;
  j["dt_min"] = s.dt_min;
  j["dt_max"] = s.dt_max;
  j["particles"] = s.particles;
  j["grid_blocks"] = s.grid_blocks;
  j["mass"] = s.mass;
  j["kinetic_energy"] = s.kinetic_energy;
  j["elastic_energy"] = s.elastic_energy;
  j["momentum"] = {s.momentum.x(), s.momentum.y(), s.momentum.z()};
  j["max_speed"] = s.max_speed;
  if (s.shell_points > 0) {
    j["shell_points"] = s.shell_points;
    j["shell_kinetic_energy"] = s.shell_kinetic_energy;
    j["shell_membrane_energy"] = s.shell_membrane_energy;
    j["shell_bending_energy"] = s.shell_bending_energy;
    j["shell_plastic_work"] = s.shell_plastic_work;
    j["shell_max_strain"] = s.shell_max_strain;
    j["shell_momentum"] = {s.shell_momentum.x(), s.shell_momentum.y(), s.shell_momentum.z()};
  }
  if (s.contact_particles > 0) {
    j["contact_particles"] = s.contact_particles;
    j["contact_compressed"] = s.contact_compressed;
    j["contact_sliding"] = s.contact_sliding;
    j["contact_nodes"] = s.contact_nodes;
    j["contact_energy"] = s.contact_energy;
    j["friction_work"] = s.friction_work;
    j["guard_pairs"] = s.guard_pairs;
    j["guard_impulses"] = s.guard_impulses;
    j["guard_zoned"] = s.guard_zoned;
    j["guard_unresolved"] = s.guard_unresolved;
  }
  if (s.implicit) {
    const ImplicitStats& im = s.implicit_stats;
    nlohmann::json j_im;
    j_im["steps"] = im.steps;
    j_im["newton_iterations"] = im.newton_iterations;
    j_im["max_newton_iterations"] = im.max_newton_iterations;
    j_im["cg_iterations"] = im.cg_iterations;
    j_im["max_residual"] = im.max_residual;
    j_im["retries"] = im.retries;
    j["implicit"] = j_im;
  }
  if (!s.bodies.empty()) {
    // The energy balance (sim/integrity/energy_audit.h) and each body's energies.
    const EnergyAudit& a = s.energy;
    nlohmann::json je;
    je["judged"] = a.judged;
    if (!a.reason.empty()) je["not_judged_because"] = a.reason;
    if (a.judged) {
      je["start"] = a.start;
      je["end"] = a.end;
      je["dissipated"] = a.dissipated;
      je["supplied"] = a.supplied;
      je["excess"] = a.excess;
      je["tolerance"] = a.tolerance;
      je["ok"] = !a.failed();
    }
    nlohmann::json bulk = nlohmann::json::object(), shells = nlohmann::json::object();
    for (const BodyEnergy& b : s.bodies)
      (b.shell ? shells : bulk)[b.name] = {
          {"kinetic", b.kinetic}, {"stored", b.stored}, {"potential", b.potential}};
    je["materials"] = bulk;
    if (!shells.empty()) je["shells"] = shells;
    j["energy"] = je;
  }
  if (s.integrity.active) {
    const IntegrityReport& r = s.integrity;
    nlohmann::json in;
    in["checks"] = r.checks;
    in["bulk_crossings"] = r.bulk_crossings;
    in["shell_point_crossings"] = r.shell_point_crossings;
    in["shell_crossing_edges"] = r.shell_crossing_edges;
    in["self_crossing_edges"] = r.self_crossing_edges;
    in["collider_penetrations"] = r.collider_penetrations;
    in["max_collider_depth"] = r.max_collider_depth;
    in["collider_depth_limit"] = r.collider_limit;
    in["non_finite"] = r.non_finite;
    in["stretched_edges"] = r.stretched_edges;
    in["max_edge"] = r.max_edge;
    // Gaps between contact surfaces (integrity_report.h), in metres and in cells.
    const auto gaps = [&r](const GapSummary& g) {
      nlohmann::json jg;
      jg["points"] = g.count;
      if (g.count) {
        jg["min"] = g.min;
        jg["median"] = g.median;
        if (r.dx > 0) {
          jg["min_dx"] = g.min / r.dx;
          jg["median_dx"] = g.median / r.dx;
        }
      }
      return jg;
    };
    in["gaps"] = {{"shell_shell", gaps(r.shell_shell)},
                  {"shell_bulk", gaps(r.shell_bulk)},
                  {"shell_collider", gaps(r.shell_collider)}};
    nlohmann::json ev = nlohmann::json::array();
    for (const IntegrityEvent& e : r.events) {
      static const char* kinds[] = {"bulk_through_shell", "shell_through_shell", "shells_intersect",
                                    "self_intersect",     "inside_collider",     "non_finite",
                                    "stretched_mesh",     "energy_gain"};
      nlohmann::json je;
      je["kind"] = kinds[static_cast<int>(e.kind)];
      je["object"] = e.object;
      if (!e.other.empty()) je["other"] = e.other;
      je["count"] = e.count;
      if (e.kind == IntegrityEvent::Kind::InsideCollider) je["depth"] = e.value;
      if (e.kind == IntegrityEvent::Kind::StretchedMesh) je["longest_edge"] = e.value;
      if (e.kind == IntegrityEvent::Kind::EnergyGain) je["excess"] = e.value;
      je["where"] = {e.where.x(), e.where.y(), e.where.z()};
      ev.push_back(je);
    }
    in["events"] = ev;
    in["ok"] = !r.failed();
    j["integrity"] = in;
  }
  nlohmann::json wall = nlohmann::json::object();
  for (const auto& [name, sec] : s.stage_seconds) wall[name] = sec;
  wall["total"] = s.wall_seconds;
  j["wall"] = wall;
  return j;
}

StatsFile::StatsFile(std::string path, nlohmann::json header)
    : path_(std::move(path)), header_(std::move(header)) {}

void StatsFile::add(const FrameStats& s) {
  frames_.push_back(frame_stats_json(s));
}

void StatsFile::write() const {
  nlohmann::json j = header_;
  j["frames"] = frames_;
  write_text_atomic(path_, j.dump(1) + "\n");
}

}  // namespace shellmpm
