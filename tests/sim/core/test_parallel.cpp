// sim/core/parallel.h and sim/core/counting_sort.h: the chunked reductions give the same
// result serially and on threads, and the counting sort is stable.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "sim/core/counting_sort.h"
#include "sim/core/parallel.h"

using namespace shellmpm;

TEST_CASE("chunk_parts: one part per chunk, in chunk order, on any thread count", "[parallel]") {
  const std::size_t n = 10007, grain = 64;
  for (bool serial : {true, false}) {
    const std::vector<std::array<std::size_t, 2>> parts =
        chunk_parts(n, grain, serial, std::array<std::size_t, 2>{0, 0},
                    [](std::size_t b, std::size_t e, std::array<std::size_t, 2>& p) {
                      p = {b, e};
                    });
    REQUIRE(parts.size() == (n + grain - 1) / grain);
    for (std::size_t c = 0; c < parts.size(); ++c) {
      CHECK(parts[c][0] == c * grain);
      CHECK(parts[c][1] == std::min(n, (c + 1) * grain));
    }
  }
  CHECK(chunk_parts(0, grain, false, 1.0, [](std::size_t, std::size_t, double&) {}).empty());
}

TEST_CASE("ordered_reduce: serial and parallel sums are bitwise equal", "[parallel]") {
  const std::size_t n = 200003;
  const auto term = [](std::size_t i) { return 1.0 / (1.0 + static_cast<double>(i) * 0.37); };
  const double serial = ordered_reduce(n, 512, true, 0.0, term);
  const double threaded = ordered_reduce(n, 512, false, 0.0, term);
  CHECK(serial == threaded);
  // The chunked order: each chunk from zero in index order, then the chunk sums.
  double expect = 0.0;
  for (std::size_t b = 0; b < n; b += 512) {
    double chunk = 0.0;
    for (std::size_t i = b; i < std::min(n, b + 512); ++i) chunk += term(i);
    expect += chunk;
  }
  CHECK(serial == expect);
}

TEST_CASE("counting_sort: bucket offsets and a stable order", "[parallel]") {
  const std::vector<int> key = {3, 0, 2, 3, 0, 0, 2, 5};
  std::vector<std::uint32_t> start, order;
  counting_sort(
      key.size(), 6, [&](std::size_t i) { return key[i]; }, start, order);
  CHECK(start == std::vector<std::uint32_t>{0, 3, 3, 5, 7, 7, 8});
  CHECK(order == std::vector<std::uint32_t>{1, 4, 5, 2, 6, 0, 3, 7});
  counting_sort(
      0, 2, [&](std::size_t i) { return key[i]; }, start, order);
  CHECK(start == std::vector<std::uint32_t>{0, 0, 0});
  CHECK(order.empty());
}
