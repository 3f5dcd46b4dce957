#include "sim/solver/body_energies.h"

#include "sim/core/parallel.h"

namespace shellmpm {

std::vector<BodyEnergy> body_energies(const StepContext& c) {
  const Scene& scene = c.scene;
  const Vec3d g = scene.shot.gravity;
  const std::size_t nm = scene.materials.size();
  std::vector<BodyEnergy> out(nm + c.shells.size());
  // Bulk: per material, summed per chunk and then in chunk order.
  const ParticleSet& p = c.particles;
  const std::vector<std::vector<double>> parts = chunk_parts(
      p.size(), kParticleGrain, c.opt.serial, std::vector<double>(4 * nm, 0.0),
      [&](std::size_t b, std::size_t e, std::vector<double>& s) {
        for (std::size_t i = b; i < e; ++i) {
          const auto mat = p.material_of(i);
          const double vol = static_cast<double>(p.volume_of(i));
          const double m = vol * c.densities[mat];
          double* a = &s[4 * mat];
          a[0] += 0.5 * m * p.v[i].cast<double>().squaredNorm();
          a[1] += vol * c.models[mat].energy(p.F[i], p.has_plastic() ? p.plastic[i] : Real(1));
          a[2] -= m * g.dot(p.x[i].cast<double>());
          a[3] += m;
        }
      });
  for (std::size_t k = 0; k < nm; ++k) {
    BodyEnergy& b = out[k];
    b.name = scene.materials[k].name;
    for (const std::vector<double>& s : parts) {
      b.kinetic += s[4 * k];
      b.stored += s[4 * k + 1];
      b.potential += s[4 * k + 2];
      b.mass += s[4 * k + 3];
    }
  }
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    ShellObject& sh = *c.shells[i];
    BodyEnergy& b = out[nm + i];
    b.name = sh.name();
    b.shell = true;
    b.kinetic = sh.kinetic_energy();
    const KirchhoffLoveShell::Energy e = sh.kl().energy(sh.x.data(), nullptr, c.opt.serial);
    b.membrane = static_cast<double>(e.membrane);
    b.bending = static_cast<double>(e.bending);
    b.stored = b.membrane + b.bending;
    if (c.contacts[i]) b.stored += c.contacts[i]->energy(sh.x.data(), c.opt.serial);
    for (std::size_t j = 0; j < sh.size(); ++j) {
      const double m = static_cast<double>(sh.mass[j]);
      b.potential -= m * g.dot(sh.x[j].cast<double>());
      b.mass += m;
    }
  }
  return out;
}

double shell_stored_energy(const StepContext& c, std::size_t i) {
  ShellObject& sh = *c.shells[i];
  const KirchhoffLoveShell::Energy e = sh.kl().energy(sh.x.data(), nullptr, c.opt.serial);
  double w = static_cast<double>(e.membrane) + static_cast<double>(e.bending);
  if (c.contacts[i]) w += c.contacts[i]->energy(sh.x.data(), c.opt.serial);
  return w;
}

double load_work(const std::vector<Vec3d>& f, const std::vector<Vec3>& v, double dt) {
  double w = 0;
  for (std::size_t j = 0; j < f.size(); ++j) w += f[j].dot(v[j].cast<double>());
  return dt * w;
}

}  // namespace shellmpm
