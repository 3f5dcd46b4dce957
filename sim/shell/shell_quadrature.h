// Quadrature rules for shells: Dunavant rules on the reference triangle (in-plane
// Kirchhoff-Love points) and Gauss-Legendre rules on [-1, 1] (through the thickness).
// D. A. Dunavant, "High degree efficient symmetrical Gaussian quadrature rules for the
// triangle", IJNME 21 (1985); rules of 1, 3, 6 and 7 points (degrees 1, 2, 4, 5).
#pragma once
#include <Eigen/Core>

#include <vector>

namespace shellmpm {

/// A rule on the reference triangle {xi1 >= 0, xi2 >= 0, xi1 + xi2 <= 1}.
/// Weights are parametric (they sum to 1/2, the reference area).
struct TriangleQuadrature {
  std::vector<Eigen::Vector2d> points;  ///< (xi1, xi2)
  std::vector<double> weights;          ///< sum = 1/2
  int degree = 0;                       ///< polynomials up to this degree are exact
};

/// Dunavant rule with `num_points` in {1, 3, 6, 7} (degree 1, 2, 4, 5); other counts
/// throw InvariantError (the scene reader validates user input before this).
TriangleQuadrature triangle_quadrature(int num_points);

/// A rule on [-1, 1].
struct LineQuadrature {
  std::vector<double> points;   ///< in [-1, 1], ascending
  std::vector<double> weights;  ///< sum = 2
};

/// Gauss-Legendre rule with `num_points` in 1..5 (exact to degree 2 n - 1).
LineQuadrature gauss_legendre(int num_points);

}  // namespace shellmpm
