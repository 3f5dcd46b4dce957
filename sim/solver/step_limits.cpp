#include "sim/solver/step_limits.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/solver/number_format.h"
#include "sim/solver/solver.h"

namespace shellmpm {
namespace {

/// Three significant digits; whole numbers from 100 to 1e5 without an exponent (5857 m/s).
std::string num(double v) {
  const double a = std::abs(v);
  return format_number(a >= 100 && a < 1e5 ? "%.0f" : "%.3g", v);
}

/// A length in mm below 1 cm, else in m.
std::string length(double m) {
  return m < 1e-2 ? num(m * 1e3) + " mm" : num(m) + " m";
}

/// A position; components below 1e-9 of the largest print as 0 (round-off).
std::string point(const Vec3d& p) {
  const double tiny = 1e-9 * p.cwiseAbs().maxCoeff();
  auto c = [&](double v) { return num(std::abs(v) <= tiny ? 0.0 : v); };
  return "(" + c(p.x()) + ", " + c(p.y()) + ", " + c(p.z()) + ")";
}

std::string quoted(const std::string& name) {
  return "'" + name + "'";
}

const std::string kLargerDx = "a larger shot.dx (the step scales with dx)";

/// The CFL bound of a speed [m/s], or NaN when it is not finite.
double cfl_dt(const ShotSettings& s, double speed) {
  if (!std::isfinite(speed)) return std::numeric_limits<double>::quiet_NaN();
  return s.cfl * s.dx / speed;
}

void add_shell_elastic(const ShellObject& sh, const ShotSettings& s, std::vector<StepLimit>& out) {
  StepLimit l;
  l.kind = StepLimitKind::ShellElastic;
  l.dt = sh.stable_dt(s.cfl);
  const std::array<int, 2>& ev = sh.min_edge_vertices();
  const ShellMaterialDesc& m = sh.material();
  l.detail = "shell " + quoted(sh.name()) + ": membrane/bending stiffness (material " +
             quoted(m.name) + ", E " + num(m.youngs_modulus) + " Pa, thickness " +
             length(m.thickness) + ") over its shortest control-mesh edge, " +
             length(sh.min_edge());
  double mean = 0;
  if (ev[0] >= 0) {
    l.detail += " between vertices " + std::to_string(ev[0]) + " and " + std::to_string(ev[1]) +
                " at " + point(0.5 * (sh.rest[ev[0]] + sh.rest[ev[1]]));
    std::size_t n = 0;
    for (const auto& t : sh.triangles())
      for (int e = 0; e < 3; ++e, ++n) mean += (sh.rest[t[e]] - sh.rest[t[(e + 1) % 3]]).norm();
    mean /= static_cast<double>(n);
  }
  const std::string softer = "a softer shell material (smaller youngs_modulus)";
  if (sh.min_edge() < 0.2 * mean) {
    l.detail += " (the mean edge is " + length(mean) + ")";
    l.hint =
        "remesh the shell or merge the vertices of that edge (a cleaned mesh without "
        "slivers); else " +
        softer;
  } else if (sh.desc().kind == ShellDesc::Kind::Mesh) {
    l.hint = "a coarser control mesh (remesh), or " + softer;
  } else {
    l.hint = "a coarser control mesh (lower geometry.resolution or subdivisions), or " + softer;
  }
  out.push_back(std::move(l));
}

void add_shell_contact(const ShellObject& sh, const ShellContact& c, const ShotSettings& s,
                       std::vector<StepLimit>& out) {
  // As Solver::setup_contact: psi'' <= 2 k_c (at s3 = 0) and gamma, over the density.
  const ContactParams& cp = c.params();
  const ShellMaterialDesc& m = sh.material();
  const double k = std::max(cp.kc, cp.gamma);
  const double speed = std::sqrt(2.0 * k / m.density);
  StepLimit l;
  l.kind = StepLimitKind::ShellContact;
  l.dt = s.cfl * s.dx / speed;
  l.detail = "shell " + quoted(sh.name()) + ": contact " +
             (cp.gamma > cp.kc ? "shear gamma " + num(cp.gamma) : "stiffness k_c " + num(cp.kc)) +
             " Pa over density " + num(m.density) + " kg/m^3 (wave speed " + num(speed) + " m/s)";
  l.hint = "a lower shell_materials[" + quoted(m.name) +
           "].contact_stiffness and contact_shear (both default to youngs_modulus; near the "
           "moduli of what the shell touches is usually enough), or " +
           kLargerDx;
  out.push_back(std::move(l));
}

std::string material_hint() {
  return "a softer material (smaller materials[].youngs_modulus; the step scales with "
         "1/sqrt(E); an effect rarely needs a metal's real stiffness), or " +
         kLargerDx;
}

/// Bulk particles, per material: the largest speed and squared wave speed, in the same
/// precision as Solver::stable_dt (so the minimum matches it exactly). Returns which
/// materials have particles.
std::vector<char> add_bulk(const Solver& solver, std::vector<StepLimit>& out) {
  const Scene& scene = solver.scene();
  const ShotSettings& s = scene.shot;
  const ParticleSet& p = solver.particles();
  const std::size_t nmat = solver.models().size();
  std::vector<Real> v2(nmat, Real(0)), c2(nmat, Real(0));
  std::vector<char> present(nmat, 0), finite(nmat, 1);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto mat = p.material_of(i);
    present[mat] = 1;
    const Real sq = p.v[i].squaredNorm();
    if (!std::isfinite(sq)) finite[mat] = 0;
    v2[mat] = std::max(v2[mat], sq);
    c2[mat] = std::max(c2[mat], solver.models()[mat].wave_modulus(
                                    p.F[i], p.has_plastic() ? p.plastic[i] : Real(1)) /
                                    solver.densities()[mat]);
  }
  for (std::size_t mat = 0; mat < nmat; ++mat) {
    if (!present[mat]) continue;
    const MaterialDesc& md = scene.materials[mat];
    const double c = static_cast<double>(std::sqrt(c2[mat]));
    if (c > 0) {
      StepLimit l;
      l.kind = StepLimitKind::Material;
      l.dt = s.cfl * s.dx / c;
      l.detail = "material " + quoted(md.name) + ": elastic wave speed " + num(c) + " m/s (E " +
                 num(md.youngs_modulus) + " Pa, density " + num(md.density) + " kg/m^3)";
      l.hint = material_hint();
      out.push_back(std::move(l));
    }
    const double v = finite[mat] ? std::sqrt(static_cast<double>(v2[mat]))
                                 : std::numeric_limits<double>::quiet_NaN();
    if (!(v > 0) && !std::isnan(v)) continue;
    StepLimit l;
    l.kind = StepLimitKind::ParticleSpeed;
    l.dt = cfl_dt(s, v);
    l.detail = "particles of material " + quoted(md.name) + ": " +
               (std::isnan(v) ? std::string("a velocity is not finite (diverged)")
                              : "max speed " + num(v) + " m/s");
    l.hint = "slower sources or colliders (or, when diverged, a smaller shot.cfl), or " + kLargerDx;
    out.push_back(std::move(l));
  }
  return present;
}

/// Shells on the grid move with the CFL bound too.
void add_shell_speeds(const Solver& solver, std::vector<StepLimit>& out) {
  const ShotSettings& s = solver.scene().shot;
  for (std::size_t i = 0; i < solver.shells().size(); ++i) {
    if (!solver.contact(i)) continue;
    const ShellObject& sh = *solver.shells()[i];
    double vmax = 0;
    for (const Vec3& v : sh.v) {
      const double sp = static_cast<double>(v.norm());
      if (!std::isfinite(sp)) {
        vmax = std::numeric_limits<double>::quiet_NaN();
        break;
      }
      vmax = std::max(vmax, sp);
    }
    if (!(vmax > 0) && !std::isnan(vmax)) continue;
    StepLimit l;
    l.kind = StepLimitKind::ShellSpeed;
    l.dt = cfl_dt(s, vmax);
    l.detail = "shell " + quoted(sh.name()) + ": " +
               (std::isnan(vmax) ? std::string("a velocity is not finite (diverged)")
                                 : "max control-point speed " + num(vmax) + " m/s");
    l.hint = "a slower shell (its velocity, pin keyframes), or " + kLargerDx;
    out.push_back(std::move(l));
  }
}

void add_colliders(const Solver& solver, std::vector<StepLimit>& out) {
  const ShotSettings& s = solver.scene().shot;
  for (const Collider& c : solver.colliders()) {
    const double v = c.max_speed(solver.time());
    if (!(v > 0)) continue;
    StepLimit l;
    l.kind = StepLimitKind::ColliderSpeed;
    l.dt = cfl_dt(s, v);
    l.detail = "collider " + quoted(c.desc().name) + ": speed " + num(v) + " m/s";
    l.hint = "slower keyframes (further apart in time), or " + kLargerDx;
    out.push_back(std::move(l));
  }
}

/// What emitting sources will make: their speed, and the wave speed at rest of materials
/// that have no particles yet.
void add_upcoming(const Solver& solver, const std::vector<char>& present,
                  std::vector<StepLimit>& out) {
  const Scene& scene = solver.scene();
  const ShotSettings& s = scene.shot;
  std::vector<char> listed = present;
  for (const SourceDesc& src : scene.sources) {
    if (!src.emit) continue;
    const double v = src.velocity.norm();
    if (v > 0) {
      StepLimit l;
      l.kind = StepLimitKind::SourceSpeed;
      l.dt = s.cfl * s.dx / v;
      l.detail = "source " + quoted(src.name) + ": emission speed " + num(v) + " m/s";
      l.hint = "a slower sources[].velocity, or " + kLargerDx;
      l.upcoming = true;
      out.push_back(std::move(l));
    }
    if (listed[src.material]) continue;
    listed[src.material] = 1;
    const ConstitutiveModel& m = solver.models()[src.material];
    const double c =
        static_cast<double>(m.wave_speed(solver.densities()[src.material], m.initial_plastic()));
    if (!(c > 0)) continue;
    const MaterialDesc& md = scene.materials[src.material];
    StepLimit l;
    l.kind = StepLimitKind::Material;
    l.dt = s.cfl * s.dx / c;
    l.detail = "material " + quoted(md.name) + " (emitted by source " + quoted(src.name) +
               "): elastic wave speed " + num(c) + " m/s (E " + num(md.youngs_modulus) +
               " Pa, density " + num(md.density) + " kg/m^3)";
    l.hint = material_hint();
    l.upcoming = true;
    out.push_back(std::move(l));
  }
}

}  // namespace

const char* to_string(StepLimitKind kind) {
  switch (kind) {
    case StepLimitKind::DtMax:
      return "shot.dt_max";
    case StepLimitKind::ShellElastic:
      return "shell elastic";
    case StepLimitKind::ShellContact:
      return "shell contact";
    case StepLimitKind::Material:
      return "material wave speed";
    case StepLimitKind::ParticleSpeed:
      return "particle speed";
    case StepLimitKind::ShellSpeed:
      return "shell speed";
    case StepLimitKind::ColliderSpeed:
      return "collider speed";
    case StepLimitKind::SourceSpeed:
      return "source speed";
  }
  return "unknown";
}

std::vector<StepLimit> step_limits(const Solver& solver, bool upcoming) {
  const Scene& scene = solver.scene();
  const ShotSettings& s = scene.shot;
  std::vector<StepLimit> out;
  {
    StepLimit l;
    l.kind = StepLimitKind::DtMax;
    l.dt = s.dt_max;
    l.detail = "shot.dt_max = " + num(s.dt_max) + " s";
    l.hint = "a larger shot.dt_max";
    out.push_back(std::move(l));
  }
  // Shells: the same bounds as Solver's constructor and setup_contact (shell_dt_).
  for (std::size_t i = 0; i < solver.shells().size(); ++i) {
    const ShellObject& sh = *solver.shells()[i];
    add_shell_elastic(sh, s, out);
    if (const ShellContact* c = solver.contact(i)) add_shell_contact(sh, *c, s, out);
  }
  const std::vector<char> present = add_bulk(solver, out);
  add_shell_speeds(solver, out);
  add_colliders(solver, out);
  if (upcoming) add_upcoming(solver, present, out);
  // NaN (diverged) first, then by dt; ties keep the order above.
  std::stable_sort(out.begin(), out.end(), [](const StepLimit& a, const StepLimit& b) {
    if (std::isnan(a.dt) || std::isnan(b.dt)) return std::isnan(a.dt) && !std::isnan(b.dt);
    return a.dt < b.dt;
  });
  return out;
}

std::string describe_step_limits(const std::vector<StepLimit>& limits, double dt_min) {
  std::string out;
  for (std::size_t i = 0; i < limits.size(); ++i) {
    const StepLimit& l = limits[i];
    if (i > 0 && !(l.dt < dt_min)) break;
    out += (i == 0 ? "limited by " : "; also ") + l.detail + " (" + format_number("%.2g", l.dt) +
           " s); to raise it: " + l.hint;
  }
  const StepLimitKind k = limits.front().kind;
  if (k == StepLimitKind::ShellElastic || k == StepLimitKind::ShellContact ||
      k == StepLimitKind::Material) {
    out +=
        ". Or keep it as it is and set shot.integrator: auto (or implicit): implicit steps "
        "follow the motion, not the stiffness (docs/implicit.md)";
  }
  return out;
}

}  // namespace shellmpm
