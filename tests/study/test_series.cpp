// Time-series measurements of the study against series with known answers.
#include <catch2/catch.hpp>
#include <cmath>

#include "study/series.h"

using namespace shellmpm;

TEST_CASE("fit_acceleration recovers a parabola's acceleration", "[study]") {
  std::vector<double> t, s;
  for (int i = 0; i <= 30; ++i) {
    const double ti = 0.1 + 0.01 * i;
    t.push_back(ti);
    s.push_back(0.3 - 0.7 * ti + 0.5 * 2.356 * ti * ti);
  }
  CHECK(fit_acceleration(t, s) == Approx(2.356).epsilon(1e-9));
  // A straight line has no acceleration.
  for (std::size_t i = 0; i < t.size(); ++i) s[i] = 1 + 2 * t[i];
  CHECK(std::abs(fit_acceleration(t, s)) < 1e-9);
  CHECK_THROWS(fit_acceleration({0.0, 1.0}, {0.0, 1.0}));
}

TEST_CASE("oscillation_period finds the period of a sampled sine, any phase and offset",
          "[study]") {
  for (double phase : {0.0, 0.7, 2.1}) {
    std::vector<double> t, s;
    const double T = 0.124;
    for (int i = 0; i <= 200; ++i) {  // 0.5 s at 400 samples per second: 4 periods
      t.push_back(i / 400.0);
      s.push_back(-0.006 + 0.006 * std::cos(2 * M_PI * t.back() / T + phase));
    }
    const auto p = oscillation_period(t, s);
    REQUIRE(p);
    INFO("phase " << phase << ": period " << *p);
    CHECK(*p == Approx(T).epsilon(2e-3));
  }
  // Less than a period: no answer.
  std::vector<double> t = {0, 0.1, 0.2}, s = {0, 1, 0};
  CHECK_FALSE(oscillation_period(t, s));
}

TEST_CASE("first_crossing interpolates between samples and respects the direction", "[study]") {
  const std::vector<double> t = {0, 1, 2, 3}, v = {-1, -0.5, 0.5, 1};
  const auto up = first_crossing(t, v, 0.0, true);
  REQUIRE(up);
  CHECK(*up == Approx(1.5));
  CHECK_FALSE(first_crossing(t, v, 0.0, false));
  CHECK_FALSE(first_crossing(t, v, 2.0, true));
}
