// KirchhoffLoveShellT<double>::stiffness_blocks: the Kirchhoff-Love stiffness from each
// quadrature point's 15 x 15 Hessian in (a_1, a_2, a_11, a_12, a_22) (see the header).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <type_traits>
#include <vector>

#include "sim/core/parallel.h"
#include "sim/core/psd_part.h"
#include "sim/shell/kl_kinematics.h"
#include "sim/shell/kl_stiffness.h"

namespace shellmpm {

namespace {

using Mat15 = Eigen::Matrix<double, 15, 15>;

/// Input i of the point's kinematics: a_1, a_2, a_11, a_12, a_22, three components each
/// (the layout of eval_kinematics' adjoints).
double& input(kl::PointKinematics<double>& k, int i) {
  Eigen::Vector3d* v[5] = {&k.a1, &k.a2, &k.a11, &k.a12, &k.a22};
  return (*v[i / 3])[i % 3];
}

/// H's positive semi-definite part. A pivoted LDL^T first: most points (stretched or at
/// rest) are already semi-definite, and that test costs a fraction of the eigensolver.
void make_psd(Mat15& H) {
  const double scale = H.diagonal().cwiseAbs().maxCoeff();
  if (!(scale > 0)) return;
  const Eigen::LDLT<Mat15> ldlt(H);
  if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() >= -1e-12 * scale).all()) return;
  psd_part(H);
}

}  // namespace

template <class T>
void KirchhoffLoveShellT<T>::stiffness_blocks(
    const Vec3T* x, double h_rel,
    const std::function<void(int, int, const Eigen::Matrix<T, 3, 3>&)>& add, bool serial,
    bool psd) const {
  static_assert(std::is_same_v<T, double>, "the stiffness is assembled in double");
  const std::size_t nq = area_.size();
  // Hessians in chunks of points (their memory bounded), computed in parallel and added
  // in point order.
  constexpr std::size_t kChunk = 2048;
  std::vector<Mat15> hess(std::min(nq, kChunk));
  std::vector<std::array<double, 5>> c;         // per entry of a point: d(input)/dx
  std::vector<Eigen::Matrix<double, 15, 3>> M;  // per entry: H J_entry
  for (std::size_t q0 = 0; q0 < nq; q0 += kChunk) {
    const std::size_t q1 = std::min(nq, q0 + kChunk);
    parallel_for(
        q1 - q0, 16,
        [&](std::size_t b, std::size_t e) {
          for (std::size_t q = q0 + b; q < q0 + e; ++q) {
            kl::PointKinematics<double> k0;
            kl::gather_kinematics(begin_, ctrl_, coef_, q, x, k0);
            double h = h_rel * std::max(k0.a1.norm(), k0.a2.norm());
            if (!(h > 0)) h = h_rel;  // a collapsed point: its energy is not finite anyway
            Mat15& H = hess[q - q0];
            double g0[15], gp[15], et = 0;
            eval_kinematics(q, k0, g0, et, nullptr);
            for (int i = 0; i < 15; ++i) {
              kl::PointKinematics<double> k = k0;
              input(k, i) += h;
              kl::compute_kinematics(k);
              eval_kinematics(q, k, gp, et, nullptr);
              for (int r = 0; r < 15; ++r) H(r, i) = (gp[r] - g0[r]) / h;
            }
            H = (0.5 * (H + H.transpose())).eval();
            if (psd) make_psd(H);
          }
        },
        serial);
    for (std::size_t q = q0; q < q1; ++q) {
      const Mat15& H = hess[q - q0];
      const std::size_t b = begin_[q], n = begin_[q + 1] - b;
      // d(input k)/dx of each entry: its weight, the first entry minus the sum of the
      // others (gather_kinematics sums differences to it).
      c.resize(n);
      M.resize(n);
      std::array<double, 5> first{0, 0, 0, 0, 0};
      for (std::size_t a = 1; a < n; ++a)
        for (int kk = 0; kk < 5; ++kk) {
          c[a][kk] = coef_[5 * (b + a) + kk];
          first[kk] -= c[a][kk];
        }
      c[0] = first;
      // M_f = H J_f (15 x 3), then K_ef = J_e^T M_f.
      for (std::size_t f = 0; f < n; ++f) {
        M[f].setZero();
        for (int kk = 0; kk < 5; ++kk)
          if (c[f][kk] != 0) M[f] += c[f][kk] * H.block<15, 3>(0, 3 * kk);
      }
      for (std::size_t e = 0; e < n; ++e)
        for (std::size_t f = 0; f < n; ++f) {
          Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
          for (int kk = 0; kk < 5; ++kk)
            if (c[e][kk] != 0) K += c[e][kk] * M[f].block<3, 3>(3 * kk, 0);
          add(ctrl_[b + e], ctrl_[b + f], K);
        }
    }
  }
}

SparseMatrixD kl_stiffness_matrix(const KirchhoffLoveShellT<double>& kl,
                                  const std::vector<Vec3d>& x, const std::vector<int>& dof_of,
                                  int dofs, bool serial, bool psd) {
  // 3x3 blocks per coupled pair, summed per row point (a short list each).
  std::vector<std::vector<std::pair<int, Eigen::Matrix3d>>> rows(x.size());
  kl.stiffness_blocks(
      x.data(), 1e-7,
      [&](int i, int j, const Eigen::Matrix3d& B) {
        auto& row = rows[static_cast<std::size_t>(i)];
        for (auto& [col, acc] : row)
          if (col == j) {
            acc += B;
            return;
          }
        row.emplace_back(j, B);
      },
      serial, psd);
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (const auto& [j, B] : rows[i])
      for (int a = 0; a < 3; ++a) {
        const int r = dof_of[3 * i + static_cast<std::size_t>(a)];
        if (r < 0) continue;
        for (int b = 0; b < 3; ++b) {
          const int c = dof_of[3 * static_cast<std::size_t>(j) + static_cast<std::size_t>(b)];
          if (c >= 0) t.emplace_back(r, c, B(a, b));
        }
      }
  SparseMatrixD K(dofs, dofs);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

template void KirchhoffLoveShellT<double>::stiffness_blocks(
    const Vec3T*, double, const std::function<void(int, int, const Eigen::Matrix<double, 3, 3>&)>&,
    bool, bool) const;

}  // namespace shellmpm
