// Kirchhoff-Love shell: the denting return mapping over every layer of every
// quadrature point (denting.h, supplement sec. 7, eqs. 27-37) and the strain statistics.
#include <algorithm>
#include <cmath>

#include "sim/core/parallel.h"
#include "sim/shell/denting.h"
#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/kl_kinematics.h"
#include "sim/shell/laminate_energy.h"

namespace shellmpm {

using kl::gather_kinematics;
using kl::kPointGrain;
using kl::layer_log_s;
using kl::mul2;
using kl::PointKinematics;

template <class T>
T KirchhoffLoveShellT<T>::project_plasticity(const Vec3T* x, bool serial) {
  if (!has_plasticity()) return T(0);
  const double work = ordered_reduce_chunks(
      area_.size(), kPointGrain, serial, 0.0, [&](std::size_t b, std::size_t e) {
        double w = 0.0;
        for (std::size_t q = b; q < e; ++q) {
          PointKinematics<T> k;
          gather_kinematics(begin_, ctrl_, coef_, q, x, k);
          for (int l = 0; l < num_layers_; ++l) {
            const std::size_t ql = q * num_layers_ + l;
            const T xi3 = layer_xi3_[l];
            const Vec3T g1 = k.a1 + xi3 * k.v1, g2 = k.a2 + xi3 * k.v2;
            Mat2T M;
            M << g1.dot(g1), g1.dot(g2), g1.dot(g2), g2.dot(g2);
            T* Fi = &fp_inv_[4 * ql];
            T Bp[4];
            mul2(&B_[4 * ql], Fi, Bp);
            Mat2T Bm;
            Bm << Bp[0], Bp[1], Bp[2], Bp[3];
            const Mat2T Ce = Bm.transpose() * M * Bm;
            Mat2T F;
            F << Fi[0], Fi[1], Fi[2], Fi[3];
            const T wd = denting_project_layer(mu_, lambda_, yield_, Ce, F);
            // Below yield F is untouched, so this copy is bitwise neutral.
            Fi[0] = F(0, 0);
            Fi[1] = F(0, 1);
            Fi[2] = F(1, 0);
            Fi[3] = F(1, 1);
            w += double(area_[q] * layer_w_[l]) * double(wd);
          }
        }
        return w;
      });
  return T(work);
}

template <class T>
T KirchhoffLoveShellT<T>::max_strain(const Vec3T* x, bool serial) const {
  const std::size_t nq = area_.size();
  if (nq == 0) return T(0);
  const bool plastic = !fp_inv_.empty();
  const std::vector<T> part =
      chunk_parts(nq, kPointGrain, serial, T(0), [&](std::size_t b, std::size_t e, T& out) {
        T m = 0;
        for (std::size_t q = b; q < e; ++q) {
          PointKinematics<T> k;
          gather_kinematics(begin_, ctrl_, coef_, q, x, k);
          for (int l = 0; l < num_layers_; ++l) {
            const std::size_t ql = q * num_layers_ + l;
            const T xi3 = layer_xi3_[l];
            const Vec3T g1 = k.a1 + xi3 * k.v1, g2 = k.a2 + xi3 * k.v2;
            const T* B = &B_[4 * ql];
            T Bp[4];
            if (plastic) {
              mul2(B, &fp_inv_[4 * ql], Bp);
              B = Bp;
            }
            T l1, l2;
            layer_log_s(B, g1.dot(g1), g1.dot(g2), g2.dot(g2), l1, l2);
            m = std::max(m, std::max(std::abs(l1), std::abs(l2)));
          }
        }
        out = m;
      });
  return *std::max_element(part.begin(), part.end());
}

template float KirchhoffLoveShellT<float>::project_plasticity(const Vec3T*, bool);
template double KirchhoffLoveShellT<double>::project_plasticity(const Vec3T*, bool);
template float KirchhoffLoveShellT<float>::max_strain(const Vec3T*, bool) const;
template double KirchhoffLoveShellT<double>::max_strain(const Vec3T*, bool) const;

}  // namespace shellmpm
