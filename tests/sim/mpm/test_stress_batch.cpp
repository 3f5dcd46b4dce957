// The constitutive batches on every instruction set the machine has
// (sim/mpm/stress_batch.h) give the same bits as the library's SSE code.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <random>
#include <vector>

#include "sim/mpm/constitutive.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

namespace {

/// Restores the level a test changed.
struct LevelGuard {
  SimdLevel saved = simd_level();
  ~LevelGuard() { set_simd_level(saved); }
};

bool same_bits(const void* a, const void* b, std::size_t bytes) {
  return std::memcmp(a, b, bytes) == 0;
}

MaterialDesc material(MaterialKind kind) {
  MaterialDesc d;
  d.name = "m";
  d.kind = kind;
  d.youngs_modulus = 1e5;
  d.poisson_ratio = 0.3;
  d.friction_angle_deg = 30;
  return d;
}

}  // namespace

TEST_CASE("the constitutive batches give the same bits on every instruction set", "[mpm]") {
  LevelGuard guard;
  INFO("this machine: " << simd_name(simd_supported()));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::size_t n = 1003;  // not a multiple of any lane count
  std::vector<Mat3> F0(n);
  std::vector<Real> p0(n);
  for (std::size_t i = 0; i < n; ++i) {
    Mat3 f = Mat3::Identity();
    for (int k = 0; k < 9; ++k) f.data()[k] += static_cast<Real>(0.6 * u(rng));
    if (i % 17 == 0) f.col(0) *= Real(-1);           // inverted
    if (i % 29 == 0) f.col(2) = f.col(1) * Real(2);  // singular
    F0[i] = f;
    p0[i] = static_cast<Real>(0.05 * (u(rng) + 1.0));
  }
  for (const MaterialKind kind : {MaterialKind::Elastic, MaterialKind::Sand, MaterialKind::Snow}) {
    const ConstitutiveModel m = ConstitutiveModel::from_desc(material(kind));
    std::vector<std::vector<Mat3>> tau(3), Fp(3), Fpk(3), taupk(3);
    std::vector<std::vector<Real>> pp(3), ppk(3);
    for (int level = 0; level <= static_cast<int>(simd_supported()); ++level) {
      set_simd_level(static_cast<SimdLevel>(level));
      REQUIRE(simd_level() == static_cast<SimdLevel>(level));
      tau[level].resize(n);
      m.kirchhoff_batch(F0.data(), p0.data(), tau[level].data(), n);
      Fp[level] = F0;
      pp[level] = p0;
      m.project_batch(Fp[level].data(), pp[level].data(), n);
      Fpk[level] = F0;
      ppk[level] = p0;
      taupk[level].resize(n);
      m.project_and_kirchhoff_batch(Fpk[level].data(), ppk[level].data(), taupk[level].data(), n);
      if (level == 0) continue;
      INFO(simd_name(static_cast<SimdLevel>(level))
           << " against sse, kind " << static_cast<int>(kind));
      CHECK(same_bits(tau[level].data(), tau[0].data(), n * sizeof(Mat3)));
      CHECK(same_bits(Fp[level].data(), Fp[0].data(), n * sizeof(Mat3)));
      CHECK(same_bits(pp[level].data(), pp[0].data(), n * sizeof(Real)));
      CHECK(same_bits(Fpk[level].data(), Fpk[0].data(), n * sizeof(Mat3)));
      CHECK(same_bits(taupk[level].data(), taupk[0].data(), n * sizeof(Mat3)));
    }
    // And the batch is what the per-particle call gives, to rounding.
    for (std::size_t i = 0; i < n; i += 97)
      CHECK((tau[0][i] - m.kirchhoff(F0[i], p0[i])).norm() <=
            1e-4 * (1 + m.kirchhoff(F0[i], p0[i]).norm()));
  }
}

TEST_CASE("a sand and jelly run gives the same bits on every instruction set", "[mpm][solver]") {
  // The constitutive batches and the transfers' per-ISA blocks (sim/mpm/transfer_blocks.h)
  // together, APIC and MLS-MPM.
  LevelGuard guard;
  Scene s;
  s.path = "test";
  s.shot.dx = 0.05;
  s.shot.domain_min = Vec3d(-1, -1, -1);
  s.shot.domain_max = Vec3d(1, 1.5, 1);
  s.shot.fps = 48;
  s.materials = {material(MaterialKind::Elastic), material(MaterialKind::Sand)};
  s.materials[1].name = "sand";
  for (int k = 0; k < 2; ++k) {
    SourceDesc src;
    src.material = k;
    src.shape.kind = ShapeDesc::Kind::Box;
    src.shape.min = Vec3d(-0.3 + 0.35 * k, -0.2, -0.15);
    src.shape.max = Vec3d(-0.05 + 0.35 * k, 0.2, 0.15);
    src.velocity = Vec3d(0.4 - 0.8 * k, 0.1, 0.3);  // the blocks meet: C and F far from rest
    s.sources.push_back(src);
  }
  for (const Transfer transfer : {Transfer::Apic, Transfer::Mls}) {
    s.shot.transfer = transfer;
    std::vector<ParticleSet> runs;
    for (int level = 0; level <= static_cast<int>(simd_supported()); ++level) {
      set_simd_level(static_cast<SimdLevel>(level));
      Solver solver(s);
      solver.advance_to(4.0 / 48);
      runs.push_back(solver.particles());
      if (level == 0) continue;
      const ParticleSet &a = runs.back(), &b = runs[0];
      INFO(simd_name(static_cast<SimdLevel>(level))
           << " against sse, " << (transfer == Transfer::Mls ? "mls" : "apic"));
      REQUIRE(a.size() == b.size());
      CHECK(same_bits(a.x.data(), b.x.data(), b.size() * sizeof(Vec3)));
      CHECK(same_bits(a.v.data(), b.v.data(), b.size() * sizeof(Vec3)));
      CHECK(same_bits(a.C.data(), b.C.data(), b.size() * sizeof(Mat3)));
      CHECK(same_bits(a.F.data(), b.F.data(), b.size() * sizeof(Mat3)));
    }
    CHECK(runs[0].size() > 1000);
    // The blocks moved and deformed: the comparison is not of particles at rest.
    Real max_c = 0;
    for (const Mat3& c : runs[0].C) max_c = std::max(max_c, c.cwiseAbs().maxCoeff());
    CHECK(max_c > Real(0.1));
  }
}
