#include "sim/implicit/collider_penalty.h"

#include <algorithm>

namespace shellmpm {

double collider_penalty(const ColliderPenaltyInput& in, const std::vector<Vec3d>& X,
                        std::vector<Vec3d>* grad, std::vector<Mat3d>* K, double* work) {
  if (K) K->assign(X.size(), Mat3d::Zero());
  if (!in.colliders || in.colliders->empty()) return 0;
  double e = 0;
  for (std::size_t j = 0; j < X.size(); ++j) {
    if (in.held && (*in.held)[j] == 7u) continue;
    Aabb at;
    at.lo = at.hi = X[j];
    double kappa = -1;
    for (const Collider& col : *in.colliders) {
      if (!col.bounds().overlaps(at)) continue;
      const double phi = col.phi(X[j]);
      if (!(phi < 0)) continue;
      if (kappa < 0)
        kappa = kColliderPenalty *
                std::max(static_cast<double>((*in.mass)[j]) / (in.dt * in.dt), in.membrane);
      e += 0.5 * kappa * phi * phi;
      const Vec3d n = col.normal(X[j]);
      if (grad) (*grad)[j] += kappa * phi * n;
      if (K) (*K)[j] += kappa * n * n.transpose();
      // The impulse over the step, -dt kappa phi n, times the collider's velocity.
      if (work && col.animated()) *work -= in.dt * kappa * phi * n.dot(col.velocity(X[j]));
    }
  }
  return e;
}

}  // namespace shellmpm
