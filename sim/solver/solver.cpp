#include "sim/solver/solver.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/core/parallel.h"
#include "sim/shell/preroll.h"
#include "sim/solver/body_energies.h"
#include "sim/solver/integrator_choice.h"
#include "sim/solver/stages/registry.h"
#include "sim/solver/stages/scene_rules.h"
#include "sim/solver/step_limits.h"

namespace shellmpm {
Solver::Solver(const Scene& scene, SolverOptions opt) {
  c_.scene = scene;
  resolve_integrator(c_.scene);  // a scene built in code; the CLI resolves auto on loading
  c_.opt = opt;
  const ShotSettings& s = c_.scene.shot;
  for (const MaterialDesc& m : c_.scene.materials) {
    c_.models.push_back(ConstitutiveModel::from_desc(m));
    c_.densities.push_back(static_cast<Real>(m.density));
  }
  c_.particles.keep_plastic = any_plastic_material(c_.scene);
  c_.grid.setup(s.dx, s.domain_min);
  for (int a = 0; a < 3; ++a)
    c_.domain_cells[a] = static_cast<int>(std::floor((s.domain_max[a] - s.domain_min[a]) / s.dx));
  for (const SourceDesc& src : c_.scene.sources) c_.samplers.emplace_back(src, s.dx, s.fps);
  for (const ColliderDesc& cd : c_.scene.colliders) c_.colliders.emplace_back(cd);
  for (const ShellDesc& sd : c_.scene.shells) {
    c_.shells.push_back(std::make_unique<ShellObject>(sd, c_.scene.shell_materials[sd.material],
                                                      build_shell_rest_mesh(sd)));
    c_.shell_dt = std::min(c_.shell_dt, c_.shells.back()->stable_dt(s.cfl));
  }
  c_.shell_forces.resize(c_.shells.size());
  setup_contact();
  // The point order is read by the shells' transfers and the implicit solve; the bulk
  // transfers and the collider reach walk the blocks' runs.
  c_.grid.keep_order = !c_.grid_shells.empty() || s.integrator == Integrator::Implicit;
  integrity_.setup(integrity_view(), s.dx);
  if (opt.fill_sources) {
    // Every source's points first, so the particle arrays are allocated once, exactly.
    std::vector<std::vector<Vec3d>> pts(c_.samplers.size());
    std::size_t total = 0;
    for (std::size_t i = 0; i < c_.samplers.size(); ++i) {
      if (c_.scene.sources[i].emit) continue;
      c_.samplers[i].fill([&](const Vec3d& p) { pts[i].push_back(p); });
      // By particle block: the first step's binning then finds a few runs of points per
      // block, as after every frame's reorder, not one every few points.
      // (A point off the grid sorts as at its edge: clamp_to_domain moves it in below.)
      auto key = [&](const Vec3d& p) {
        const Vec3 g = c_.grid.grid_coord(p.cast<Real>()).cwiseMax(Real(0.5)).cwiseMin(Real(1e6));
        return c_.grid.block_key(g);
      };
      std::sort(pts[i].begin(), pts[i].end(), [&](const Vec3d& a, const Vec3d& b) {
        const std::uint64_t ka = key(a), kb = key(b);
        if (ka != kb) return ka < kb;
        return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
      });
      total += pts[i].size();
    }
    c_.particles.reserve_more(total, true);
    for (std::size_t i = 0; i < c_.samplers.size(); ++i) {
      if (pts[i].empty()) continue;
      c_.add_particles_from(i, pts[i]);
      std::vector<Vec3d>().swap(pts[i]);
    }
    c_.clamp_to_domain();
  }
  for (auto& st : make_stages(c_.scene)) stages_.push_back({std::move(st), 0.0});
}

void Solver::setup_contact() {
  c_.contacts.resize(c_.shells.size());
  c_.grid_shells.clear();
  for (std::size_t i = 0; i < c_.shells.size(); ++i) {
    if (!shell_has_contact(c_.scene, i)) continue;
    const ShellMaterialDesc& m = c_.shells[i]->material();
    ContactParams cp;
    cp.kc = m.contact_stiffness.value_or(m.youngs_modulus);
    cp.gamma = m.contact_shear.value_or(cp.kc);
    cp.friction = m.friction;
    c_.contacts[i] = std::make_unique<ShellContact>(c_.shells[i]->basis(), c_.shells[i]->rest,
                                                    m.thickness, m.contact_samples, cp);
    c_.shell_dt =
        std::min(c_.shell_dt, shell_contact_stable_dt(m, c_.scene.shot.cfl, c_.scene.shot.dx));
    GridShell g;
    g.shell = c_.shells[i].get();
    g.contact = c_.contacts[i].get();
    c_.grid_shells.push_back(std::move(g));
  }
  c_.shell_table.build(c_.grid_shells);
  c_.shell_fields.setup(
      c_.grid,
      c_.scene.shot.shell_velocities == ShellVelocities::Shared ? 0 : c_.grid_shells.size(),
      !c_.scene.sources.empty(), c_.scene.shot.fold_fields);
  c_.shell_fields.set_implicit(c_.scene.shot.integrator == Integrator::Implicit &&
                               c_.scene.shot.shell_fields_in_solve);
  std::vector<Real> half;
  for (const GridShell& g : c_.grid_shells) {
    const ShellMaterialDesc& m = g.shell->material();
    half.push_back(static_cast<Real>(0.5 * m.contact_thickness.value_or(m.thickness)));
  }
  c_.shell_fields.set_contact_surfaces(c_.scene.shot.contact_at == ContactAt::Surface,
                                       std::move(half));
}

std::vector<std::string> Solver::stage_names() const {
  std::vector<std::string> n;
  for (const Slot& s : stages_) n.emplace_back(s.stage->name());
  return n;
}

IntegrityView Solver::integrity_view() const {
  IntegrityView v;
  v.bulk = &c_.particles;
  for (const GridShell& g : c_.grid_shells) {
    v.shells.push_back(g.shell);
    const ShellMaterialDesc& m = g.shell->material();
    v.half_thickness.push_back(0.5 * m.contact_thickness.value_or(m.thickness));
  }
  v.colliders = &c_.colliders;
  v.serial = c_.opt.serial;
  return v;
}

IntegrityReport Solver::integrity_snapshot() {
  return integrity_.snapshot(integrity_view());
}

double Solver::stable_dt() const {
  return stable_dt(nullptr);
}

double Solver::stable_dt(double* vmax_out) const {
  const ShotSettings& s = c_.scene.shot;
  // Implicit: no wave-speed bound, only motion (cfl dx / max speed) and dt_max.
  const bool implicit = s.integrator == Integrator::Implicit;
  double dt = implicit ? s.dt_max : std::min(s.dt_max, c_.shell_dt);
  const std::size_t n = c_.particles.size();
  double vmax = 0, cmax = 0;
  if (n > 0) {
    // Per chunk: the largest speed (NaN if one is not finite) and wave speed.
    const std::vector<std::array<double, 2>> parts = chunk_parts(
        n, kParticleGrain, c_.opt.serial, std::array<double, 2>{0.0, 0.0},
        [&](std::size_t b, std::size_t e, std::array<double, 2>& part) {
          // Squared wave speeds, from the deformed state F (a material stiffens or softens
          // as it is squeezed); one square root per chunk.
          Real v2 = 0, c2 = 0;
          bool finite = true;
          for (std::size_t p = b; p < e; ++p) {
            const Real sq = c_.particles.v[p].squaredNorm();
            finite = finite && std::isfinite(sq);
            v2 = std::max(v2, sq);
            const auto mat = c_.particles.material_of(p);
            c2 = std::max(c2, c_.models[mat].wave_modulus(
                                  c_.particles.F[p],
                                  c_.particles.has_plastic() ? c_.particles.plastic[p] : Real(1)) /
                                  c_.densities[mat]);
          }
          part[0] = finite ? std::sqrt(static_cast<double>(v2))
                           : std::numeric_limits<double>::quiet_NaN();
          part[1] = std::sqrt(c2);
        });
    for (const std::array<double, 2>& part : parts)
      if (!std::isfinite(part[0])) return part[0];  // diverged
    for (const std::array<double, 2>& part : parts) {
      vmax = std::max(vmax, part[0]);
      cmax = std::max(cmax, part[1]);
    }
  }
  for (const GridShell& g : c_.grid_shells)
    for (const Vec3& v : g.shell->v) {
      const double sp = static_cast<double>(v.norm());
      if (!std::isfinite(sp)) return sp;  // diverged
      vmax = std::max(vmax, sp);
    }
  if (implicit)
    for (std::size_t i = 0; i < c_.shells.size(); ++i) {
      if (c_.contacts[i]) continue;
      for (const Vec3& v : c_.shells[i]->v) {
        const double sp = static_cast<double>(v.norm());
        if (!std::isfinite(sp)) return sp;  // diverged
        vmax = std::max(vmax, sp);
      }
    }
  for (const Collider& c : c_.colliders) vmax = std::max(vmax, c.max_speed(c_.time));
  if (vmax_out) *vmax_out = vmax;
  if (vmax > 0) dt = std::min(dt, s.cfl * s.dx / vmax);
  if (cmax > 0 && !implicit) dt = std::min(dt, s.cfl * s.dx / cmax);
  return dt;
}

double Solver::checked_stable_dt(double remaining, double* vmax) const {
  const double dt = stable_dt(vmax);
  if (!std::isfinite(dt)) {
    std::ostringstream os;
    os << "at t = " << c_.time << " s the simulation diverged (a velocity is not finite); "
       << "try a smaller shot.cfl, or a stiffer contact or smaller dx for fast contact";
    throw SimulationError(os.str());
  }
  if (dt < c_.scene.shot.dt_min && remaining > c_.scene.shot.dt_min) {
    std::ostringstream os;
    os << "at t = " << c_.time << " s the stable step " << dt
       << " s is below shot.dt_min = " << c_.scene.shot.dt_min << " s, "
       << describe_step_limits(step_limits(*this), c_.scene.shot.dt_min);
    throw SimulationError(os.str());
  }
  return dt;
}

void Solver::reorder_particles() {
  // By grid block, once per frame, for memory locality.
  if (c_.particles.size() == 0) return;
  // The sort order without grid blocks: the reorder's peak is the particles and one index
  // each (the grid's nodes are freed), then the grid is binned again as it was (the
  // frame's statistics count its blocks).
  c_.grid.bin_for_sort(c_.particles.x, c_.opt.serial);
  c_.particles.permute(c_.grid.order());
  c_.grid.release_order();
  c_.grid.bin(c_.particles.x, c_.opt.serial);
  ++c_.particle_epoch;
}

double step_end_time(double time, double dt, double t_end, bool last) {
  return last || t_end - (time + dt) <= kTimeSnap * dt ? t_end : time + dt;
}

FrameStats Solver::advance_to(double t_end, const SubstepCallback& cb) {
  using clock = std::chrono::steady_clock;
  const auto wall0 = clock::now();
  for (Slot& st : stages_) st.seconds = 0;
  c_.guard_frame = ShellGuardStats{};
  c_.implicit_frame = ImplicitStats{};
  c_.energy_supplied = 0;
  c_.shell_dissipated.assign(c_.shells.size(), 0.0);
  if (energy_start_.empty()) energy_start_ = body_energies(c_);
  ++c_.advance_epoch;
  FrameStats fs;
  fs.dt_min = std::numeric_limits<double>::infinity();
  // Integrity: the side checks during the frame, and its first and last checks (the
  // frame-end ones include the crossing search over every shell's limit mesh).
  double dt_seconds = 0, integrity_seconds = 0, integrity_frame_seconds = 0;
  const auto i0 = clock::now();
  const IntegrityView view = integrity_view();
  integrity_.begin_frame(view);
  integrity_frame_seconds += std::chrono::duration<double>(clock::now() - i0).count();
  // Relative motion since the last integrity side check, bounded by twice the largest
  // speed times the time elapsed: a check whenever it could reach dx (integrity_monitor.h).
  double moved = 0;
  while (c_.time < t_end) {
    const auto d0 = clock::now();
    double vmax = 0;
    const double remaining = t_end - c_.time;
    double dt = checked_stable_dt(remaining, &vmax);
    const double steps = std::max(1.0, std::ceil(remaining / dt - 1e-9));
    dt = remaining / steps;
    dt_seconds += std::chrono::duration<double>(clock::now() - d0).count();
    c_.dt = dt;
    if (trace_.on()) trace_.begin(c_);
    for (Slot& st : stages_) {
      const auto t0 = clock::now();
      st.stage->run(c_);
      st.seconds += std::chrono::duration<double>(clock::now() - t0).count();
      if (trace_.on()) trace_.after(c_, st.stage->name());
    }
    // An implicit stage may have taken a shorter step than asked (a retry at half the step).
    const bool shortened = c_.dt < dt;
    dt = c_.dt;
    c_.time = step_end_time(c_.time, dt, t_end, steps == 1.0 && !shortened);
    fs.substeps++;
    fs.dt_min = std::min(fs.dt_min, dt);
    fs.dt_max = std::max(fs.dt_max, dt);
    moved += 2.0 * vmax * dt;
    if (moved >= c_.grid.dx() && c_.time < t_end) {
      const auto c0 = clock::now();
      integrity_.track(view);
      integrity_seconds += std::chrono::duration<double>(clock::now() - c0).count();
      moved = 0;
    }
    if (cb) cb(fs.substeps, dt, c_.time);
  }
  {
    const auto c0 = clock::now();
    fs.integrity = integrity_.end_frame(view);
    integrity_frame_seconds += std::chrono::duration<double>(clock::now() - c0).count();
  }
  if (fs.substeps == 0) fs.dt_min = 0;
  const auto r0 = clock::now();
  reorder_particles();
  const double reorder_seconds = std::chrono::duration<double>(clock::now() - r0).count();
  fs.time = c_.time;
  const auto m0 = clock::now();
  measure(fs);
  fs.energy = audit_energy_frame(fs);
  const double measure_seconds = std::chrono::duration<double>(clock::now() - m0).count();
  fs.implicit = c_.scene.shot.integrator == Integrator::Implicit;
  fs.implicit_stats = c_.implicit_frame;
  if (fs.implicit) fs.implicit_stats.steps = fs.substeps;
  for (const Slot& st : stages_)
    fs.stage_seconds.emplace_back(std::string(st.stage->name()), st.seconds);
  if (!stages_.empty()) {
    fs.stage_seconds.emplace_back("dt", dt_seconds);
    fs.stage_seconds.emplace_back("reorder", reorder_seconds);
    fs.stage_seconds.emplace_back("frame_stats", measure_seconds);
    if (integrity_.active()) {
      fs.stage_seconds.emplace_back("integrity", integrity_seconds);
      fs.stage_seconds.emplace_back("integrity_frame", integrity_frame_seconds);
    }
  }
  fs.wall_seconds = std::chrono::duration<double>(clock::now() - wall0).count();
  return fs;
}

void Solver::measure(FrameStats& s) const {
  const ParticleSet& p = c_.particles;
  const std::size_t n = p.size();
  s.particles = n;
  s.grid_blocks = c_.grid.num_grid_blocks();
  struct Acc {
    double vmax = 0;
    Vec3d mom = Vec3d::Zero();
    Acc& operator+=(const Acc& o) {
      mom += o.mom;
      vmax = std::max(vmax, o.vmax);
      return *this;
    }
  };
  const Acc total = ordered_reduce(n, kParticleGrain, c_.opt.serial, Acc{}, [&](std::size_t i) {
    Acc a;
    const double m = static_cast<double>(p.volume_of(i)) * c_.densities[p.material_of(i)];
    const Vec3d v = p.v[i].cast<double>();
    a.mom = m * v;
    a.vmax = v.norm();
    return a;
  });
  s.bodies = body_energies(c_);
  for (const BodyEnergy& b : s.bodies) {
    if (b.shell) {
      s.shell_kinetic_energy += b.kinetic;
      s.shell_membrane_energy += b.membrane;
      s.shell_bending_energy += b.bending;
      s.contact_energy += b.stored - b.membrane - b.bending;
    } else {
      s.kinetic_energy += b.kinetic;
      s.elastic_energy += b.stored;
      s.mass += b.mass;
    }
  }
  for (const auto& sh : c_.shells) {
    s.shell_points += sh->size();
    s.shell_max_strain = std::max(s.shell_max_strain, sh->max_strain());
  }
  s.shell_plastic_work = c_.plastic_work;
  for (std::size_t i = 0; i < c_.shells.size(); ++i) {
    const ShellObject& sh = *c_.shells[i];
    for (std::size_t j = 0; j < sh.size(); ++j)
      s.shell_momentum += static_cast<double>(sh.mass[j]) * sh.v[j].cast<double>();
    if (c_.contacts[i]) s.contact_particles += c_.contacts[i]->num_sites();
  }
  s.contact_compressed = c_.contact_step.compressed;
  s.contact_sliding = c_.contact_step.sliding;
  s.contact_nodes = c_.shell_fields.met_nodes();
  s.friction_work = c_.friction_work;
  s.guard_pairs = c_.guard_frame.pairs;
  s.guard_impulses = c_.guard_frame.impulses;
  s.guard_zoned = c_.guard_frame.zoned;
  s.guard_unresolved = c_.guard_frame.unresolved;
  s.momentum = total.mom;
  s.max_speed = total.vmax;
}

EnergyAudit Solver::audit_energy_frame(FrameStats& fs) {
  const std::size_t nm = c_.scene.materials.size();
  std::vector<double> dissipated(nm, 0.0);
  dissipated.insert(dissipated.end(), c_.shell_dissipated.begin(), c_.shell_dissipated.end());
  double mass = 0;
  for (const BodyEnergy& b : fs.bodies) mass += b.mass;
  const double floor = kEnergyFloor * mass * kStandardGravity * c_.scene.shot.dx;
  EnergyAudit a = audit_energy(energy_start_, fs.bodies, dissipated, c_.energy_supplied, floor);
  energy_start_ = fs.bodies;
  if (a.failed() && c_.scene.shot.on_energy_gain != ShotSettings::OnEnergyGain::Ignore) {
    IntegrityEvent e;
    e.kind = IntegrityEvent::Kind::EnergyGain;
    e.object = a.object;
    e.value = a.excess;
    std::ostringstream os;
    os.precision(3);
    os << "start " << a.start << " J, end " << a.end << " J, dissipated " << a.dissipated
       << " J, supplied " << a.supplied << " J";
    e.other = os.str();
    fs.integrity.events.push_back(e);  // after the failures, with the warnings
    fs.integrity.energy_gain = true;
    fs.integrity.active = true;
    fs.integrity.dx = c_.scene.shot.dx;
  }
  return a;
}

int Solver::preroll(const PrerollSettings& p) {
  if (c_.shells.empty()) return 0;
  const int steps =
      settle_shells(c_.shells, c_.scene.shot.gravity, c_.time, c_.shell_dt, p, c_.opt.serial);
  // The settled shape is the contact particles' new reference: unit normal columns, no
  // APIC velocity field (else the sag would read as compression).
  for (std::size_t i = 0; i < c_.shells.size(); ++i)
    if (c_.contacts[i]) c_.contacts[i]->reset(c_.shells[i]->x.data(), c_.opt.serial);
  return steps;
}

}  // namespace shellmpm
