// The gap between contact surfaces at a node (sim/contact/contact_gap.h) and the pair rule
// that lets two bodies close by it (sim/contact/field_contact.h, `allow`).
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "sim/contact/contact_gap.h"
#include "sim/contact/field_contact.h"
#include "sim/mpm/bspline.h"

using namespace shellmpm;

namespace {
/// The 1-D quadratic B-spline.
double bspline(double u) {
  u = std::abs(u);
  if (u < 0.5) return 0.75 - u * u;
  if (u < 1.5) return 0.5 * (1.5 - u) * (1.5 - u);
  return 0;
}
}  // namespace

TEST_CASE("the kernel's share beyond a plane is the integral of the B-spline", "[contact_gap]") {
  for (double s = -1.6; s <= 1.6; s += 0.05) {
    // Midpoint rule with 20000 intervals over [s, 1.5].
    double sum = 0;
    const double lo = std::max(s, -1.5), hi = 1.5, h = (hi - lo) / 20000;
    for (int i = 0; i < 20000 && hi > lo; ++i) sum += bspline(lo + (i + 0.5) * h) * h;
    INFO("s = " << s);
    CHECK(double(kernel_share_beyond(Real(s))) == Approx(sum).margin(2e-6));
  }
  CHECK(kernel_share_beyond(0) == Approx(0.5));
}

TEST_CASE("the surface distance inverts the kernel's share", "[contact_gap]") {
  for (double s = -1.45; s <= 1.45; s += 0.01) {
    const Real phi = kernel_share_beyond(Real(s));
    INFO("s = " << s << ", share " << phi);
    CHECK(double(surface_distance_from_share(phi)) == Approx(s).margin(1e-4));
  }
  CHECK(surface_distance_from_share(0) == Approx(1.5));
  CHECK(surface_distance_from_share(1) == Approx(-1.5));
  CHECK(surface_distance_from_share(Real(1.2)) == Approx(-1.5));  // compressed material
}

TEST_CASE("particles at two per cell and axis put their surface half a spacing past them",
          "[contact_gap]") {
  // Material filling y < Y with particles at (k + 1/2) dx/2 below Y, each of volume
  // (dx/2)^3: the volume fraction at a node, summed with the B-spline weights as the P2G
  // does, places the surface at Y within a twentieth of a cell, wherever Y lies against
  // the nodes (and with the material's lateral extent covering the stencil), for nodes up
  // to a cell from the surface: those whose stencils reach a body resting on it. (Past a
  // cell the share is the kernel's tip, 1/48 of it, and two particle layers decide it.)
  const double dx = 1;
  for (double Y = 0.0; Y < 1.0; Y += 0.0625) {
    for (int node = -2; node <= 3; ++node) {
      const double s_true = node - Y;  // node's distance above the surface, in cells
      if (std::abs(s_true) > 1.0) continue;
      double phi = 0;
      for (int k = 0; k < 12; ++k) {
        const double y = Y - (k + 0.5) * 0.5 * dx;
        phi += bspline(node - y) * 0.5;  // 2 particles per cell across; laterally: sum 1
      }
      INFO("surface at " << Y << ", node " << node);
      CHECK(double(surface_distance_from_share(Real(phi))) == Approx(s_true).margin(0.05));
    }
  }
}

TEST_CASE("bodies closing faster than the gap allows close exactly by it", "[contact_gap]") {
  const Vec3 n(0, 1, 0);  // from a towards b
  const Real dt = Real(1e-3), gap = Real(2e-3);
  const Real allow = closing_allowance(gap, dt);
  CHECK(allow == Approx(2.0));
  SECTION("too fast: the relative normal velocity becomes -gap/dt, momentum kept") {
    Vec3 va(0, 0, 0), vb(1, -5, 0);
    const Vec3 p0 = va / Real(0.5) + vb / Real(0.25);
    CHECK(field_contact(n, Real(0.2), Real(0.5), va, Real(0.25), vb, allow));
    CHECK(double((vb - va).dot(n)) == Approx(-2.0));
    // Friction takes c_F times the normal velocity removed (3 m/s) off the slip.
    CHECK(double((vb - va).x()) == Approx(1.0 - 0.2 * 3.0));
    CHECK(double((va / Real(0.5) + vb / Real(0.25) - p0).norm()) < 1e-5);
  }
  SECTION("slow enough: untouched, no friction") {
    Vec3 va(0, 0, 0), vb(Real(0.5), Real(-1.5), 0);
    const Vec3 b0 = vb;
    CHECK_FALSE(field_contact(n, Real(0.2), 1, va, 1, vb, allow));
    CHECK(vb == b0);
    CHECK(va == Vec3::Zero());
  }
  SECTION("touching: no approach at all; overlapping: they separate by a share of it") {
    CHECK(closing_allowance(0, dt) == 0);
    CHECK(closing_allowance(-std::numeric_limits<Real>::infinity(), dt) == 0);
    Vec3 va(0, 0, 0), vb(0, Real(-0.1), 0);
    CHECK(field_contact(n, 0, 1, va, 1, vb, closing_allowance(0, dt)));
    CHECK(double((vb - va).y()) == Approx(0.0).margin(1e-7));
    // 1 mm of overlap at a 1 ms step: a quarter of it undone within the step.
    const Real back = closing_allowance(Real(-1e-3), dt);
    CHECK(double(back) == Approx(-0.25));
    va = Vec3::Zero();
    vb = Vec3(0, Real(-0.1), 0);
    CHECK(field_contact(n, 0, 1, va, 1, vb, back));
    CHECK(double((vb - va).y()) == Approx(0.25));
    // Separating faster than that already: untouched.
    va = Vec3::Zero();
    vb = Vec3(0, 1, 0);
    CHECK_FALSE(field_contact(n, 0, 1, va, 1, vb, back));
  }
}

TEST_CASE("an overlap is undone at a rate that does not grow as the step shrinks",
          "[contact_gap]") {
  const Real overlap = Real(-1e-4);
  // Frame-sized steps: a quarter of the overlap per step.
  CHECK(double(closing_allowance(overlap, Real(1) / 240)) == Approx(-0.25 * 1e-4 * 240));
  CHECK(double(closing_allowance(overlap, Real(1) / 4000)) == Approx(-0.25 * 1e-4 * 4000));
  // Shorter steps, down to stiff steel's explicit step (1e-7 s): 0.1 mm parts at 0.1 m/s,
  // not the 250 m/s of a quarter per step.
  for (const Real dt : {Real(1e-4), Real(1e-5), Real(1e-7)}) {
    INFO("dt " << dt);
    CHECK(double(closing_allowance(overlap, dt)) == Approx(-1000 * 1e-4));
  }
  // While apart the bodies may close by the whole gap within the step, at any step.
  CHECK(double(closing_allowance(Real(1e-4), Real(1e-7))) == Approx(1e3));
}
