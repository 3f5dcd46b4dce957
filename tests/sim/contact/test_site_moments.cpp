// The contact sites' mass-weighted gradient moments (sim/contact/shell_transfer.h):
// site_dots_batch (eight sites at once, with every instruction-set level set; the per-ISA
// instances inside the shells' transfers are compared in test_contact_solver.cpp) against
// one site at a time, and the gradient's exactness for linear velocity fields.
#include <catch2/catch.hpp>

#include <cstring>
#include <random>

#include "sim/contact/shell_transfer.h"
#include "sim/mpm/stress_batch.h"

using namespace shellmpm;

namespace {

/// Node masses of a stencil: random, with some nodes empty, or a plane of nodes only.
void masses(std::mt19937& rng, int kind, Real (&m)[27]) {
  std::uniform_real_distribution<Real> u(0, 1);
  for (int n = 0; n < 27; ++n) {
    m[n] = u(rng) < Real(0.3) ? Real(0) : u(rng);
    if (kind == 1) m[n] = (n / 3) % 3 == 1 ? Real(0.5) + u(rng) : Real(0);  // one y layer
    if (kind == 2) m[n] = 0;                                                // no mass at all
  }
}

}  // namespace

TEST_CASE(
    "site moments: a batch gives each site's bits alone; the gradient is exact for "
    "linear velocities",
    "[contact]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> pos(10, 20);
  const Real dx = Real(0.01);
  for (int n = 1; n <= kSiteLanes; n += 3) {
    QuadraticWeights W[kSiteLanes];
    Real m[kSiteLanes][27];
    Vec3 u[kSiteLanes];
    SiteLaneInputs in;
    for (int i = 0; i < n; ++i) {
      W[i] = QuadraticWeights(Vec3(pos(rng), pos(rng), pos(rng)));
      masses(rng, i % 4 == 3 ? 1 : (i == 2 ? 2 : 0), m[i]);
      u[i] = Vec3(pos(rng), -pos(rng), pos(rng)) / Real(15);
      in.set(i, W[i], u[i]);
      for (int k = 0; k < 27; ++k) in.m[k][i] = m[i][k];
    }
    // Unweighted and weighted, on every instruction set the machine has.
    Real t[27][kSiteLanes], ga[27][kSiteLanes];
    bool any[kSiteLanes], any_w[kSiteLanes];
    SiteLaneInputs in2 = in;
    site_dots_batch(in, n, dx, false, t, any);
    site_dots_batch(in2, n, dx, true, ga, any_w);
    const SimdLevel best = simd_supported();
    for (int i = 0; i < n; ++i) {
      INFO("batch of " << n << ", site " << i);
      const Vec3i base(W[i].base[0], W[i].base[1], W[i].base[2]);
      int k = 0;
      Real mk[27];
      std::memcpy(mk, m[i], sizeof mk);
      const SiteMoments one =
          site_moments(W[i], dx, base, [&](const StencilNode&) { return mk[k++]; });
      REQUIRE(one.any == any[i]);
      REQUIRE(one.any == any_w[i]);
      CHECK(one.any == (i != 2));
      if (!one.any) continue;
      Real t1[27], ga1[27];
      one.offsets_dot(u[i], t1);
      one.dot(u[i], ga1);
      for (int c = 0; c < 27; ++c) {
        CHECK(std::memcmp(&t1[c], &t[c][i], sizeof(Real)) == 0);
        CHECK(std::memcmp(&ga1[c], &ga[c][i], sizeof(Real)) == 0);
      }
      for (int level = 0; level <= static_cast<int>(best); ++level) {
        set_simd_level(static_cast<SimdLevel>(level));
        SiteLaneInputs in3 = in2;
        Real ga3[27][kSiteLanes];
        bool any3[kSiteLanes];
        site_dots_batch(in3, n, dx, true, ga3, any3);
        for (int c = 0; c < 27; ++c) CHECK(std::memcmp(&ga1[c], &ga3[c][i], sizeof(Real)) == 0);
      }
      set_simd_level(best);
      // grad v u = sum_n v_n (g_n . u) for v = L x: L u, up to the regularisation (1e-3 of
      // the full-stencil moment) where the nodes with mass span all three axes.
      if (i % 4 == 3) continue;  // one layer of nodes: the normal axis rests on the rule
      Mat3 L;
      L << 1, 2, -1, 0.5, -3, 2, 4, 1, 0.25;
      const Vec3 v(Real(0.3), Real(-0.8), Real(0.52));
      Real gl[27];
      one.dot(v, gl);
      Vec3 sum = Vec3::Zero();
      int at = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          for (int c = 0; c < 3; ++c, ++at) {
            const Vec3 x =
                dx * Vec3(Real(W[i].base[0] + a), Real(W[i].base[1] + b), Real(W[i].base[2] + c));
            sum += gl[at] * (L * x);
          }
      CHECK((sum - L * v).norm() < Real(5e-3) * (L * v).norm());
    }
  }
}
