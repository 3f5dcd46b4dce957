// Bardenhagen's pair rule between two velocity fields at a node (sim/contact/field_contact.h).
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "sim/contact/field_contact.h"

using namespace shellmpm;

namespace {
Vec3 momentum(Real wa, const Vec3& va, Real wb, const Vec3& vb) {
  return va / wa + vb / wb;
}
}  // namespace

TEST_CASE("approaching fields end with one normal velocity, momentum unchanged",
          "[field_contact]") {
  const Vec3 n(0, 1, 0);                          // from a towards b
  const Real wa = Real(1) / 2, wb = Real(1) / 3;  // masses 2 and 3
  Vec3 va(0, 1, 0), vb(0, -1, 0);
  const Vec3 p0 = momentum(wa, va, wb, vb);
  field_contact(n, 0, wa, va, wb, vb);
  CHECK(va.y() == Approx(vb.y()));
  // The common normal velocity is the centre-of-mass one: (2 * 1 + 3 * -1) / 5.
  CHECK(va.y() == Approx(-0.2));
  CHECK((momentum(wa, va, wb, vb) - p0).norm() < 1e-5);
}

TEST_CASE("separating fields keep their velocities", "[field_contact]") {
  const Vec3 n(0, 1, 0);
  Vec3 va(0.3, -1, 0), vb(-0.2, 1, 0.5);
  const Vec3 a0 = va, b0 = vb;
  field_contact(n, 0.5, 1, va, 1, vb);
  CHECK(va == a0);
  CHECK(vb == b0);
}

TEST_CASE("friction takes c_F times the normal approach off the slip, or sticks",
          "[field_contact]") {
  const Vec3 n(0, 0, 1);
  // Equal masses, relative velocity u = vb - va = (2, 0, -1): normal approach 1, slip 2.
  Vec3 va(0, 0, 0), vb(2, 0, -1);
  field_contact(n, 0.5, 1, va, 1, vb);
  const Vec3 u = vb - va;
  CHECK(std::abs(u.z()) < 1e-6);                    // no relative normal motion left
  CHECK(u.x() == Approx(2 - 0.5 * 1));              // slip reduced by c_F * 1
  CHECK((va + vb - Vec3(2, 0, -1)).norm() < 1e-6);  // momentum (equal masses)
  // With c_F * approach above the slip, the fields stick: no relative velocity at all.
  va = Vec3(0, 0, 0);
  vb = Vec3(0.2, 0, -1);
  field_contact(n, 0.5, 1, va, 1, vb);
  CHECK((vb - va).norm() < 1e-6);
}

TEST_CASE("a pinned field (inverse mass 0) does not move, and the other takes it all",
          "[field_contact]") {
  const Vec3 n(1, 0, 0);
  Vec3 va(0.5, 0, 0), vb(-1, 0.25, 0);
  field_contact(n, 0, 0, va, 1, vb);
  CHECK(va == Vec3(0.5, 0, 0));
  CHECK(vb.x() == Approx(0.5));   // takes the pinned field's normal velocity
  CHECK(vb.y() == Approx(0.25));  // frictionless: the slip stays
  // Both pinned: nothing to do.
  Vec3 a(1, 0, 0), b(-1, 0, 0);
  field_contact(n, 0, 0, a, 0, b);
  CHECK(a == Vec3(1, 0, 0));
  CHECK(b == Vec3(-1, 0, 0));
}

TEST_CASE("a field's inverse mass stays finite for tiny masses, and the rule with it",
          "[field_contact]") {
  CHECK(inverse_field_mass(2, 0) == Approx(0.5));
  CHECK(inverse_field_mass(2, 2) == 0);  // fully pinned: infinitely heavy
  CHECK(inverse_field_mass(2, 1) == Approx(0.25));
  CHECK(inverse_field_mass(0, 0) == 0);  // no mass: no part
  // m^2 underflows to zero (float: m below about 4e-23): the old (m - held) / (m m)
  // was 0/0 or x/0 there.
  const Real tiny = std::sqrt(std::numeric_limits<Real>::denorm_min()) / 4;  // m m == 0
  const Real w = inverse_field_mass(tiny, 0);
  CHECK(std::isfinite(w));
  CHECK(w == Approx(1 / tiny).epsilon(1e-5));  // (m - 0) / m^2 = 1 / m
  CHECK(inverse_field_mass(tiny, tiny / 2) == Approx(0.5 * w).epsilon(1e-5));
  // A subnormal mass takes no part, rather than an infinite inverse mass.
  CHECK(inverse_field_mass(std::numeric_limits<Real>::denorm_min(), 0) == 0);
  // Two such fields meeting: velocities stay finite and end with one normal velocity.
  Vec3 va(0, 1, 0), vb(0, -1, 0);
  field_contact(Vec3(0, 1, 0), Real(0.3), w, va, inverse_field_mass(2 * tiny, 0), vb);
  CHECK(va.allFinite());
  CHECK(vb.allFinite());
  CHECK(va.y() == Approx(vb.y()));
}
