// Coulomb friction of one contact particle: the return mapping of its contact strain
// (Guo et al. 2018, supplement section 6, eqs. 24-26), applied after every step to the
// third column s of R (contact_energy.h).
#pragma once
#include <cmath>

#include "sim/contact/contact_energy.h"

namespace shellmpm {

/// What the return mapping did to one particle.
enum class ContactState : unsigned char { Separated = 0, Sticking = 1, Sliding = 2 };

/// Coulomb return mapping on s (supplement sec. 6): separated (s3 > 1) -> (0, 0, 1);
/// compressed with gamma |(s1, s2)| > c_F k_c (1 - s3)^2 -> shear scaled onto that bound.
template <class T>
ContactState contact_return_map(Eigen::Matrix<T, 3, 1>& s, const ContactParams& p) {
  if (s[2] >= 1) {
    s = Eigen::Matrix<T, 3, 1>(0, 0, 1);
    return ContactState::Separated;
  }
  const T c = 1 - s[2];
  const T bound = static_cast<T>(p.friction * p.kc / p.gamma) * c * c;
  const T n = std::sqrt(s[0] * s[0] + s[1] * s[1]);
  if (n > bound) {
    const T k = n > 0 ? bound / n : T(0);
    s[0] *= k;
    s[1] *= k;
    return ContactState::Sliding;
  }
  return ContactState::Sticking;
}

}  // namespace shellmpm
