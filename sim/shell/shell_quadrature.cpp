#include "sim/shell/shell_quadrature.h"

#include <cmath>

#include "sim/core/check.h"

namespace shellmpm {
namespace {

// Adds the three permutations of barycentric (a, a, 1 - 2a) with one weight
// (the weight is for the unit-area normalization; scaled by 1/2 at the end).
void add_orbit3(TriangleQuadrature& q, double a, double w) {
  const double b = 1.0 - 2.0 * a;
  q.points.emplace_back(b, a);
  q.points.emplace_back(a, b);
  q.points.emplace_back(a, a);
  for (int i = 0; i < 3; ++i) q.weights.push_back(w);
}

}  // namespace

TriangleQuadrature triangle_quadrature(int num_points) {
  TriangleQuadrature q;
  switch (num_points) {
    case 1:
      q.degree = 1;
      q.points.emplace_back(1.0 / 3.0, 1.0 / 3.0);
      q.weights.push_back(1.0);
      break;
    case 3:
      q.degree = 2;
      add_orbit3(q, 1.0 / 6.0, 1.0 / 3.0);
      break;
    case 6:  // Dunavant degree 4
      q.degree = 4;
      add_orbit3(q, 0.445948490915965, 0.223381589678011);
      add_orbit3(q, 0.091576213509771, 0.109951743655322);
      break;
    case 7: {  // Dunavant degree 5 (Radon), closed form
      q.degree = 5;
      const double s15 = std::sqrt(15.0);
      q.points.emplace_back(1.0 / 3.0, 1.0 / 3.0);
      q.weights.push_back(9.0 / 40.0);
      add_orbit3(q, (6.0 + s15) / 21.0, (155.0 + s15) / 1200.0);
      add_orbit3(q, (6.0 - s15) / 21.0, (155.0 - s15) / 1200.0);
      break;
    }
    default:
      SHELLMPM_CHECK(false, "triangle quadrature with " << num_points << " points (1, 3, 6 or 7)");
  }
  for (double& w : q.weights) w *= 0.5;
  return q;
}

LineQuadrature gauss_legendre(int num_points) {
  LineQuadrature q;
  switch (num_points) {
    case 1:
      q.points = {0.0};
      q.weights = {2.0};
      break;
    case 2: {
      const double p = 1.0 / std::sqrt(3.0);
      q.points = {-p, p};
      q.weights = {1.0, 1.0};
      break;
    }
    case 3: {
      const double p = std::sqrt(0.6);
      q.points = {-p, 0.0, p};
      q.weights = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
      break;
    }
    case 4: {
      const double r = 2.0 / 7.0 * std::sqrt(6.0 / 5.0);
      const double p1 = std::sqrt(3.0 / 7.0 - r), p2 = std::sqrt(3.0 / 7.0 + r);
      const double w1 = (18.0 + std::sqrt(30.0)) / 36.0, w2 = (18.0 - std::sqrt(30.0)) / 36.0;
      q.points = {-p2, -p1, p1, p2};
      q.weights = {w2, w1, w1, w2};
      break;
    }
    case 5: {
      const double r = 2.0 * std::sqrt(10.0 / 7.0);
      const double p1 = std::sqrt(5.0 - r) / 3.0, p2 = std::sqrt(5.0 + r) / 3.0;
      const double s = 13.0 * std::sqrt(70.0);
      const double w1 = (322.0 + s) / 900.0, w2 = (322.0 - s) / 900.0;
      q.points = {-p2, -p1, 0.0, p1, p2};
      q.weights = {w2, w1, 128.0 / 225.0, w1, w2};
      break;
    }
    default:
      SHELLMPM_CHECK(false, "Gauss-Legendre rule with " << num_points << " points (1 to 5)");
  }
  return q;
}

}  // namespace shellmpm
