// Small least-squares fits for tests that measure a motion.
#pragma once
#include <Eigen/Dense>
#include <vector>

namespace shellmpm::test {

/// Least-squares acceleration a of s(t) = a0 + a1 t + a/2 t^2.
inline double fit_acceleration(const std::vector<double>& t, const std::vector<double>& s) {
  Eigen::MatrixXd A(t.size(), 3);
  Eigen::VectorXd b(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    A(k, 0) = 1;
    A(k, 1) = t[k];
    A(k, 2) = 0.5 * t[k] * t[k];
    b[k] = s[k];
  }
  return A.colPivHouseholderQr().solve(b)[2];
}

}  // namespace shellmpm::test
