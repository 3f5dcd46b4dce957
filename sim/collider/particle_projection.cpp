#include "sim/collider/particle_projection.h"

#include <algorithm>
#include <cmath>

#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

constexpr std::size_t kGrain = 4096;

// What project_point did to a point, as bit flags (0: nothing).
constexpr int kMovedOut = 1;      // moved out from inside the collider
constexpr int kSweptBack = 2;     // put back where its path entered the collider
constexpr int kByMovingBody = 4;  // the collider moves (its work is in wv)

// One point against one collider; returns kMovedOut or kSweptBack, with kByMovingBody
// when the collider moves. Adds the velocity change times a moving collider's velocity
// to wv.
int project_point(const Collider& c, double dx, double dt, double offset, bool sweep, Vec3& xr,
                  Vec3& v, double& wv) {
  const Vec3d x = xr.cast<double>();
  const Vec3d start = x - dt * v.cast<double>();
  const Vec3d x0 = c.animated() ? c.end_of(start) : start;  // the start, in the end pose's frame
  const double len = (x - x0).norm();
  Aabb box;
  box.lo = x.cwiseMin(x0).array() - dx;
  box.hi = x.cwiseMax(x0).array() + dx;
  if (!c.bounds().overlaps(box)) return 0;
  const double phi = c.phi(x);
  if (phi < offset) {
    // A hair outside (1e-4 dx), so that float rounding does not leave it inside.
    const Vec3d n = c.normal(x);
    const Vec3d y = x + (1e-4 * dx + offset - phi) * n;
    xr = y.cast<Real>();
    const Vec3 v0 = v;
    v = c.resolve(y, n, v);
    if (!c.animated()) return kMovedOut;
    wv += (v - v0).cast<double>().dot(c.velocity(y));
    return kMovedOut | kByMovingBody;
  }
  const int samples = sweep ? static_cast<int>(std::ceil(len / (0.5 * dx))) : 0;
  if (samples < 2) return 0;
  Vec3d last = x0;
  if (c.phi(x0) < offset) return 0;  // started inside (the grid pushes it out): not a sweep
  for (int k = 1; k < samples; ++k) {
    const Vec3d y = x0 + (x - x0) * (static_cast<double>(k) / samples);
    if (c.phi(y) < offset) {
      const Vec3d n = c.normal(last);
      xr = last.cast<Real>();
      const Vec3 v0 = v;
      v = c.resolve(last, n, v);
      if (!c.animated()) return kSweptBack;
      wv += (v - v0).cast<double>().dot(c.velocity(last));
      return kSweptBack | kByMovingBody;
    }
    last = y;
  }
  return 0;
}

}  // namespace

ProjectionStats project_out_of_colliders(const std::vector<Collider>& colliders, double dx,
                                         double dt, std::vector<Vec3>& x, std::vector<Vec3>& v,
                                         const std::vector<std::uint8_t>* held, bool serial,
                                         double offset, const ProjectionWork* work) {
  ProjectionStats total;
  if (colliders.empty() || x.empty()) return total;
  const std::vector<ProjectionStats> part = chunk_parts(
      x.size(), kGrain, serial, ProjectionStats{},
      [&](std::size_t b, std::size_t e, ProjectionStats& st) {
        for (std::size_t i = b; i < e; ++i) {
          if (held && (*held)[i]) continue;
          // The second pass only for points the first one moved.
          bool moved = false;
          double wv = 0;
          const Vec3d x0 = x[i].cast<double>();
          for (int pass = 0; pass < 2 && (pass == 0 || moved); ++pass)
            for (const Collider& c : colliders) {
              const int r = project_point(c, dx, dt, offset, pass == 0, x[i], v[i], wv);
              st.inside += (r & kMovedOut) != 0;
              st.swept += (r & kSweptBack) != 0;
              st.moving += (r & kByMovingBody) != 0;
              moved = moved || r != 0;
            }
          if (moved && work)
            st.work += work->mass(i) * (wv - work->gravity.dot(x[i].cast<double>() - x0));
        }
      });
  for (const ProjectionStats& p : part) {
    total.inside += p.inside;
    total.swept += p.swept;
    total.work += p.work;
    total.moving += p.moving;
  }
  return total;
}

}  // namespace shellmpm
