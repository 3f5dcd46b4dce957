#include "sim/integrity/integrity_report.h"

#include <sstream>

namespace shellmpm {

std::vector<std::string> describe_integrity(const IntegrityReport& r, int frame, double dx) {
  std::vector<std::string> out;
  for (const IntegrityEvent& e : r.events) {
    std::ostringstream os;
    os.precision(3);
    os << "frame " << frame << ": ";
    const auto at = [&] {
      os << " (at " << e.where.x() << ", " << e.where.y() << ", " << e.where.z() << ")";
    };
    switch (e.kind) {
      case IntegrityEvent::Kind::BulkThroughShell:
        os << e.count << " bulk particles crossed shell '" << e.object << "'";
        at();
        break;
      case IntegrityEvent::Kind::ShellThroughShell:
        os << e.count << " points of shell '" << e.other << "' crossed shell '" << e.object << "'";
        at();
        break;
      case IntegrityEvent::Kind::ShellsIntersect:
        os << "shells '" << e.object << "' and '" << e.other << "' pass through each other ("
           << e.count << " crossing edges)";
        at();
        break;
      case IntegrityEvent::Kind::SelfIntersect:
        os << "shell '" << e.object << "' passes through itself (" << e.count << " crossing edges)";
        at();
        break;
      case IntegrityEvent::Kind::InsideCollider:
        os << e.count << " points are more than " << 0.5 << " dx inside collider '" << e.object
           << "' (deepest " << e.value / dx << " dx";
        os << ", at " << e.where.x() << ", " << e.where.y() << ", " << e.where.z() << ")";
        break;
      case IntegrityEvent::Kind::NonFinite:
        os << e.count << " non-finite positions or velocities in " << e.object;
        break;
      case IntegrityEvent::Kind::StretchedMesh:
        os << "shell '" << e.object << "' has " << e.count << " edges longer than 2 dx (longest "
           << e.value / dx << " dx): contact can leak between its control points; refine the "
           << "mesh or raise dx";
        break;
      case IntegrityEvent::Kind::EnergyGain:
        os << "the bodies gained " << e.value
           << " J of energy that neither gravity nor the colliders, pins, loads or sources "
              "supplied ("
           << e.other << "; most in '" << e.object
           << "'): a blow-up, or contact pushing bodies apart (stats.json: energy; "
              "docs/integrity.md)";
        break;
    }
    out.push_back(os.str());
  }
  return out;
}

}  // namespace shellmpm
