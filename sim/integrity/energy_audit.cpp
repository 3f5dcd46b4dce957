#include "sim/integrity/energy_audit.h"

#include <algorithm>
#include <cmath>

namespace shellmpm {

EnergyAudit audit_energy(const std::vector<BodyEnergy>& start, const std::vector<BodyEnergy>& end,
                         const std::vector<double>& dissipated, double supplied, double floor) {
  EnergyAudit a;
  a.supplied = supplied;
  double scale = std::abs(supplied);
  double best = -1;
  for (std::size_t i = 0; i < end.size(); ++i) {
    const BodyEnergy& e = end[i];
    const double d = i < dissipated.size() ? dissipated[i] : 0.0;
    a.end += e.total();
    a.dissipated += d;
    if (i >= start.size()) continue;
    const BodyEnergy& s = start[i];
    a.start += s.total();
    scale += s.kinetic + std::abs(s.stored) + std::abs(e.potential - s.potential) + std::abs(d);
    const double gain = e.total() - s.total() + d;
    if (gain > best) {
      best = gain;
      a.object = e.name;
      a.object_gain = gain;
    }
  }
  a.excess = a.end - a.start + a.dissipated - a.supplied;
  a.tolerance = kEnergyTolerance * scale + floor;
  a.judged = start.size() == end.size();
  if (!a.judged) a.reason = "the bodies changed";
  return a;
}

}  // namespace shellmpm
