#include "sim/solver/source_sampler.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace shellmpm {
namespace {

// Deterministic jitter in [-0.5, 0.5) from lattice index and seed (splitmix64).
double jitter(std::int64_t i, std::int64_t j, std::int64_t k, unsigned seed, int axis) {
  std::uint64_t z = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ULL ^
                    static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL ^
                    static_cast<std::uint64_t>(k) * 0x165667B19E3779F9ULL ^
                    (static_cast<std::uint64_t>(seed) << 32) ^ static_cast<std::uint64_t>(axis);
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * (1.0 / 9007199254740992.0) - 0.5;
}

constexpr double kJitter = 0.6;  // fraction of the spacing a point may move

}  // namespace

SourceSampler::SourceSampler(const SourceDesc& src, double dx, double fps) : src_(src) {
  h_ = dx / std::cbrt(src.particles_per_cell);
  bounds_ = shape_bounds(src.shape);
  if (src.emit) {
    t0_ = (src.emit_start - 1) / fps;
    t1_ = src.emit_end / fps;
  }
}

Vec3d SourceSampler::point(const Vec3i& ijk, double t) const {
  Vec3d p;
  for (int a = 0; a < 3; ++a)
    p[a] = h_ * (ijk[a] + 0.5 + kJitter * jitter(ijk[0], ijk[1], ijk[2], src_.seed, a));
  if (src_.emit) p += src_.velocity * (t - t0_);
  return p;
}

void SourceSampler::fill(const std::function<void(const Vec3d&)>& out) const {
  Vec3i lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<int>(std::floor(bounds_.lo[a] / h_)) - 1;
    hi[a] = static_cast<int>(std::ceil(bounds_.hi[a] / h_)) + 1;
  }
  for (int i = lo[0]; i <= hi[0]; ++i)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int k = lo[2]; k <= hi[2]; ++k) {
        const Vec3d p = point(Vec3i(i, j, k), 0.0);
        if (shape_phi(src_.shape, p) < 0) out(p);
      }
}

std::size_t SourceSampler::count_fill() const {
  std::size_t n = 0;
  fill([&](const Vec3d&) { ++n; });
  return n;
}

void SourceSampler::emit(double t, double dt, const std::function<void(const Vec3d&)>& out) const {
  if (!src_.emit) return;
  const double a = std::max(t, t0_), b = std::min(t + dt, t1_);
  if (!(b > a)) return;
  // Lattice indices whose points are inside the shape's bounds at time a.
  const Vec3d shift = src_.velocity * (a - t0_);
  Vec3i lo, hi;
  for (int ax = 0; ax < 3; ++ax) {
    lo[ax] = static_cast<int>(std::floor((bounds_.lo[ax] - shift[ax]) / h_)) - 1;
    hi[ax] = static_cast<int>(std::ceil((bounds_.hi[ax] - shift[ax]) / h_)) + 1;
  }
  for (int i = lo[0]; i <= hi[0]; ++i)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int k = lo[2]; k <= hi[2]; ++k) {
        const Vec3i ijk(i, j, k);
        const Vec3d pa = point(ijk, a);
        if (shape_phi(src_.shape, pa) >= 0) continue;
        const Vec3d pb = point(ijk, b);
        if (shape_phi(src_.shape, pb) < 0) continue;
        // Released between a and b; place it where it is at the end of the step.
        out(pb + src_.velocity * ((t + dt) - b));
      }
}

}  // namespace shellmpm
