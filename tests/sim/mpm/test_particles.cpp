#include <catch2/catch.hpp>

#include <algorithm>
#include <numeric>
#include <random>

#include "sim/mpm/particles.h"

using namespace shellmpm;

namespace {

ParticleSet numbered(std::size_t n, bool plastic) {
  ParticleSet p;
  p.keep_plastic = plastic;
  for (std::size_t i = 0; i < n; ++i) {
    const Real f = static_cast<Real>(i);
    p.push_back(Vec3(f, f + 1, f + 2), Vec3(-f, f, 2 * f), f + Real(0.5),
                static_cast<std::uint16_t>(i % 7), 3 * f);
    p.C.back() = Mat3::Constant(f);
    p.F.back() = Mat3::Identity() * (f + 1);
  }
  return p;
}

// Every attribute of new index i is old index order[i]'s.
void check_permuted(const ParticleSet& p, const ParticleSet& old,
                    const std::vector<std::uint32_t>& order) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::uint32_t o = order[i];
    REQUIRE(p.x[i] == old.x[o]);
    REQUIRE(p.v[i] == old.v[o]);
    REQUIRE(p.C[i] == old.C[o]);
    REQUIRE(p.F[i] == old.F[o]);
    REQUIRE(p.kind[i] == old.kind[o]);
    REQUIRE(p.volume_of(i) == old.volume_of(o));
    REQUIRE(p.material_of(i) == old.material_of(o));
    REQUIRE(p.id[i] == old.id[o]);
    if (old.has_plastic()) REQUIRE(p.plastic[i] == old.plastic[o]);
  }
}

}  // namespace

TEST_CASE("the in-place reorder moves every attribute to its new place", "[particles]") {
  std::mt19937 rng(7);
  for (const bool plastic : {false, true}) {
    // A random permutation (long cycles), and one close to the identity (a few particles
    // moved far: the others shift by one), as after a frame.
    const std::size_t n = 1000;
    std::vector<std::uint32_t> random(n), near(n);
    std::iota(random.begin(), random.end(), 0u);
    std::shuffle(random.begin(), random.end(), rng);
    std::iota(near.begin(), near.end(), 0u);
    std::rotate(near.begin() + 100, near.begin() + 101, near.begin() + 900);
    std::swap(near[3], near[4]);
    for (const auto* order : {&random, &near}) {
      const ParticleSet old = numbered(n, plastic);
      ParticleSet p = old;
      p.permute(*order);
      check_permuted(p, old, *order);
      // The inverse permutation restores the original.
      std::vector<std::uint32_t> inverse(n);
      for (std::uint32_t i = 0; i < n; ++i) inverse[(*order)[i]] = i;
      p.permute(inverse);
      std::vector<std::uint32_t> identity(n);
      std::iota(identity.begin(), identity.end(), 0u);
      check_permuted(p, old, identity);
    }
  }
}
