// The batched float Kirchhoff-Love kernel (sim/shell/kl_batch.cpp) and its lane
// logarithm (sim/shell/kl_lanes.h).
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "sim/mpm/stress_batch.h"
#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/kl_lanes.h"
#include "sim/shell/shell_object.h"
#include "tests/support/bezier_test_basis.h"

using namespace shellmpm;
using shellmpm_test::BezierShell;

namespace {

/// Distance in units in the last place between two finite floats of the same sign.
long ulp_distance(float a, float b) {
  std::int32_t ia, ib;
  std::memcpy(&ia, &a, 4);
  std::memcpy(&ib, &b, 4);
  return std::labs(static_cast<long>(ia) - static_cast<long>(ib));
}

float lane_log(float x) {
  const kl::lanes::F4 r = kl::lanes::vlog(kl::lanes::F4{x, 1.0f, 2.0f, 0.5f});
  return r[0];
}

ShellMaterialDesc metal() {
  ShellMaterialDesc m;
  m.youngs_modulus = 1e9;
  m.poisson_ratio = 0.3;
  m.density = 2700;
  m.thickness = 0.01;
  m.yield_stress = 2e6;
  return m;
}

/// Every layer's F^P moved off identity by up to 0.05 (rng), then positions from rest:
/// stretched 1.9x along x past x = 0.5 (past the default stretch limit 1.5), bent and
/// perturbed everywhere, and shifted by `offset`.
std::vector<Eigen::Vector3f> plastic_and_bent(KirchhoffLoveShellT<float>& shf,
                                              const std::vector<Eigen::Vector3d>& rest,
                                              std::mt19937& rng, const Eigen::Vector3f& offset) {
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> pf = shf.plastic_state();
  for (float& v : pf) v += 0.05f * u(rng);
  shf.set_plastic_state(pf);
  std::vector<Eigen::Vector3f> x(rest.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    Eigen::Vector3d p = rest[i];
    if (p.x() > 0.5) p.x() = 0.5 + 1.9 * (p.x() - 0.5);
    p.z() += 0.1 * p.x() * p.x() + 0.01 * u(rng);
    x[i] = p.cast<float>() + offset;
  }
  return x;
}

}  // namespace

TEST_CASE("the four-lane fused multiply-add has the bits of a single rounding", "[kl]") {
  // madd4 without the FMA instruction (this file is compiled without it) against fmaf,
  // which rounds once. The naive double sum fails on the second kind of case below.
#ifdef __FMA__
  WARN("compiled with FMA: madd4 is the instruction here, not the double emulation");
#endif
  const auto madd = [](float a, float b, float c) {
    float out[4];
    _mm_storeu_ps(out,
                  kl::lanes::madd4(_mm_set_ps(0.0f, 0.0f, c, a), _mm_set_ps(0.0f, 1.0f, 0.0f, b),
                                   _mm_set_ps(c, 0.0f, 0.0f, c)));
    return out[0];
  };
  const auto same = [](float x, float y) {
    std::uint32_t bx, by;
    std::memcpy(&bx, &x, 4);
    std::memcpy(&by, &y, 4);
    return bx == by || (std::isnan(x) && std::isnan(y));
  };
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> mant(-2.0f, 2.0f);
  std::uniform_int_distribution<int> expo(-70, 70);
  long wrong = 0, naive_wrong = 0;
  for (int i = 0; i < 300000; ++i) {
    const float a = std::ldexp(mant(rng), expo(rng)), b = std::ldexp(mant(rng), expo(rng));
    // c at random, or near -a b (cancellation), or a tiny nudge off a halfway product.
    float c = std::ldexp(mant(rng), expo(rng));
    if (i % 3 == 1) c = -static_cast<float>(static_cast<double>(a) * b) * (1 + 1e-6f * mant(rng));
    wrong += !same(madd(a, b, c), std::fmaf(a, b, c));
  }
  // Products halfway between floats, broken by a c below double precision: the sum rounds
  // to the tie in double and then to even in float, where fmaf rounds away from it.
  for (int k = 1; k < 12; ++k) {
    const float a = 1.0f + std::ldexp(1.0f, -k), b = 1.0f + std::ldexp(1.0f, -24 + k);
    for (const float c : {std::ldexp(1.0f, -60), -std::ldexp(1.0f, -60), 0.0f}) {
      const float want = std::fmaf(a, b, c);
      wrong += !same(madd(a, b, c), want);
      naive_wrong +=
          static_cast<float>(static_cast<double>(a) * b + static_cast<double>(c)) != want;
    }
  }
  CHECK(wrong == 0);
  CHECK(naive_wrong > 0);  // the cases do test the rounding to odd
  // Signs of zero, overflow, subnormal results, infinities and NaN.
  const float inf = std::numeric_limits<float>::infinity(), big = 3e38f, tiny = 1e-30f;
  const float cases[][3] = {{0.0f, 1.0f, -0.0f},   {-0.0f, 1.0f, -0.0f},       {1.0f, -1.0f, 1.0f},
                            {big, 10.0f, 0.0f},    {big, 10.0f, -big},         {tiny, tiny, 0.0f},
                            {tiny, tiny, -1e-45f}, {inf, 1.0f, 1.0f},          {inf, 0.0f, 1.0f},
                            {1.0f, 1.0f, -inf},    {std::nanf(""), 1.0f, 1.0f}};
  for (const auto& t : cases) {
    INFO(t[0] << " * " << t[1] << " + " << t[2]);
    CHECK(same(madd(t[0], t[1], t[2]), std::fmaf(t[0], t[1], t[2])));
  }
}

TEST_CASE("the lane logarithm is within 2 ulp of std::log, with its special values", "[kl]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> mant(1.0f, 2.0f);
  std::uniform_int_distribution<int> expo(-120, 120);
  long worst = 0;
  for (int i = 0; i < 200000; ++i) {
    const float x = std::ldexp(mant(rng), expo(rng));
    const float ref = static_cast<float>(std::log(static_cast<double>(x)));
    const float got = lane_log(x);
    if (std::abs(ref) < 1e-30f) continue;
    if ((ref > 0) != (got > 0)) {
      CHECK(std::abs(got - ref) < 1e-7f);
      continue;
    }
    worst = std::max(worst, ulp_distance(got, ref));
  }
  // Near 1 (log x ~ x - 1, the hardest place for relative accuracy).
  for (int i = -2000; i <= 2000; ++i) {
    const float x = 1.0f + static_cast<float>(i) * 1e-6f;
    if (x == 1.0f) continue;
    const float ref = static_cast<float>(std::log(static_cast<double>(x)));
    worst = std::max(worst, ulp_distance(lane_log(x), ref));
  }
  INFO("worst " << worst << " ulp");
  CHECK(worst <= 2);
  CHECK(lane_log(1.0f) == 0.0f);
  CHECK(std::isinf(lane_log(0.0f)));
  CHECK(lane_log(0.0f) < 0);
  CHECK(std::isnan(lane_log(-1.0f)));
  CHECK(std::isnan(lane_log(std::numeric_limits<float>::quiet_NaN())));
  CHECK(std::isinf(lane_log(std::numeric_limits<float>::infinity())));
}

TEST_CASE(
    "the float KL kernel matches double with plasticity, past the stretch limit and "
    "in a part batch",
    "[kl]") {
  // 3 x 3 patches, two triangles each, 7-point rules: 126 points, not a multiple of four.
  const BezierShell s = shellmpm_test::make_bezier_grid(3, 3, 7);
  REQUIRE(s.points.size() % 4 != 0);
  const std::vector<Eigen::Vector3d> rest =
      shellmpm_test::interpolate(s, [](const Eigen::Vector2d& uv) {
        return Eigen::Vector3d(uv.x(), uv.y(), 0.2 * std::sin(2.0 * uv.x()) * uv.y());
      });
  KirchhoffLoveShellT<double> shd(s.points, s.weights, rest, metal(), 3);
  KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, metal(), 3);
  // A stored plastic state: every layer a different F^P near identity.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> pd = shd.plastic_state();
  for (std::size_t i = 0; i < pd.size(); ++i) pd[i] += 0.05 * u(rng);
  shd.set_plastic_state(pd);
  shf.set_plastic_state(std::vector<float>(pd.begin(), pd.end()));
  // Stretched 1.9x along x (past the default stretch limit 1.5) on one side, bent and
  // perturbed everywhere.
  std::vector<Eigen::Vector3d> x = rest;
  for (Eigen::Vector3d& p : x) {
    if (p.x() > 0.5) p.x() = 0.5 + 1.9 * (p.x() - 0.5);
    p.z() += 0.1 * p.x() * p.x() + 0.01 * u(rng);
  }
  std::vector<Eigen::Vector3d> fd(x.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3f> xf(x.size()), ff(x.size(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < x.size(); ++i) xf[i] = x[i].cast<float>();
  const double ed = shd.energy(x.data(), fd.data()).total;
  const auto ef = shf.energy(xf.data(), ff.data());
  CHECK(shd.max_strain(x.data()) > std::log(1.5));  // the stretch term is on somewhere
  CHECK(double(ef.total) == Approx(ed).epsilon(1e-4));
  double scale = 0;
  for (const auto& f : fd) scale = std::max(scale, f.norm());
  REQUIRE(scale > 0);
  for (std::size_t i = 0; i < x.size(); ++i)
    CHECK((ff[i].cast<double>() - fd[i]).norm() < 1e-4 * scale);
  // The membrane diagnostic does not change the total or the forces.
  std::vector<Eigen::Vector3f> ff2(x.size(), Eigen::Vector3f::Zero());
  const auto ef2 = shf.energy(xf.data(), ff2.data(), false, false);
  CHECK(ef2.total == ef.total);
  CHECK(std::memcmp(ff2.data(), ff.data(), ff.size() * sizeof(Eigen::Vector3f)) == 0);
  CHECK(ef.membrane > 0);
}

TEST_CASE("the float KL kernel gives the same bits on every instruction set", "[kl][simd]") {
  // 126 points: every width ends in a part register. Plastic, past the stretch limit on
  // one side, bent and perturbed, as above.
  const BezierShell s = shellmpm_test::make_bezier_grid(3, 3, 7);
  const std::vector<Eigen::Vector3d> rest =
      shellmpm_test::interpolate(s, [](const Eigen::Vector2d& uv) {
        return Eigen::Vector3d(uv.x(), uv.y(), 0.2 * std::sin(2.0 * uv.x()) * uv.y());
      });
  KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, metal(), 3);
  std::mt19937 rng(4);
  const std::vector<Eigen::Vector3f> x =
      plastic_and_bent(shf, rest, rng, Eigen::Vector3f(100.0f, -50.0f, 20.0f));  // far out
  struct Restore {
    SimdLevel saved = simd_level();
    ~Restore() { set_simd_level(saved); }
  } restore;
  INFO("this machine: " << simd_name(simd_supported()));
  // On patches (18 faces of 7 points: part registers at every width) and point by point.
  REQUIRE(shf.patched());
  const bool patches = GENERATE(true, false);
  shf.use_patches(patches);
  INFO("patches " << patches);
  std::vector<Eigen::Vector3f> ref;
  KirchhoffLoveShellT<float>::Energy eref{};
  for (int level = 0; level <= static_cast<int>(simd_supported()); ++level) {
    set_simd_level(static_cast<SimdLevel>(level));
    INFO("level " << simd_name(simd_level()));
    std::vector<Eigen::Vector3f> f(x.size(), Eigen::Vector3f::Zero());
    const auto e = shf.energy(x.data(), f.data(), false, true);
    CHECK(e.total > 0);
    if (level == 0) {
      ref = f;
      eref = e;
      continue;
    }
    CHECK(std::memcmp(&e.total, &eref.total, sizeof e.total) == 0);
    CHECK(std::memcmp(&e.membrane, &eref.membrane, sizeof e.membrane) == 0);
    CHECK(std::memcmp(f.data(), ref.data(), f.size() * sizeof(Eigen::Vector3f)) == 0);
  }
}

TEST_CASE(
    "KL patches: a Loop sheet's faces form them; the same energy as point by point and the "
    "forces to rounding; points in uneven runs go point by point",
    "[kl]") {
  // A Loop sheet with the default 3-point rule: one patch per face, a handful of patterns.
  ShellDesc sd;
  sd.kind = ShellDesc::Kind::Sheet;
  sd.size[0] = sd.size[1] = 1.0;
  sd.resolution[0] = sd.resolution[1] = 6;
  ShellMaterialDesc mat = metal();
  const ShellObject sheet(sd, mat, build_shell_rest_mesh(sd));
  CHECK(sheet.kl().patched());

  // Bezier patches (7 points each), plastic, stretched past the limit, bent.
  const BezierShell s = shellmpm_test::make_bezier_grid(3, 3, 7);
  const std::vector<Eigen::Vector3d> rest =
      shellmpm_test::interpolate(s, [](const Eigen::Vector2d& uv) {
        return Eigen::Vector3d(uv.x(), uv.y(), 0.2 * std::sin(2.0 * uv.x()) * uv.y());
      });
  KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, mat, 3);
  REQUIRE(shf.patched());
  std::mt19937 rng(6);
  const std::vector<Eigen::Vector3f> x = plastic_and_bent(shf, rest, rng, Eigen::Vector3f::Zero());
  std::vector<Eigen::Vector3f> fp(x.size(), Eigen::Vector3f::Zero()), fq = fp;
  const auto ep = shf.energy(x.data(), fp.data(), false, true);
  shf.use_patches(false);
  CHECK_FALSE(shf.patched());
  const auto eq = shf.energy(x.data(), fq.data(), false, true);
  // The same float energy per point, summed in other chunks (in double).
  CHECK(ep.total == Approx(eq.total).epsilon(1e-6));
  CHECK(ep.membrane == Approx(eq.membrane).epsilon(1e-6));
  float scale = 0, worst = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    scale = std::max(scale, fq[i].norm());
    worst = std::max(worst, (fp[i] - fq[i]).norm());
  }
  REQUIRE(scale > 0);
  CHECK(worst < 1e-5f * scale);

  // Dropping the last point leaves a run of 6: no patches, and the same first points.
  std::vector<BasisPoint> pts(s.points.begin(), s.points.end() - 1);
  std::vector<double> w(s.weights.begin(), s.weights.end() - 1);
  const KirchhoffLoveShellT<float> uneven(pts, w, rest, mat, 3);
  CHECK_FALSE(uneven.patched());
}
