// Numbers in the solver's messages (step limits, the integrator's choice).
#pragma once
#include <cstdio>
#include <string>

namespace shellmpm {

/// v printed with the printf format f, which holds one double conversion ("%.3g").
inline std::string format_number(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace shellmpm
