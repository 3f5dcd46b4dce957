// Quadratic B-spline interpolation weights (Stomakhin et al. 2013, eq. (123) of the
// SIGGRAPH 2016 MPM course notes). A particle at grid coordinate g (position / dx)
// touches nodes base + {0,1,2} per axis with base = floor(g - 0.5).
#pragma once
#include <cmath>

#include "sim/core/types.h"

namespace shellmpm {

/// Weights and derivatives (w.r.t. grid coordinate, multiply by 1/dx for world) per axis.
struct QuadraticWeights {
  int base[3];    ///< lowest node index per axis
  Real fx[3];     ///< g - base, in [0.5, 1.5)
  Real w[3][3];   ///< w[axis][k], k = node offset 0..2
  Real dw[3][3];  ///< dw/dg

  QuadraticWeights() = default;  ///< unset (a slot to fill)
  /// g: particle position in grid units (position relative to the grid origin / dx).
  explicit QuadraticWeights(const Vec3& g) {
    for (int a = 0; a < 3; ++a) {
      const int b = static_cast<int>(std::floor(g[a] - Real(0.5)));
      base[a] = b;
      const Real f = g[a] - Real(b);
      fx[a] = f;
      const Real d0 = Real(1.5) - f, d1 = f - Real(1), d2 = f - Real(0.5);
      w[a][0] = Real(0.5) * d0 * d0;
      w[a][1] = Real(0.75) - d1 * d1;
      w[a][2] = Real(0.5) * d2 * d2;
      dw[a][0] = -d0;
      dw[a][1] = Real(-2) * d1;
      dw[a][2] = d2;
    }
  }
};

}  // namespace shellmpm
