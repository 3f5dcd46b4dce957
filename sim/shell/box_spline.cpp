#include "sim/shell/box_spline.h"

namespace shellmpm {
namespace {

struct Term {
  int i, j, k;
  double c;
};
struct BoxFunction {
  int n;
  Term t[15];
};
const BoxFunction kBox[12] = {
    {2, {{4, 0, 0, 1}, {3, 1, 0, 2}}},
    {2, {{4, 0, 0, 1}, {3, 0, 1, 2}}},
    {9,
     {{4, 0, 0, 1},
      {3, 0, 1, 2},
      {3, 1, 0, 6},
      {2, 1, 1, 6},
      {2, 2, 0, 12},
      {1, 2, 1, 6},
      {1, 3, 0, 6},
      {0, 3, 1, 2},
      {0, 4, 0, 1}}},
    {15,
     {{4, 0, 0, 6},
      {3, 0, 1, 24},
      {2, 0, 2, 24},
      {1, 0, 3, 8},
      {0, 0, 4, 1},
      {3, 1, 0, 24},
      {2, 1, 1, 60},
      {1, 1, 2, 36},
      {0, 1, 3, 6},
      {2, 2, 0, 24},
      {1, 2, 1, 36},
      {0, 2, 2, 12},
      {1, 3, 0, 8},
      {0, 3, 1, 6},
      {0, 4, 0, 1}}},
    {9,
     {{4, 0, 0, 1},
      {3, 0, 1, 6},
      {2, 0, 2, 12},
      {1, 0, 3, 6},
      {0, 0, 4, 1},
      {3, 1, 0, 2},
      {2, 1, 1, 6},
      {1, 1, 2, 6},
      {0, 1, 3, 2}}},
    {2, {{1, 3, 0, 2}, {0, 4, 0, 1}}},
    {15,
     {{4, 0, 0, 1},
      {3, 0, 1, 6},
      {2, 0, 2, 12},
      {1, 0, 3, 6},
      {0, 0, 4, 1},
      {3, 1, 0, 8},
      {2, 1, 1, 36},
      {1, 1, 2, 36},
      {0, 1, 3, 8},
      {2, 2, 0, 24},
      {1, 2, 1, 60},
      {0, 2, 2, 24},
      {1, 3, 0, 24},
      {0, 3, 1, 24},
      {0, 4, 0, 6}}},
    {15,
     {{4, 0, 0, 1},
      {3, 0, 1, 8},
      {2, 0, 2, 24},
      {1, 0, 3, 24},
      {0, 0, 4, 6},
      {3, 1, 0, 6},
      {2, 1, 1, 36},
      {1, 1, 2, 60},
      {0, 1, 3, 24},
      {2, 2, 0, 12},
      {1, 2, 1, 36},
      {0, 2, 2, 24},
      {1, 3, 0, 6},
      {0, 3, 1, 8},
      {0, 4, 0, 1}}},
    {2, {{1, 0, 3, 2}, {0, 0, 4, 1}}},
    {2, {{0, 3, 1, 2}, {0, 4, 0, 1}}},
    {9,
     {{1, 0, 3, 2},
      {0, 0, 4, 1},
      {1, 1, 2, 6},
      {0, 1, 3, 6},
      {1, 2, 1, 6},
      {0, 2, 2, 12},
      {1, 3, 0, 2},
      {0, 3, 1, 6},
      {0, 4, 0, 1}}},
    {2, {{0, 0, 4, 1}, {0, 1, 3, 2}}},
};

}  // namespace

void box_spline(double xi1, double xi2, double out[6][12]) {
  const double u = xi1, v = xi2, w = 1.0 - xi1 - xi2;
  // Powers x^(e) for e = -2..4 at index e + 2 (negative powers only ever multiply 0).
  double pu[7] = {0, 0, 1, u, u * u, u * u * u, u * u * u * u};
  double pv[7] = {0, 0, 1, v, v * v, v * v * v, v * v * v * v};
  double pw3[7] = {0, 0, 1, w, w * w, w * w * w, w * w * w * w};
  for (int b = 0; b < 12; ++b) {
    double f = 0, fu = 0, fv = 0, fw = 0, fuu = 0, fvv = 0, fww = 0, fuv = 0, fuw = 0, fvw = 0;
    for (int m = 0; m < kBox[b].n; ++m) {
      const Term& t = kBox[b].t[m];
      const double U = pu[t.i + 2], V = pv[t.j + 2], W = pw3[t.k + 2];
      const double U1 = t.i * pu[t.i + 1], V1 = t.j * pv[t.j + 1], W1 = t.k * pw3[t.k + 1];
      const double U2 = t.i * (t.i - 1) * pu[t.i], V2 = t.j * (t.j - 1) * pv[t.j],
                   W2 = t.k * (t.k - 1) * pw3[t.k];
      f += t.c * U * V * W;
      fu += t.c * U1 * V * W;
      fv += t.c * U * V1 * W;
      fw += t.c * U * V * W1;
      fuu += t.c * U2 * V * W;
      fvv += t.c * U * V2 * W;
      fww += t.c * U * V * W2;
      fuv += t.c * U1 * V1 * W;
      fuw += t.c * U1 * V * W1;
      fvw += t.c * U * V1 * W1;
    }
    const double s = 1.0 / 12.0;
    out[0][b] = s * f;
    out[1][b] = s * (fu - fw);
    out[2][b] = s * (fv - fw);
    out[3][b] = s * (fuu - 2 * fuw + fww);
    out[4][b] = s * (fuv - fuw - fvw + fww);
    out[5][b] = s * (fvv - 2 * fvw + fww);
  }
}

}  // namespace shellmpm
