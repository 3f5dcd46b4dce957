// Coulomb friction at a collider node as a term of the implicit objective: the lagged
// dissipation potential of Li et al. 2020 (IPC, section 5), written for one grid node's
// velocity u. With the normal impulse and the surface's normal and velocity fixed from a
// previous solve (lagged), friction is the gradient of
//   D(u) = bound * f0(|v_t|),   v_t = (I - n n^T)(u - v_c),   bound = mu * normal impulse,
// where f0 is |v_t| smoothed below eps:
//   f0(s) = s^2 / eps - s^3 / (3 eps^2) + eps / 3   (s < eps),   s   (s >= eps),
// so f0' = f1 rises from 0 to 1 over [0, eps] and is 1 beyond: a node sliding faster than
// eps feels the full Coulomb impulse bound against its tangential velocity, and a slower
// one a stiff spring (curvature 2 bound / eps) towards the surface's velocity. D is convex
// in u and C^2 away from s = eps (C^1 there), so Newton sees friction's stiffness and the
// solve's elastic response includes it, where friction applied after the solve changes
// velocities that the solve's stiffness never saw (implicit.md).
#pragma once
#include "sim/core/types.h"

namespace shellmpm {

struct LaggedFriction {
  Vec3d n{0, 0, 0};   ///< unit normal of the constraint
  Vec3d vc{0, 0, 0};  ///< the surface's velocity [m/s]
  double bound = 0;   ///< friction coefficient times the normal impulse [N s]
  double eps = 1e-3;  ///< tangential speed below which it sticks elastically [m/s]

  /// v_t at u.
  Vec3d tangential(const Vec3d& u) const {
    const Vec3d d = u - vc;
    return d - d.dot(n) * n;
  }
  /// D(u) [J].
  double energy(const Vec3d& u) const {
    const double s = tangential(u).norm();
    if (s >= eps) return bound * s;
    return bound * (s * s / eps - s * s * s / (3 * eps * eps) + eps / 3);
  }
  /// dD/du [N s]: the friction impulse's opposite.
  Vec3d gradient(const Vec3d& u) const {
    const Vec3d t = tangential(u);
    const double s = t.norm();
    // f1(s) / s, finite at s = 0.
    const double k = s >= eps ? 1 / s : 2 / eps - s / (eps * eps);
    return bound * k * t;
  }
  /// d^2 D / du^2 (symmetric positive semi-definite) [kg].
  Mat3d hessian(const Vec3d& u) const {
    const Vec3d t = tangential(u);
    const double s = t.norm();
    const Mat3d P = Mat3d::Identity() - n * n.transpose();
    if (s >= eps) return bound / s * (P - t * t.transpose() / (s * s));
    // (f1 / s) P + (f1' - f1 / s) t t^T / s^2, with f1' - f1 / s = -s / eps^2.
    const Mat3d tt = s > 0 ? Mat3d(t * t.transpose() / (s * eps * eps)) : Mat3d::Zero();
    return bound * ((2 / eps - s / (eps * eps)) * P - tt);
  }
};

}  // namespace shellmpm
