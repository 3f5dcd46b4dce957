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
    std::fprintf(stderr,
                 "energy t %.6f s %-18s %+.4e J (most in '%s': kinetic %+.3e, stored %+.3e, "
                 "potential %+.3e J)\n",
                 c.time, std::string(stage).c_str(), e - last_, now[k].name.c_str(),
                 now[k].kinetic - bodies_[k].kinetic, now[k].stored - bodies_[k].stored,
                 now[k].potential - bodies_[k].potential);
  }
  last_ = e;
  bodies_ = std::move(now);
}

}  // namespace shellmpm
