#include "io/number_text.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace shellmpm {
namespace {

/// "1e+20" -> "1e20", "1e-06" -> "1e-6": the exponent without sign or leading zeros.
std::string tidy_exponent(std::string s) {
  const std::size_t e = s.find('e');
  if (e != std::string::npos) {
    std::size_t d = e + 1;
    if (s[d] == '+') s.erase(d, 1);
    if (s[d] == '-') ++d;
    while (d + 1 < s.size() && s[d] == '0') s.erase(d, 1);
  }
  return s;
}

}  // namespace

std::string fmt_num(double x) {
  char buf[64];
  if (x == std::floor(x) && std::fabs(x) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return tidy_exponent(buf);
}

std::string fmt3(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return tidy_exponent(buf);
}

std::string fmt_bound(double x) {
  const std::string whole = fmt_num(x);
  if (!(std::fabs(x) >= 1e6) || x != std::floor(x)) return whole;
  char buf[64];
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*e", prec - 1, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  const std::string shortest = tidy_exponent(buf);
  return shortest.size() < whole.size() ? shortest : whole;
}

std::string join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : sep) + s;
  return out;
}

}  // namespace shellmpm
