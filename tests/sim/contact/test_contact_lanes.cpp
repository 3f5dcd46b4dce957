// Contact gradients and frames of several sites at once (contact_lanes.h, on every
// instruction set; ShellContact::forces eight sites at a time) against one site alone:
// the same bits.
#include <catch2/catch.hpp>

#include <cstring>
#include <random>

#include "sim/contact/contact_lanes.h"
#include "sim/contact/shell_contact.h"
#include "sim/mpm/stress_batch.h"
#include "sim/shell/procedural_mesh.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

ContactParams params() {
  return test::contact_params();
}

bool same_bits(Real a, Real b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace

TEST_CASE(
    "contact gradients and frames on lanes give each lane the bits of its site alone, on "
    "every instruction set",
    "[contact]") {
  using namespace contact_lanes;
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-1, 1);
  GradientLanes in;
  FrameLanes fin;
  Vec3 b1[kLanes], b2[kLanes], b3[kLanes];
  for (int j = 0; j < kLanes; ++j) {
    // Compressed, separated and exactly at rest length (s3 = 1) sites, with shear.
    const Real s3 = j % 3 == 0 ? Real(0.7) + Real(0.2) * u(rng) : (j % 3 == 1 ? Real(1.1) : 1);
    b1[j] = Vec3(Real(1.1) + Real(0.1) * u(rng), Real(0.1) * u(rng), Real(0.1) * u(rng));
    b2[j] = Vec3(Real(0.2) * u(rng), Real(0.9), Real(0.1) * u(rng));
    b3[j] = Vec3(Real(0.2) * u(rng), Real(0.2) * u(rng), s3);
    for (int c = 0; c < 3; ++c) {
      in.a1[c][j] = b1[j][c];
      in.a2[c][j] = b2[j][c];
      in.a3e[c][j] = b3[j][c];
      fin.a1[c][j] = b1[j][c];
      fin.a2[c][j] = b2[j][c];
      fin.a3e[c][j] = b3[j][c];
    }
  }
  struct Restore {
    SimdLevel saved = simd_level();
    ~Restore() { set_simd_level(saved); }
  } restore;
  for (int level = 0; level <= static_cast<int>(simd_supported()); ++level) {
    set_simd_level(static_cast<SimdLevel>(level));
    INFO(simd_name(static_cast<SimdLevel>(level)));
    GradientLanes g = in;
    gradients(g, params());
    FrameLanes f = fin;
    frames(f);
    int compressed = 0;
    for (int j = 0; j < kLanes; ++j) {
      Mat3 G;
      const Real psi1 = contact_gradient<Real>(b1[j], b2[j], b3[j], params(), &G);
      compressed += G.col(2).norm() > Real(1e3);
      CHECK(same_bits(g.psi[j], psi1));
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i) CHECK(same_bits(g.g[c][i][j], G(i, c)));
      const ContactFrameT<double> fr =
          contact_frame<double>(b1[j].cast<double>(), b2[j].cast<double>(), b3[j].cast<double>());
      for (int i = 0; i < 3; ++i) {
        CHECK(f.s[i][j] == fr.s[i]);
        for (int c = 0; c < 3; ++c) CHECK(f.q[i][c][j] == fr.q[i][c]);
      }
    }
    CHECK(compressed >= 2);  // both branches of f(s3) are exercised
  }
}

namespace {

/// Checks c.forces(x) against contact_gradient on each site alone, bit for bit (G3, the
/// energy and the positions), where the site is not separated; a separated site has none,
/// and where the control points are those of its return mapping (`unmoved`) its own
/// gradient is round-off. Returns the number of compressed sites.
int check_forces(ShellContact& c, const std::vector<Vec3>& x, bool unmoved) {
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  const double e = c.forces(x.data(), f.data(), true);
  ShellContact ref = c;
  ref.update_positions(x.data(), true);
  double e1 = 0;
  int compressed = 0;
  for (std::size_t p = 0; p < c.num_sites(); ++p) {
    Vec3 a1, a2;
    c.tangents(x.data(), p, a1, a2);
    Mat3 G;
    const Real psi = contact_gradient<Real>(a1, a2, c.a3e[p], params(), &G);
    if (c.state[p] == static_cast<std::uint8_t>(ContactState::Separated)) {
      CHECK(c.G3[p] == Vec3::Zero());
      if (unmoved) CHECK(G.norm() < Real(1e-6) * Real(params().kc));
      CHECK(same_bits(c.x[p][0], ref.x[p][0]));
      continue;
    }
    e1 += static_cast<double>(c.volume[p] * psi);
    compressed += G.col(2).norm() > Real(1e3);  // k_c (1 - s3)^2 > 1e3 Pa
    for (int i = 0; i < 3; ++i) {
      CHECK(same_bits(c.G3[p][i], G(i, 2)));
      CHECK(same_bits(c.x[p][i], ref.x[p][i]));
    }
  }
  CHECK(e == e1);
  CHECK(f[x.size() / 2].norm() > 0);
  return compressed;
}

}  // namespace

TEST_CASE(
    "ShellContact::forces gives every site the scalar gradient's bits, partial lanes and "
    "tangents kept from the return mapping too, on every instruction set",
    "[contact]") {
  // (The return mapping's stencil sums run on AVX-512 where the machine has it; the
  // reference tangents are the scalar walk's.)
  struct Restore {
    SimdLevel saved = simd_level();
    ~Restore() { set_simd_level(saved); }
  } restore;
  const int level = GENERATE(range(0, 3));
  if (level > static_cast<int>(simd_supported())) return;
  set_simd_level(static_cast<SimdLevel>(level));
  INFO(simd_name(static_cast<SimdLevel>(level)));
  const ShellMesh sheet = make_sheet(1.0, 0.8, 7, 5);  // 70 sites: a partial last batch
  const LoopBasis basis(static_cast<int>(sheet.vertices.size()), sheet.triangles);
  ShellContact c(basis, sheet.vertices, 1e-3, 1, params());
  REQUIRE(c.num_sites() % 8 != 0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::vector<Vec3> x(sheet.vertices.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = sheet.vertices[i].cast<Real>() + Real(0.02) * Vec3(u(rng), u(rng), u(rng));
  for (std::size_t p = 0; p < c.num_sites(); ++p)  // compressed (~half) and separated
    c.a3e[p] = Vec3(Real(0.1) * u(rng), Real(0.9) + Real(0.2) * u(rng), Real(0.1) * u(rng));
  c.state.assign(c.num_sites(), static_cast<std::uint8_t>(ContactState::Sticking));
  CHECK(check_forces(c, x, false) > 10);
  // The return mapping keeps its tangents for these control points: the next forces()
  // takes them, with the same bits; the sites it separated have no force.
  c.return_map(x.data(), true);
  int separated = 0;
  for (const std::uint8_t st : c.state)
    separated += st == static_cast<std::uint8_t>(ContactState::Separated);
  CHECK(separated > 10);
  CHECK(check_forces(c, x, true) > 0);
  // Control points that moved after the return mapping: walked again.
  c.return_map(x.data(), true);
  x[x.size() / 2].y() += Real(0.01);
  CHECK(check_forces(c, x, false) > 0);
}
