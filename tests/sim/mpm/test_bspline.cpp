#include <catch2/catch.hpp>
#include <random>

#include "sim/mpm/bspline.h"

using namespace shellmpm;

TEST_CASE("quadratic B-spline weights: partition of unity and zero gradient sum", "[bspline]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(3.0, 50.0);
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 g(Real(u(rng)), Real(u(rng)), Real(u(rng)));
    const QuadraticWeights W(g);
    double sum = 0, first[3] = {0, 0, 0};
    Vec3d gsum = Vec3d::Zero();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) {
          const double w = double(W.w[0][i]) * W.w[1][j] * W.w[2][k];
          sum += w;
          gsum += Vec3d(double(W.dw[0][i]) * W.w[1][j] * W.w[2][k],
                        double(W.w[0][i]) * W.dw[1][j] * W.w[2][k],
                        double(W.w[0][i]) * W.w[1][j] * W.dw[2][k]);
          // first moment: sum w (node - g) = 0 (linear reproduction)
          first[0] += w * (W.base[0] + i - double(g[0]));
          first[1] += w * (W.base[1] + j - double(g[1]));
          first[2] += w * (W.base[2] + k - double(g[2]));
        }
    REQUIRE(sum == Approx(1.0).epsilon(1e-5));
    REQUIRE(gsum.norm() < 1e-5);
    for (double f : first) REQUIRE(std::abs(f) < 1e-4);
    for (int a = 0; a < 3; ++a) {
      REQUIRE(W.fx[a] >= Real(0.5));
      REQUIRE(W.fx[a] < Real(1.5));
    }
  }
}

TEST_CASE("quadratic B-spline derivative matches finite differences", "[bspline]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(5.0, 6.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double x = u(rng);
    const QuadraticWeights W(Vec3(Real(x), 0, 0));
    const double h = 1e-3;
    const QuadraticWeights Wp(Vec3(Real(x + h), 0, 0)), Wm(Vec3(Real(x - h), 0, 0));
    if (Wp.base[0] != W.base[0] || Wm.base[0] != W.base[0]) continue;
    for (int k = 0; k < 3; ++k) {
      // dw is the derivative of the weight with respect to the particle position
      const double fd = (double(Wp.w[0][k]) - double(Wm.w[0][k])) / (2 * h);
      REQUIRE(fd == Approx(double(W.dw[0][k])).margin(5e-3));
    }
  }
}
