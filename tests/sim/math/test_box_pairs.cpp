// BoxPairs against its definition, by brute force: every pair of boxes within r on each
// axis exactly once, the keep filter applied, sorted, on any thread count; also far from
// the origin and at distances just inside and just outside r.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "sim/core/parallel.h"
#include "sim/math/box_pairs.h"

using namespace shellmpm;

namespace {

using Box = BoxPairs::Box;

bool finite(const Box& a) {
  for (double v : a)
    if (!std::isfinite(v)) return false;
  return true;
}

/// The definition: both boxes finite, and on each axis neither lies r or more past the other.
bool within(const Box& a, const Box& b, double r) {
  if (!finite(a) || !finite(b)) return false;
  for (int ax = 0; ax < 3; ++ax)
    if (b[ax] - a[ax + 3] >= r || a[ax] - b[ax + 3] >= r) return false;
  return true;
}

/// Segments (boxes of two points) of length up to `len` scattered over a slab, offset by o.
std::vector<Box> segments(std::mt19937& rng, int n, double len, const Vec3d& o) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Box> boxes;
  for (int i = 0; i < n; ++i) {
    const Vec3d p = o + Vec3d(u(rng), 0.1 * u(rng), u(rng));
    const Vec3d q = p + len * Vec3d(u(rng), u(rng), u(rng));
    boxes.push_back({std::min(p[0], q[0]), std::min(p[1], q[1]), std::min(p[2], q[2]),
                     std::max(p[0], q[0]), std::max(p[1], q[1]), std::max(p[2], q[2])});
  }
  return boxes;
}

std::vector<Eigen::Vector2i> brute(const std::vector<Box>& boxes, double r) {
  std::vector<Eigen::Vector2i> out;
  for (std::size_t a = 0; a < boxes.size(); ++a)
    for (std::size_t b = a + 1; b < boxes.size(); ++b)
      if (within(boxes[a], boxes[b], r)) out.emplace_back(int(a), int(b));
  return out;
}

}  // namespace

TEST_CASE("box pairs: every pair within r once, sorted, on any thread count", "[grid]") {
  std::mt19937 rng(11);
  const double r = 0.01;
  for (const Vec3d& o : {Vec3d(0, 0, 0), Vec3d(3e3, -2e3, 5e2)}) {
    INFO("offset " << o.transpose());
    std::vector<Box> boxes = segments(rng, 6000, 0.03, o);
    boxes[17][4] = std::nan("");  // not finite: in no pair
    boxes[18][0] = -std::numeric_limits<double>::infinity();
    const std::vector<Eigen::Vector2i> want = brute(boxes, r);
    REQUIRE(want.size() > 1000);
    for (const double cell : {0.02, 0.05, 0.13}) {
      BoxPairs bp;
      const auto all = [](int, int) { return true; };
      std::vector<Eigen::Vector2i> serial = bp.find(boxes, r, cell, true, all), parallel;
      {
        ThreadLimit lim(2);
        parallel = bp.find(boxes, r, cell, false, all);
      }
      CHECK(serial == want);
      CHECK(parallel == want);
      // The filter: only the pairs it keeps, each asked about once.
      std::atomic<int> asked{0};
      const auto odd = bp.find(boxes, r, cell, false, [&](int a, int b) {
        ++asked;
        return (a + b) % 2 == 1;
      });
      std::vector<Eigen::Vector2i> want_odd;
      for (const auto& p : want)
        if ((p[0] + p[1]) % 2 == 1) want_odd.push_back(p);
      CHECK(odd == want_odd);
      CHECK(asked == static_cast<int>(want.size()));
    }
  }
}

TEST_CASE("box pairs: a gap just under r pairs, r and more does not, at any position", "[grid]") {
  const double r = 0.004, cell = 0.01;
  // Two boxes on the x axis, the second's low corner r -+ a few ulps past the first's high
  // corner, with the middle of the gap on a cell boundary (where boxes grown by less than
  // r / 2 share no cell) and elsewhere.
  for (const double mid : {cell, 7 * cell, 123456 * cell, 0.0123, 1234.5678}) {
    for (const int ulps : {-4, -1, 0, 1, 3}) {
      const double hi = mid - 0.5 * r, x0 = hi - 0.01;
      double lo = hi + r;
      for (int k = 0; k < std::abs(ulps); ++k)
        lo = std::nextafter(lo, ulps < 0 ? -INFINITY : INFINITY);
      const std::vector<Box> boxes = {Box{x0, 0, 0, hi, 0.01, 0.01},
                                      Box{lo, 0.002, 0.003, lo + 0.02, 0.005, 0.02}};
      BoxPairs bp;
      const auto got = bp.find(boxes, r, cell, true, [](int, int) { return true; });
      INFO("mid " << mid << " ulps " << ulps);
      CHECK(got.size() == (within(boxes[0], boxes[1], r) ? 1u : 0u));
      CHECK(within(boxes[0], boxes[1], r) == (lo - hi < r));
    }
  }
}
