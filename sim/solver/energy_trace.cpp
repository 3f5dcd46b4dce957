#include "sim/solver/energy_trace.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "sim/solver/body_energies.h"

namespace shellmpm {

namespace {
constexpr double kTraceThreshold = 1e-4;  ///< [J]
}

EnergyTrace::EnergyTrace() {
  const char* e = std::getenv("SHELLMPM_ENERGY_TRACE");
  on_ = e && *e && std::strcmp(e, "0") != 0;
}

double EnergyTrace::balance(const StepContext& c, std::vector<BodyEnergy>& bodies) const {
  bodies = body_energies(c);
  double e = -c.energy_supplied;
  for (const BodyEnergy& b : bodies) e += b.total();
  for (const double d : c.shell_dissipated) e += d;
  return e;
}

void EnergyTrace::begin(const StepContext& c) {
  if (on_) last_ = balance(c, bodies_);
}

void EnergyTrace::after(const StepContext& c, std::string_view stage) {
  if (!on_) return;
  std::vector<BodyEnergy> now;
  const double e = balance(c, now);
  if (std::abs(e - last_) > kTraceThreshold && now.size() == bodies_.size()) {
    std::size_t k = 0;
    double most = -1;
    for (std::size_t i = 0; i < now.size(); ++i) {
      const double d = std::abs(now[i].total() - bodies_[i].total());
      if (d > most) most = d, k = i;
    }
    const BodyEnergy &a = bodies_[k], &b = now[k];
    std::fprintf(stderr,
                 "energy t %.6f s %-18s %+.4e J (most in '%s': kinetic %+.3e, stored %+.3e, "
                 "potential %+.3e J)",
                 c.time, std::string(stage).c_str(), e - last_, b.name.c_str(),
                 b.kinetic - a.kinetic, b.stored - a.stored, b.potential - a.potential);
    // A shell's stored energy: its membrane and bending energy, and its contact particles'.
    if (b.shell) {
      const double membrane = b.membrane - a.membrane, bending = b.bending - a.bending;
      std::fprintf(stderr, " [membrane %+.3e, bending %+.3e, contact %+.3e J]", membrane, bending,
                   b.stored - a.stored - membrane - bending);
    }
    std::fputc('\n', stderr);
  }
  last_ = e;
  bodies_ = std::move(now);
}

}  // namespace shellmpm
