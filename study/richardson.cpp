#include "study/richardson.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace shellmpm {

std::optional<Extrapolation> richardson(const std::vector<double>& h,
                                        const std::vector<double>& q) {
  if (h.size() != q.size() || h.size() < 3) return std::nullopt;
  std::vector<std::size_t> idx(h.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return h[a] < h[b]; });
  // h1 < h2 < h3: finest first.
  const double h1 = h[idx[0]], h2 = h[idx[1]], h3 = h[idx[2]];
  const double q1 = q[idx[0]], q2 = q[idx[1]], q3 = q[idx[2]];
  if (!(h1 > 0) || !(h2 > h1) || !(h3 > h2)) return std::nullopt;
  const double d21 = q2 - q1, d32 = q3 - q2;
  if (d21 == 0 || d32 == 0) return std::nullopt;
  Extrapolation e;
  if ((d21 > 0) != (d32 > 0)) {
    e.monotone = false;
    return std::nullopt;
  }
  // q(h) = q_inf + C h^p: d32 / d21 = (h3^p - h2^p) / (h2^p - h1^p) =: g(p), increasing in p.
  const double target = d32 / d21;
  auto g = [&](double p) {
    return (std::pow(h3, p) - std::pow(h2, p)) / (std::pow(h2, p) - std::pow(h1, p));
  };
  double lo = 0.05, hi = 12;
  if (target < g(lo) || target > g(hi)) return std::nullopt;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) < target ? lo : hi) = mid;
  }
  e.order = 0.5 * (lo + hi);
  const double C = d21 / (std::pow(h2, e.order) - std::pow(h1, e.order));
  e.limit = q1 - C * std::pow(h1, e.order);
  e.error = std::abs(q1 - e.limit);
  return e;
}

std::optional<double> fitted_order(const std::vector<double>& h, const std::vector<double>& err) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < h.size() && i < err.size(); ++i)
    if (h[i] > 0 && err[i] != 0 && std::isfinite(err[i])) {
      x.push_back(std::log(h[i]));
      y.push_back(std::log(std::abs(err[i])));
    }
  if (x.size() < 2) return std::nullopt;
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / x.size();
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / y.size();
  double num = 0, den = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    num += (x[i] - mx) * (y[i] - my);
    den += (x[i] - mx) * (x[i] - mx);
  }
  if (den <= 0) return std::nullopt;
  return num / den;
}

}  // namespace shellmpm
