// The quartic box spline of a regular patch (sim/shell/box_spline.h): a partition of unity
// whose derivatives match central differences.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/shell/box_spline.h"

using shellmpm::box_spline;

TEST_CASE("box spline: partition of unity, derivatives match central differences",
          "[loop][box_spline]") {
  const double points[][2] = {{0.2, 0.3}, {0.0, 0.0}, {0.6, 0.1}, {1.0 / 3, 1.0 / 3}, {0.1, 0.85}};
  const double h = 1e-5;
  for (const auto& p : points) {
    CAPTURE(p[0], p[1]);
    double f[6][12], fu[2][6][12], fv[2][6][12];
    box_spline(p[0], p[1], f);
    box_spline(p[0] + h, p[1], fu[0]);
    box_spline(p[0] - h, p[1], fu[1]);
    box_spline(p[0], p[1] + h, fv[0]);
    box_spline(p[0], p[1] - h, fv[1]);
    double sum[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 12; ++k) {
      for (int q = 0; q < 6; ++q) sum[q] += f[q][k];
      CHECK(f[0][k] >= -1e-15);  // non-negative on the patch
      // First derivatives from values, second from first derivatives.
      CHECK(f[1][k] == Approx((fu[0][0][k] - fu[1][0][k]) / (2 * h)).margin(1e-8));
      CHECK(f[2][k] == Approx((fv[0][0][k] - fv[1][0][k]) / (2 * h)).margin(1e-8));
      CHECK(f[3][k] == Approx((fu[0][1][k] - fu[1][1][k]) / (2 * h)).margin(1e-7));
      CHECK(f[4][k] == Approx((fv[0][1][k] - fv[1][1][k]) / (2 * h)).margin(1e-7));
      CHECK(f[5][k] == Approx((fv[0][2][k] - fv[1][2][k]) / (2 * h)).margin(1e-7));
    }
    CHECK(sum[0] == Approx(1.0).margin(1e-14));
    for (int q = 1; q < 6; ++q) CHECK(sum[q] == Approx(0.0).margin(1e-12));
  }
}
