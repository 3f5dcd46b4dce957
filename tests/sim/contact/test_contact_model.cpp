// Contact elasticity and friction of one contact particle (sim/contact/contact_energy.h,
// friction_return_map.h): finite differences of the energy against its gradient and Kirchhoff
// stress, and the Coulomb return mapping.
#include <catch2/catch.hpp>
#include <random>

#include "sim/contact/contact_energy.h"
#include "sim/contact/friction_return_map.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

namespace {

ContactParams params() {
  return test::contact_params();
}

// A random deformed site: tangents near an orthogonal frame, a3E compressed (s3 in
// (0.3, 0.95)) or separated (s3 > 1), with shear.
void random_site(std::mt19937& rng, bool compressed, V3& a1, V3& a2, V3& a3) {
  std::uniform_real_distribution<double> u(-1, 1);
  const M3 R = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized())
                   .toRotationMatrix();
  a1 = R * V3(1.2 + 0.2 * u(rng), 0.1 * u(rng), 0);
  a2 = R * V3(0.3 * u(rng), 0.9 + 0.2 * u(rng), 0);
  const double s3 = compressed ? 0.6 + 0.3 * u(rng) : 1.2 + 0.1 * u(rng);
  a3 = R * V3(0.2 * u(rng), 0.2 * u(rng), s3);
}

// Max over the 9 entries of |FD - analytic| / max |analytic|.
double fd_error(const V3& a1, const V3& a2, const V3& a3, double eps) {
  const ContactParams p = params();
  M3 G;
  contact_gradient<double>(a1, a2, a3, p, &G);
  M3 D;
  D << a1, a2, a3;
  double err = 0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      M3 Dp = D, Dm = D;
      Dp(r, c) += eps;
      Dm(r, c) -= eps;
      const double ep = contact_gradient<double>(Dp.col(0), Dp.col(1), Dp.col(2), p, nullptr);
      const double em = contact_gradient<double>(Dm.col(0), Dm.col(1), Dm.col(2), p, nullptr);
      err = std::max(err, std::abs((ep - em) / (2 * eps) - G(r, c)));
    }
  return err / G.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("contact energy gradient matches finite differences, error falls with eps", "[contact]") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    V3 a1, a2, a3;
    random_site(rng, trial % 4 != 3, a1, a2, a3);
    const double e1 = fd_error(a1, a2, a3, 1e-3);
    const double e2 = fd_error(a1, a2, a3, 1e-4);
    INFO("trial " << trial << " errors " << e1 << " " << e2);
    CHECK(e2 < 1e-6);
    CHECK(e2 < 0.05 * e1);  // second-order convergence: 100x per decade, allow 20x
  }
}

TEST_CASE("contact Kirchhoff stress is eq. (23) in the QR frame and equals dpsi/dD D^T",
          "[contact]") {
  std::mt19937 rng(11);
  const ContactParams p = params();
  for (int trial = 0; trial < 20; ++trial) {
    V3 a1, a2, a3;
    random_site(rng, true, a1, a2, a3);
    M3 G;
    contact_gradient<double>(a1, a2, a3, p, &G);
    M3 D;
    D << a1, a2, a3;
    const M3 tau = contact_kirchhoff<double>(a1, a2, a3, p);
    const M3 tau_fd = G * D.transpose();  // tau = P F^T = (dpsi/dD) D^T
    INFO("tau\n" << tau << "\nG D^T\n" << tau_fd);
    CHECK((tau - tau_fd).cwiseAbs().maxCoeff() < 1e-9 * tau.cwiseAbs().maxCoeff());
    CHECK((tau - tau.transpose()).cwiseAbs().maxCoeff() < 1e-9 * tau.cwiseAbs().maxCoeff());
    // Compression pushes: the normal stress q3 . tau q3 = f'(s3) s3 < 0.
    const ContactFrameT<double> f = contact_frame<double>(a1, a2, a3);
    CHECK(f.q[2].dot(tau * f.q[2]) < 0);
  }
}

TEST_CASE("contact energy is zero at rest and under rotations", "[contact]") {
  const ContactParams p = params();
  const M3 R = Eigen::AngleAxisd(0.7, V3(1, 2, 3).normalized()).toRotationMatrix();
  M3 G;
  const V3 a1 = R * V3(1.3, 0, 0), a2 = R * V3(0.2, 0.8, 0), a3 = R * V3(0, 0, 1);
  // Round-off only: shear of order 1e-16 gives gamma s^2 ~ 1e-27 and gamma s ~ 1e-11.
  CHECK(contact_gradient<double>(a1, a2, a3, p, &G) < 1e-20);
  CHECK(G.cwiseAbs().maxCoeff() < 1e-9);
  // Stretched normal column (separated): no energy from f, no shear.
  CHECK(contact_gradient<double>(a1, a2, 1.5 * a3, p, nullptr) < 1e-20);
  // A compressed column does store energy (the checks above can fail).
  CHECK(contact_gradient<double>(a1, a2, 0.9 * a3, p, nullptr) > 1.0);
}

TEST_CASE("contact return mapping: inside kept, outside onto the cone, separated reset",
          "[contact]") {
  const ContactParams p = params();
  const double ratio = p.friction * p.kc / p.gamma;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const double s3 = 0.2 + 1.2 * std::abs(u(rng));
    V3 s(0.3 * u(rng), 0.3 * u(rng), s3);
    const V3 s0 = s;
    const double psi0 = contact_energy_density<double>(s0, p);
    const ContactState st = contact_return_map<double>(s, p);
    const double psi1 = contact_energy_density<double>(s, p);
    const double bound = ratio * (1 - s3) * (1 - s3);
    const double shear0 = std::hypot(s0[0], s0[1]);
    INFO("s0 " << s0.transpose() << " -> " << s.transpose());
    if (s3 >= 1) {
      CHECK(st == ContactState::Separated);
      CHECK(s == V3(0, 0, 1));
    } else if (shear0 <= bound) {
      CHECK(st == ContactState::Sticking);
      CHECK(s == s0);  // bitwise untouched
    } else {
      CHECK(st == ContactState::Sliding);
      CHECK(std::hypot(s[0], s[1]) == Approx(bound).epsilon(1e-12));
      CHECK(s[2] == s0[2]);
      // Same direction, scaled down.
      CHECK(s[0] * s0[1] - s[1] * s0[0] == Approx(0).margin(1e-15));
      CHECK(s[0] * s0[0] + s[1] * s0[1] >= 0);
    }
    CHECK(psi1 <= psi0 + 1e-12);  // the projection never adds energy
  }
}
