// A signed distance field sampled on a dense regular grid (negative inside).
// io/ builds these from meshes with OpenVDB; sim/ only samples them.
#pragma once
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

struct SdfGrid {
  Vec3d origin{0, 0, 0};      ///< world position of sample (0,0,0) [m]
  double spacing = 1.0;       ///< sample spacing [m]
  Vec3i dims{0, 0, 0};        ///< samples per axis
  float background = 1e3f;    ///< value returned outside the sampled box (positive: outside)
  std::vector<float> values;  ///< x fastest: values[(k*dims.y + j)*dims.x + i]

  /// Trilinear sample; positions outside the box return max(background, distance to box).
  double sample(const Vec3d& p) const;
  /// Central-difference gradient of the sampled field (not normalized).
  Vec3d gradient(const Vec3d& p) const;
};

}  // namespace shellmpm
