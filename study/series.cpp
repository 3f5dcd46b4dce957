#include "study/series.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace shellmpm {

double fit_acceleration(const std::vector<double>& t, const std::vector<double>& s) {
  if (t.size() != s.size() || t.size() < 3)
    throw std::invalid_argument("fit_acceleration: need at least 3 samples");
  Eigen::MatrixXd A(t.size(), 3);
  Eigen::VectorXd b(t.size());
  const double t0 = t.front();  // centred times keep the normal equations well conditioned
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double dt = t[i] - t0;
    A(i, 0) = 1;
    A(i, 1) = dt;
    A(i, 2) = 0.5 * dt * dt;
    b(i) = s[i];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < 3) throw std::invalid_argument("fit_acceleration: samples at too few times");
  return qr.solve(b)(2);
}

double fit_slope(const std::vector<double>& t, const std::vector<double>& v) {
  if (t.size() != v.size() || t.size() < 2)
    throw std::invalid_argument("fit_slope: need at least 2 samples");
  double mt = 0, mv = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    mt += t[i];
    mv += v[i];
  }
  mt /= t.size();
  mv /= t.size();
  double num = 0, den = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    num += (t[i] - mt) * (v[i] - mv);
    den += (t[i] - mt) * (t[i] - mt);
  }
  if (den <= 0) throw std::invalid_argument("fit_slope: samples at one time only");
  return num / den;
}

namespace {

/// Times where s crosses `level` in one direction, interpolated linearly.
std::vector<double> crossings(const std::vector<double>& t, const std::vector<double>& s,
                              double level, bool rising) {
  std::vector<double> out;
  for (std::size_t i = 1; i < t.size() && i < s.size(); ++i) {
    const double a = s[i - 1] - level, b = s[i] - level;
    const bool hit = rising ? (a < 0 && b >= 0) : (a > 0 && b <= 0);
    if (hit) out.push_back(t[i - 1] + (t[i] - t[i - 1]) * a / (a - b));
  }
  return out;
}

}  // namespace

std::optional<double> oscillation_period(const std::vector<double>& t,
                                         const std::vector<double>& s) {
  if (s.size() < 3) return std::nullopt;
  double mean = 0;
  for (double v : s) mean += v;
  mean /= s.size();
  // Up- and down-crossings each give (count - 1) full periods between their first and last.
  double span = 0;
  int periods = 0;
  for (bool rising : {true, false}) {
    const std::vector<double> c = crossings(t, s, mean, rising);
    if (c.size() < 2) continue;
    span += c.back() - c.front();
    periods += static_cast<int>(c.size()) - 1;
  }
  if (periods == 0) return std::nullopt;
  return span / periods;
}

std::optional<double> first_crossing(const std::vector<double>& t, const std::vector<double>& s,
                                     double level, bool rising) {
  const std::vector<double> c = crossings(t, s, level, rising);
  if (c.empty()) return std::nullopt;
  return c.front();
}

}  // namespace shellmpm
