// Convergence of a quantity under refinement: the observed order from three resolutions
// and Richardson extrapolation to zero spacing (Roache, "Verification and Validation in
// Computational Science and Engineering", 1998, ch. 5; the general-ratio form solves the
// order equation numerically), and the order fitted to errors against a known answer.
#pragma once
#include <optional>
#include <vector>

namespace shellmpm {

/// What three or more refinements say about the limit.
struct Extrapolation {
  double order = 0;      ///< observed order p (q - q_inf ~ C h^p), from the three finest
  double limit = 0;      ///< Richardson estimate of q at h -> 0
  double error = 0;      ///< |q_finest - limit|: the estimated error left in the finest result
  bool monotone = true;  ///< false when the differences change sign (oscillatory: no order)
};

/// Observed order and Richardson limit from values q at spacings h (any order of input;
/// the three smallest h are used). Needs 3 distinct h > 0. Returns nothing when the
/// differences change sign or vanish, or the order equation has no root in (0.05, 12).
std::optional<Extrapolation> richardson(const std::vector<double>& h, const std::vector<double>& q);

/// Least-squares slope of log|err| against log h (the convergence order against a known
/// answer); nothing with fewer than two points with err != 0 and distinct h > 0.
std::optional<double> fitted_order(const std::vector<double>& h, const std::vector<double>& err);

}  // namespace shellmpm
