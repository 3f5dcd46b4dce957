// Richardson extrapolation and fitted orders on sequences with known limits and orders.
#include <catch2/catch.hpp>
#include <cmath>

#include "study/richardson.h"

using namespace shellmpm;

TEST_CASE("richardson recovers order and limit of q = q0 + C h^p", "[study]") {
  for (double p : {1.0, 2.0, 1.5}) {
    for (auto hs :
         {std::vector<double>{0.04, 0.02, 0.01}, std::vector<double>{0.03, 0.02, 0.005}}) {
      std::vector<double> q;
      for (double h : hs) q.push_back(2.5 - 3.0 * std::pow(h, p));
      const auto e = richardson(hs, q);
      REQUIRE(e);
      INFO("p " << p << " h " << hs[0] << "," << hs[1] << "," << hs[2]);
      CHECK(e->order == Approx(p).epsilon(1e-6));
      CHECK(e->limit == Approx(2.5).epsilon(1e-9));
      CHECK(e->error == Approx(3.0 * std::pow(hs.back(), p)).epsilon(1e-6));
    }
  }
}

TEST_CASE("richardson refuses oscillating or flat sequences, and takes any input order",
          "[study]") {
  CHECK_FALSE(richardson({0.04, 0.02, 0.01}, {1.0, 1.1, 1.05}));  // changes direction
  CHECK_FALSE(richardson({0.04, 0.02, 0.01}, {1.0, 1.0, 1.1}));   // a zero difference
  CHECK_FALSE(richardson({0.04, 0.02}, {1.0, 1.1}));              // two points
  const auto e = richardson({0.01, 0.04, 0.02}, {1 - 1e-4, 1 - 16e-4, 1 - 4e-4});
  REQUIRE(e);
  CHECK(e->order == Approx(2).epsilon(1e-6));
  CHECK(e->limit == Approx(1).epsilon(1e-9));
}

TEST_CASE("fitted_order is the log-log slope of the error", "[study]") {
  const auto p = fitted_order({0.1, 0.05, 0.025}, {-0.2, -0.05, -0.0125});
  REQUIRE(p);
  CHECK(*p == Approx(2).epsilon(1e-9));
  CHECK_FALSE(fitted_order({0.1}, {0.2}));
  CHECK_FALSE(fitted_order({0.1, 0.05}, {0.0, 0.0}));
}
