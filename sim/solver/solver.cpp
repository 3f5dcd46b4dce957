#include "sim/solver/solver.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <cmath>
#include <sstream>

#include "sim/collider/particle_projection.h"
#include "sim/core/check.h"
#include "sim/core/parallel.h"
#include "sim/mpm/transfer.h"
#include "sim/solver/step_limits.h"

namespace shellmpm {
namespace {

constexpr int kWallCells = 3;  // nodes this close to the domain boundary act as walls
constexpr std::size_t kParticleGrain = 4096;

// Sums f(i) over [0, n) in fixed chunks, combining chunk sums in order (deterministic).
template <class T, class F>
T ordered_sum(std::size_t n, bool serial, T zero, F f) {
  const std::size_t chunks = (n + kParticleGrain - 1) / kParticleGrain;
  std::vector<T> part(chunks, zero);
  parallel_for(
      n, kParticleGrain,
      [&](std::size_t b, std::size_t e) {
        T acc = zero;
        for (std::size_t i = b; i < e; ++i) acc += f(i);
        part[b / kParticleGrain] = acc;
      },
      serial);
  T total = zero;
  for (const T& p : part) total += p;
  return total;
}

}  // namespace

Solver::Solver(const Scene& scene, SolverOptions opt) : scene_(scene), opt_(opt) {
  const ShotSettings& s = scene_.shot;
  for (const MaterialDesc& m : scene_.materials) {
    models_.push_back(ConstitutiveModel::from_desc(m));
    densities_.push_back(static_cast<Real>(m.density));
    any_plastic_ = any_plastic_ || models_.back().has_plasticity();
  }
  particles_.keep_plastic = any_plastic_;
  grid_.setup(s.dx, s.domain_min);
  for (int a = 0; a < 3; ++a)
    domain_cells_[a] = static_cast<int>(std::floor((s.domain_max[a] - s.domain_min[a]) / s.dx));
  for (const SourceDesc& src : scene_.sources) {
    samplers_.emplace_back(src, s.dx, s.fps);
    any_emit_ = any_emit_ || src.emit;
  }
  for (const ColliderDesc& c : scene_.colliders) colliders_.emplace_back(c);
  for (const ShellDesc& sd : scene_.shells) {
    shells_.push_back(std::make_unique<ShellObject>(sd, scene_.shell_materials[sd.material],
                                                    build_shell_rest_mesh(sd)));
    shell_dt_ = std::min(shell_dt_, shells_.back()->stable_dt(s.cfl));
  }
  shell_forces_.resize(shells_.size());
  setup_contact();
  integrity_.setup(integrity_view(), s.dx);
  if (opt_.fill_sources) {
    for (std::size_t i = 0; i < samplers_.size(); ++i) {
      if (scene_.sources[i].emit) continue;
      std::vector<Vec3d> pts;
      samplers_[i].fill([&](const Vec3d& p) { pts.push_back(p); });
      add_particles_from(i, pts);
    }
    clamp_to_domain();
  }
  build_stages();
}

void Solver::add_particles_from(std::size_t i, const std::vector<Vec3d>& pts) {
  const SourceDesc& src = scene_.sources[i];
  const auto mat = static_cast<std::uint16_t>(src.material);
  const Real vol = static_cast<Real>(samplers_[i].particle_volume());
  const Vec3 vel = src.velocity.cast<Real>();
  const Real pl0 = models_[mat].initial_plastic();
  for (const Vec3d& p : pts) particles_.push_back(p.cast<Real>(), vel, vol, mat, pl0);
}

void Solver::setup_contact() {
  // Contact is on for a shell when asked, or (auto) when there is something to touch.
  const bool others = !scene_.colliders.empty() || !scene_.sources.empty() || shells_.size() > 1;
  contacts_.resize(shells_.size());
  grid_shells_.clear();
  for (std::size_t i = 0; i < shells_.size(); ++i) {
    const ShellDesc::Contact mode = shells_[i]->desc().contact;
    const bool on = mode == ShellDesc::Contact::On || (mode == ShellDesc::Contact::Auto && others);
    if (!on) continue;
    const ShellMaterialDesc& m = shells_[i]->material();
    ContactParams cp;
    cp.kc = m.contact_stiffness > 0 ? m.contact_stiffness : m.youngs_modulus;
    cp.gamma = m.contact_shear > 0 ? m.contact_shear : cp.kc;
    cp.friction = m.friction;
    contacts_[i] = std::make_unique<ShellContact>(shells_[i]->basis(), shells_[i]->rest, m.thickness,
                                                  m.contact_samples, cp);
    // Contact wave speed: psi'' <= 2 k_c (at s3 = 0) and gamma, over the shell density.
    const double c = std::sqrt(2.0 * std::max(cp.kc, cp.gamma) / m.density);
    shell_dt_ = std::min(shell_dt_, scene_.shot.cfl * scene_.shot.dx / c);
    GridShell g;
    g.shell = shells_[i].get();
    g.contact = contacts_[i].get();
    grid_shells_.push_back(std::move(g));
  }
  shell_table_.build(grid_shells_);
  shell_fields_.setup(grid_, scene_.shot.shared_shell_velocity ? 0 : grid_shells_.size(),
                      !scene_.sources.empty());
}

TransferParams Solver::transfer_params() {
  TransferParams tp;
  tp.dt = static_cast<Real>(dt_);
  tp.mls = scene_.shot.transfer == "mls";
  tp.serial = opt_.serial;
  tp.models = &models_;
  tp.densities = &densities_;
  tp.first_bulk = static_cast<std::uint32_t>(shell_table_.size());
  return tp;
}

void Solver::build_stages() {
  stages_.clear();
  const bool on_grid = !grid_shells_.empty();
  bool direct = false;
  for (const auto& c : contacts_) direct = direct || c == nullptr;
  if (!shells_.empty()) {
    stages_.push_back({"shell_forces", [this] {
                         const Vec3d zero = Vec3d::Zero();
                         for (std::size_t i = 0; i < shells_.size(); ++i) {
                           ShellObject& sh = *shells_[i];
                           if (!contacts_[i]) {
                             sh.forces(scene_.shot.gravity, shell_forces_[i], opt_.serial);
                             continue;
                           }
                           // On the grid, gravity is applied to the nodes.
                           sh.forces(zero, shell_forces_[i], opt_.serial);
                           const Real damp = static_cast<Real>(sh.material().damping);
                           if (damp > 0)
                             for (std::size_t j = 0; j < sh.size(); ++j)
                               shell_forces_[i][j] -= damp * sh.mass[j] * sh.v[j];
                         }
                       }});
    // Shells without contact: control points integrate directly, no grid.
    if (direct)
      stages_.push_back({"shell_update", [this] {
                           for (std::size_t i = 0; i < shells_.size(); ++i)
                             if (!contacts_[i])
                               shells_[i]->integrate(shell_forces_[i], time_, dt_, opt_.serial);
                         }});
  }
  if (on_grid)
    stages_.push_back({"contact", [this] {
                         std::size_t k = 0;
                         for (std::size_t i = 0; i < shells_.size(); ++i) {
                           if (!contacts_[i]) continue;
                           GridShell& g = grid_shells_[k++];
                           prescribe_pins(*g.shell, time_, dt_, g.held);
                           g.contact->update_positions(g.shell->x.data(), opt_.serial);
                           g.force.swap(shell_forces_[i]);
                           g.contact->forces(g.shell->x.data(), g.force.data(), opt_.serial);
                         }
                         clamp_to_domain();
                       }});
  if (on_grid || !scene_.sources.empty()) add_grid_stages();
  bool denting = false;
  for (const auto& sh : shells_) denting = denting || sh->has_denting();
  if (denting)
    stages_.push_back({"denting", [this] {
                         for (auto& sh : shells_) plastic_work_ += sh->project_plasticity(opt_.serial);
                       }});
  if (any_emit_) stages_.push_back({"emit", [this] { emit(); }});
}

void Solver::add_grid_stages() {
  const bool on_grid = !grid_shells_.empty();
  stages_.push_back({"bin", [this] {
                       const bool shells = !grid_shells_.empty();
                       if (shells) shell_table_.positions(grid_shells_, shell_points_);
                       grid_.bin(shells ? &shell_points_ : nullptr, particles_.x, opt_.serial);
                     }});
  stages_.push_back({"p2g", [this] {
                       TransferParams tp = transfer_params();
                       const Real dt = tp.dt;
                       if (!grid_shells_.empty())
                         tp.others = [this, dt](std::size_t b, GridNode* buf) {
                           shell_p2g_block(grid_, shell_table_, grid_shells_, dt, b, buf);
                         };
                       particles_to_grid(particles_, grid_, tp);
                       if (shell_fields_.active())
                         shell_fields_.p2g(grid_, grid_shells_, dt, &particles_, tp.first_bulk, opt_.serial);
                     }});
  stages_.push_back({"grid", [this] { grid_update(); }});
  if (on_grid)
    stages_.push_back({"contact_grid", [this] {
                         contact_normal_forces(grid_, shell_table_, grid_shells_,
                                               static_cast<Real>(dt_), opt_.serial);
                         apply_walls();
                       }});
  if (!colliders_.empty()) stages_.push_back({"colliders", [this] { apply_colliders(); }});
  stages_.push_back({"g2p", [this] {
                       TransferParams tp = transfer_params();
                       const Real dt = tp.dt;
                       if (!grid_shells_.empty())
                         tp.others = [this, dt](std::size_t b, GridNode* buf) {
                           shell_g2p_block(grid_, shell_table_, grid_shells_, dt, b, buf);
                         };
                       const bool fields = shell_fields_.active();
                       if (fields)
                         shell_fields_.before_g2p(
                             grid_, [this](const Vec3i& n) { return single_velocity_node(n); },
                             opt_.serial);
                       grid_to_particles(particles_, grid_, tp);
                       if (fields) shell_fields_.after_g2p(grid_shells_, dt, opt_.serial);
                       clamp_to_domain();
                     }});
  if (!colliders_.empty())
    stages_.push_back({"collider_particles", [this] {
                         const double dx = grid_.dx();
                         project_out_of_colliders(colliders_, dx, dt_, particles_.x, particles_.v,
                                                  nullptr, opt_.serial);
                         for (GridShell& g : grid_shells_)
                           project_out_of_colliders(colliders_, dx, dt_, g.shell->x, g.shell->v,
                                                    &g.held, opt_.serial);
                       }});
  if (on_grid)
    stages_.push_back({"friction", [this] {
                         ContactStepStats total;
                         for (GridShell& g : grid_shells_) {
                           const ContactStepStats st = g.contact->return_map(g.shell->x.data(), opt_.serial);
                           total.compressed += st.compressed;
                           total.sliding += st.sliding;
                           total.friction_work += st.friction_work;
                           total.separation_work += st.separation_work;
                         }
                         friction_work_ += total.friction_work;
                         contact_step_ = total;
                       }});
  if (any_plastic_) stages_.push_back({"plasticity", [this] { project_plasticity(); }});
}

std::vector<std::string> Solver::stage_names() const {
  std::vector<std::string> n;
  for (const Stage& s : stages_) n.push_back(s.name);
  return n;
}

void Solver::grid_update() {
  const Vec3 g = scene_.shot.gravity.cast<Real>();
  const Real dt = static_cast<Real>(dt_);
  const bool walls = grid_shells_.empty();  // with contact, walls come after contact forces
  parallel_for(
      grid_.num_grid_blocks(), 16,
      [&](std::size_t bb, std::size_t be) {
        for (std::size_t b = bb; b < be; ++b)
          grid_.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
            const Real inv_m = Real(1) / nd.m;
            for (int a = 0; a < 3; ++a) {
              Real v = nd.v[a] * inv_m + dt * g[a];
              if (walls && n[a] < kWallCells && v < 0) v = 0;
              if (walls && n[a] > domain_cells_[a] - kWallCells && v > 0) v = 0;
              nd.v[a] = v;
            }
          });
      },
      opt_.serial);
}

bool Solver::single_velocity_node(const Vec3i& n) const {
  for (int a = 0; a < 3; ++a)
    if (n[a] < kWallCells || n[a] > domain_cells_[a] - kWallCells) return true;
  Aabb at;
  at.lo = at.hi = grid_.node_position(n);
  for (const Collider& c : colliders_) {
    if (!c.bounds().overlaps(at)) continue;
    Vec3 v = Vec3::Zero();
    if (c.apply(at.lo, v)) return true;
  }
  return false;
}

void Solver::apply_walls() {
  parallel_for(
      grid_.num_grid_blocks(), 16,
      [&](std::size_t bb, std::size_t be) {
        for (std::size_t b = bb; b < be; ++b)
          grid_.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
            for (int a = 0; a < 3; ++a) {
              if (n[a] < kWallCells && nd.v[a] < 0) nd.v[a] = 0;
              if (n[a] > domain_cells_[a] - kWallCells && nd.v[a] > 0) nd.v[a] = 0;
            }
          });
      },
      opt_.serial);
}

void Solver::apply_colliders() {
  for (Collider& c : colliders_) c.begin_step(time_, dt_);
  const double dx = grid_.dx();
  parallel_for(
      grid_.num_grid_blocks(), 16,
      [&](std::size_t bb, std::size_t be) {
        for (std::size_t b = bb; b < be; ++b) {
          const Vec3i c = unpack_block(grid_.gblock_key[b]) * kBlockSize;
          Aabb box;
          box.lo = grid_.node_position(c).array() - dx;
          box.hi = grid_.node_position(c + Vec3i::Constant(kBlockSize - 1)).array() + dx;
          for (const Collider& col : colliders_) {
            if (!col.bounds().overlaps(box)) continue;
            grid_.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
              Vec3 v(nd.v[0], nd.v[1], nd.v[2]);
              if (col.apply(grid_.node_position(n), v)) {
                nd.v[0] = v[0];
                nd.v[1] = v[1];
                nd.v[2] = v[2];
              }
            });
          }
        }
      },
      opt_.serial);
}

void Solver::project_plasticity() {
  // Runs of one material in storage order go through the SIMD batch return mapping.
  parallel_for(
      particles_.size(), kParticleGrain,
      [&](std::size_t b, std::size_t e) {
        std::size_t i = b;
        while (i < e) {
          const auto mat = particles_.material[i];
          std::size_t j = i + 1;
          while (j < e && particles_.material[j] == mat) ++j;
          const ConstitutiveModel& m = models_[mat];
          if (m.has_plasticity())
            m.project_batch(particles_.F.data() + i, particles_.plastic.data() + i, j - i);
          i = j;
        }
      },
      opt_.serial);
}

void Solver::emit() {
  for (std::size_t i = 0; i < samplers_.size(); ++i) {
    if (!scene_.sources[i].emit) continue;
    std::vector<Vec3d> pts;
    samplers_[i].emit(time_, dt_, [&](const Vec3d& p) { pts.push_back(p); });
    add_particles_from(i, pts);
  }
}

void Solver::clamp_to_domain() {
  const ShotSettings& s = scene_.shot;
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<Real>(s.domain_min[a] + s.dx);
    hi[a] = static_cast<Real>(s.domain_min[a] + (domain_cells_[a] - 1) * s.dx);
  }
  parallel_for(
      particles_.size(), kParticleGrain,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t p = b; p < e; ++p) particles_.x[p] = particles_.x[p].cwiseMax(lo).cwiseMin(hi);
      },
      opt_.serial);
  for (GridShell& g : grid_shells_) {
    for (Vec3& x : g.shell->x) x = x.cwiseMax(lo).cwiseMin(hi);
    for (Vec3& x : g.contact->x) x = x.cwiseMax(lo).cwiseMin(hi);
  }
}

IntegrityView Solver::integrity_view() const {
  IntegrityView v;
  v.bulk = &particles_;
  for (const GridShell& g : grid_shells_) v.shells.push_back(g.shell);
  v.colliders = &colliders_;
  v.serial = opt_.serial;
  return v;
}

IntegrityReport Solver::integrity_snapshot() { return integrity_.snapshot(integrity_view()); }

double Solver::stable_dt() const { return stable_dt(nullptr); }

double Solver::stable_dt(double* vmax_out) const {
  const ShotSettings& s = scene_.shot;
  double dt = std::min(s.dt_max, shell_dt_);
  const std::size_t n = particles_.size();
  double vmax = 0, cmax = 0;
  if (n > 0) {
    const std::size_t chunks = (n + kParticleGrain - 1) / kParticleGrain;
    std::vector<double> vm(chunks, 0.0), cm(chunks, 0.0);
    parallel_for(
        n, kParticleGrain,
        [&](std::size_t b, std::size_t e) {
          // Squared wave speeds, from the deformed state F (a material stiffens or softens
          // as it is squeezed); one square root per chunk.
          Real v2 = 0, c2 = 0;
          bool finite = true;
          for (std::size_t p = b; p < e; ++p) {
            const Real sq = particles_.v[p].squaredNorm();
            finite = finite && std::isfinite(sq);
            v2 = std::max(v2, sq);
            const auto mat = particles_.material[p];
            c2 = std::max(c2, models_[mat].wave_modulus(
                                  particles_.F[p],
                                  particles_.has_plastic() ? particles_.plastic[p] : Real(1)) /
                                  densities_[mat]);
          }
          vm[b / kParticleGrain] =
              finite ? std::sqrt(static_cast<double>(v2)) : std::numeric_limits<double>::quiet_NaN();
          cm[b / kParticleGrain] = std::sqrt(c2);
        },
        opt_.serial);
    for (double v : vm)
      if (!std::isfinite(v)) return v;  // diverged
    vmax = *std::max_element(vm.begin(), vm.end());
    cmax = *std::max_element(cm.begin(), cm.end());
  }
  for (const GridShell& g : grid_shells_)
    for (const Vec3& v : g.shell->v) {
      const double sp = static_cast<double>(v.norm());
      if (!std::isfinite(sp)) return sp;  // diverged
      vmax = std::max(vmax, sp);
    }
  for (const Collider& c : colliders_) vmax = std::max(vmax, c.max_speed(time_));
  if (vmax_out) *vmax_out = vmax;
  if (vmax > 0) dt = std::min(dt, s.cfl * s.dx / vmax);
  if (cmax > 0) dt = std::min(dt, s.cfl * s.dx / cmax);
  return dt;
}

FrameStats Solver::advance_to(double t_end, const SubstepCallback& cb) {
  using clock = std::chrono::steady_clock;
  const auto wall0 = clock::now();
  for (Stage& st : stages_) st.seconds = 0;
  FrameStats fs;
  fs.dt_min = 1e300;
  double dt_seconds = 0, integrity_seconds = 0;
  const auto i0 = clock::now();
  const IntegrityView view = integrity_view();
  integrity_.begin_frame(view);
  integrity_seconds += std::chrono::duration<double>(clock::now() - i0).count();
  // Relative motion since the last integrity side check, bounded by twice the largest
  // speed times the time elapsed: a check whenever it could reach dx (integrity_monitor.h).
  double moved = 0;
  while (time_ < t_end) {
    const auto d0 = clock::now();
    double vmax = 0;
    double dt = stable_dt(&vmax);
    const double remaining = t_end - time_;
    if (!std::isfinite(dt)) {
      std::ostringstream os;
      os << "at t = " << time_ << " s the simulation diverged (a velocity is not finite); "
         << "try a smaller shot.cfl, or a stiffer contact or smaller dx for fast contact";
      throw SimulationError(os.str());
    }
    if (dt < scene_.shot.dt_min && remaining > scene_.shot.dt_min) {
      std::ostringstream os;
      os << "at t = " << time_ << " s the stable step " << dt
         << " s is below shot.dt_min = " << scene_.shot.dt_min << " s, "
         << describe_step_limits(step_limits(*this), scene_.shot.dt_min);
      throw SimulationError(os.str());
    }
    const double steps = std::max(1.0, std::ceil(remaining / dt - 1e-9));
    dt = remaining / steps;
    dt_seconds += std::chrono::duration<double>(clock::now() - d0).count();
    dt_ = dt;
    for (Stage& st : stages_) {
      const auto t0 = clock::now();
      st.run();
      st.seconds += std::chrono::duration<double>(clock::now() - t0).count();
    }
    time_ = (steps == 1.0) ? t_end : time_ + dt;
    fs.substeps++;
    fs.dt_min = std::min(fs.dt_min, dt);
    fs.dt_max = std::max(fs.dt_max, dt);
    moved += 2.0 * vmax * dt;
    if (moved >= grid_.dx() && time_ < t_end) {
      const auto c0 = clock::now();
      integrity_.track(view);
      integrity_seconds += std::chrono::duration<double>(clock::now() - c0).count();
      moved = 0;
    }
    if (cb) cb(fs.substeps, dt, time_);
  }
  {
    const auto c0 = clock::now();
    fs.integrity = integrity_.end_frame(view);
    integrity_seconds += std::chrono::duration<double>(clock::now() - c0).count();
  }
  if (fs.substeps == 0) fs.dt_min = 0;
  // Reorder particles by grid block once per frame for memory locality.
  const auto r0 = clock::now();
  if (particles_.size() > 0) {
    grid_.bin(particles_.x, opt_.serial);
    particles_.permute(grid_.order);
  }
  const double reorder_seconds = std::chrono::duration<double>(clock::now() - r0).count();
  fs.time = time_;
  measure(fs);
  for (const Stage& st : stages_) fs.stage_seconds.emplace_back(st.name, st.seconds);
  if (!stages_.empty()) {
    fs.stage_seconds.emplace_back("dt", dt_seconds);
    fs.stage_seconds.emplace_back("reorder", reorder_seconds);
    if (integrity_.active()) fs.stage_seconds.emplace_back("integrity", integrity_seconds);
  }
  fs.wall_seconds = std::chrono::duration<double>(clock::now() - wall0).count();
  return fs;
}

void Solver::measure(FrameStats& s) const {
  const ParticleSet& p = particles_;
  const std::size_t n = p.size();
  s.particles = n;
  s.grid_blocks = grid_.num_grid_blocks();
  struct Acc {
    double ke = 0, pe = 0, m = 0, vmax = 0;
    Vec3d mom = Vec3d::Zero();
    Acc& operator+=(const Acc& o) {
      ke += o.ke;
      pe += o.pe;
      m += o.m;
      mom += o.mom;
      vmax = std::max(vmax, o.vmax);
      return *this;
    }
  };
  const Acc total = ordered_sum<Acc>(n, opt_.serial, Acc{}, [&](std::size_t i) {
    Acc a;
    const auto mat = p.material[i];
    const double m = static_cast<double>(p.volume[i]) * densities_[mat];
    const Vec3d v = p.v[i].cast<double>();
    a.m = m;
    a.ke = 0.5 * m * v.squaredNorm();
    a.mom = m * v;
    a.vmax = v.norm();
    a.pe = static_cast<double>(p.volume[i]) *
           models_[mat].energy(p.F[i], p.has_plastic() ? p.plastic[i] : Real(1));
    return a;
  });
  for (const auto& sh : shells_) {
    const KirchhoffLoveShell::Energy e = sh->kl().energy(sh->x.data(), nullptr, opt_.serial);
    s.shell_points += sh->size();
    s.shell_kinetic_energy += sh->kinetic_energy();
    s.shell_membrane_energy += static_cast<double>(e.membrane);
    s.shell_bending_energy += static_cast<double>(e.bending);
    s.shell_max_strain = std::max(s.shell_max_strain, sh->max_strain());
  }
  s.shell_plastic_work = plastic_work_;
  for (std::size_t i = 0; i < shells_.size(); ++i) {
    const ShellObject& sh = *shells_[i];
    for (std::size_t j = 0; j < sh.size(); ++j) s.shell_momentum += static_cast<double>(sh.mass[j]) * sh.v[j].cast<double>();
    if (!contacts_[i]) continue;
    const ShellContact& c = *contacts_[i];
    s.contact_particles += c.num_sites();
    s.contact_energy += c.energy(sh.x.data(), opt_.serial);
  }
  s.contact_compressed = contact_step_.compressed;
  s.contact_sliding = contact_step_.sliding;
  s.friction_work = friction_work_;
  s.kinetic_energy = total.ke;
  s.elastic_energy = total.pe;
  s.mass = total.m;
  s.momentum = total.mom;
  s.max_speed = total.vmax;
}

int Solver::preroll(const PrerollSettings& p) {
  if (shells_.empty()) return 0;
  const int steps = settle_shells(p);
  // The settled shape is the contact particles' new reference: unit normal columns, no
  // APIC velocity field (else the sag would read as compression).
  for (std::size_t i = 0; i < shells_.size(); ++i)
    if (contacts_[i]) contacts_[i]->reset(shells_[i]->x.data(), opt_.serial);
  return steps;
}

int Solver::settle_shells(const PrerollSettings& p) {
  // Reference force scale: the largest weight of a control point (or 1 N without gravity).
  double fref = 0;
  for (const auto& sh : shells_)
    for (Real m : sh->mass) fref = std::max(fref, m * scene_.shot.gravity.norm());
  for (const auto& sh : shells_)
    for (const PointLoadDesc& pl : sh->desc().point_loads) fref = std::max(fref, pl.force.norm());
  if (fref <= 0) fref = 1;
  if (p.method == PrerollSettings::Method::Static) {
    // Shells do not touch each other in the pre-roll (as in the dynamic one), so each
    // settles on its own; the residual criterion is the same as below.
    int iterations = 0;
    for (auto& sh : shells_) {
      const StaticSolveResult r =
          sh->settle(scene_.shot.gravity, time_, p.tolerance * fref, p.max_steps, opt_.serial);
      if (!r.converged) {
        std::ostringstream os;
        os << "pre-roll did not settle shell '" << sh->name() << "' in " << r.iterations
           << " iterations: residual " << r.residual << " N = " << r.residual / fref
           << " x the reference force " << fref << " N, tolerance " << p.tolerance;
        if (r.stalled)
          os << "; no progress in the last " << StaticSolveOptions().stall_iterations
             << " iterations: is there an equilibrium (pins holding the shell)?";
        else
          os << " (preroll.max_steps = " << p.max_steps << ")";
        throw SimulationError(os.str());
      }
      iterations = std::max(iterations, r.iterations);
    }
    return iterations;
  }
  double ke_prev = 0;
  for (int step = 1; step <= p.max_steps; ++step) {
    double residual = 0, ke = 0;
    for (std::size_t i = 0; i < shells_.size(); ++i) {
      ShellObject& sh = *shells_[i];
      sh.forces(scene_.shot.gravity, shell_forces_[i], opt_.serial);
      for (std::size_t j = 0; j < sh.size(); ++j)
        for (int a = 0; a < 3; ++a)
          if (!(sh.pin_mask[j] & (1u << a)))
            residual = std::max(residual, std::abs(double(shell_forces_[i][j][a])));
      sh.integrate(shell_forces_[i], time_, shell_dt_, opt_.serial);
      ke += sh.kinetic_energy();
    }
    if (residual / fref < p.tolerance) {
      for (auto& sh : shells_)
        for (auto& v : sh->v) v.setZero();
      return step;
    }
    // Kinetic damping: at a peak of kinetic energy, stop every point.
    if (ke < ke_prev) {
      for (auto& sh : shells_)
        for (auto& v : sh->v) v.setZero();
      ke = 0;
    }
    ke_prev = ke;
  }
  std::ostringstream os;
  os << "pre-roll did not settle within preroll.max_steps = " << p.max_steps
     << " steps (tolerance " << p.tolerance << ")";
  throw SimulationError(os.str());
}

}  // namespace shellmpm
