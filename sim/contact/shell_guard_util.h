// Small helpers the shell guard's files share (sim/contact/shell_guard.cpp, its pairs and
// solve; shell_guard_candidates.cpp, its candidate lists).
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>

#include "sim/core/types.h"

namespace shellmpm {
namespace guard_util {

constexpr std::size_t kPointGrain = 4096;  ///< control points or limit vertices per chunk

inline Vec3d to_d(const Vec3& v) {
  return v.cast<double>();
}

/// Whether the boxes of the point sets a and b are farther apart than r on some axis (a
/// cheap test before an exact distance).
template <std::size_t NA, std::size_t NB>
inline bool boxes_apart(const std::array<const Vec3d*, NA>& a,
                        const std::array<const Vec3d*, NB>& b, double r) {
  for (int ax = 0; ax < 3; ++ax) {
    double alo = (*a[0])[ax], ahi = alo, blo = (*b[0])[ax], bhi = blo;
    for (std::size_t i = 1; i < NA; ++i) {
      alo = std::min(alo, (*a[i])[ax]);
      ahi = std::max(ahi, (*a[i])[ax]);
    }
    for (std::size_t i = 1; i < NB; ++i) {
      blo = std::min(blo, (*b[i])[ax]);
      bhi = std::max(bhi, (*b[i])[ax]);
    }
    if (blo - ahi >= r || alo - bhi >= r) return true;
  }
  return false;
}

}  // namespace guard_util
}  // namespace shellmpm
