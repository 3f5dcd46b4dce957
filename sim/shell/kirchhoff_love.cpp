#include "sim/shell/kirchhoff_love.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "sim/core/check.h"
#include "sim/core/counting_sort.h"
#include "sim/core/parallel.h"
#include "sim/shell/denting.h"
#include "sim/shell/kl_kinematics.h"
#include "sim/shell/laminate_energy.h"
#include "sim/shell/shell_quadrature.h"

namespace shellmpm {
namespace {
constexpr std::size_t kGatherGrain = 1024;  // control points per chunk
}  // namespace

using kl::gather_kinematics;
using kl::kPointGrain;
using kl::layer_log_s;
using kl::layer_psi;
using kl::mul2;
using kl::PointKinematics;

namespace {
/// B_ba = gbar^b . e_a of the rest layer at xi3 (rest kinematics k) in the orthonormal rest
/// frame e_1 = gbar_1/|gbar_1|, e_2 = a3 x e_1 (row-major into out[4]).
template <class T>
void rest_layer_B(const PointKinematics<double>& k, double xi3, std::size_t q, T* out) {
  using V3d = Eigen::Matrix<double, 3, 1>;
  const V3d g1 = k.a1 + xi3 * k.v1, g2 = k.a2 + xi3 * k.v2;
  const V3d e1 = g1.normalized();
  const V3d e2 = k.a3.cross(e1);
  Eigen::Matrix2d G;
  G << g1.dot(g1), g1.dot(g2), g1.dot(g2), g2.dot(g2);
  SHELLMPM_CHECK(G.determinant() > 0, "degenerate rest layer at quadrature point " << q);
  const Eigen::Matrix2d Gi = G.inverse();
  const V3d d1 = Gi(0, 0) * g1 + Gi(0, 1) * g2, d2 = Gi(1, 0) * g1 + Gi(1, 1) * g2;
  out[0] = T(d1.dot(e1));
  out[1] = T(d1.dot(e2));
  out[2] = T(d2.dot(e1));
  out[3] = T(d2.dot(e2));
}
}  // namespace

template <class T>
KirchhoffLoveShellT<T>::KirchhoffLoveShellT(std::vector<BasisPoint> points,
                                            std::vector<double> inplane_weights,
                                            const std::vector<Eigen::Matrix<double, 3, 1>>& rest,
                                            const ShellMaterialDesc& mat, int thickness_points) {
  SHELLMPM_CHECK(points.size() == inplane_weights.size(),
                 "points " << points.size() << " weights " << inplane_weights.size());
  SHELLMPM_CHECK(mat.youngs_modulus > 0 && mat.poisson_ratio > -1 && mat.poisson_ratio < 0.5 &&
                     mat.thickness > 0 && mat.yield_stress >= 0 && mat.stretch_limit > 1 &&
                     mat.stretch_limit <= kMaxStretchLimit,
                 "material E " << mat.youngs_modulus << " nu " << mat.poisson_ratio << " t "
                               << mat.thickness << " yield " << mat.yield_stress
                               << " stretch limit " << mat.stretch_limit);
  const double E = mat.youngs_modulus, nu = mat.poisson_ratio, t = mat.thickness;
  num_ctrl_ = rest.size();
  mu_ = T(E / (2.0 * (1.0 + nu)));
  lambda_ = T(E * nu / (1.0 - nu * nu));  // = 2 mu lambda / (lambda + 2 mu): plane stress
  yield_ = T(mat.yield_stress);
  stiffening_.limit = T(mat.stretch_limit);
  stiffening_.log_limit = T(std::log(mat.stretch_limit));
  stiffening_.k = T(kStretchStiffening * (E / (2.0 * (1.0 + nu)) + E * nu / (1.0 - nu * nu)));
  thickness_ = T(t);
  rho_ = mat.density;
  thickness_d_ = t;

  const LineQuadrature gl = gauss_legendre(thickness_points);
  num_layers_ = thickness_points;
  for (int k = 0; k < num_layers_; ++k) {
    layer_xi3_.push_back(T(0.5 * t * gl.points[k]));
    layer_w_.push_back(T(0.5 * t * gl.weights[k]));
  }
  size_entries(points);
  rest_area_ = 0.0;
  for (std::size_t q = 0; q < points.size(); ++q) {
    const PointKinematics<double> k = load_point(q, points[q], rest);
    const double jac = k.a1.cross(k.a2).norm();
    SHELLMPM_CHECK(jac > 0 && std::isfinite(jac),
                   "degenerate rest tangents at quadrature point " << q);
    area_[q] = T(inplane_weights[q] * jac);
    rest_area_ += inplane_weights[q] * jac;
    for (int l = 0; l < num_layers_; ++l)
      rest_layer_B(k, 0.5 * t * gl.points[l], q, &B_[4 * (q * num_layers_ + l)]);
    rest_layer_B(k, 0.0, q, &B0_[4 * q]);
  }
  if (has_plasticity()) {
    fp_inv_.resize(4 * points.size() * num_layers_);
    reset_plastic_state();
  }
  build_gather_map();
  if constexpr (std::is_same_v<T, float>) {
    patches_ = kl::build_patches(begin_, ctrl_, coef_, num_ctrl_);
    if (!patches_.empty()) kl::lay_out_lanes(patches_, B_, area_, num_layers_);
  }
}

template <class T>
void KirchhoffLoveShellT<T>::size_entries(const std::vector<BasisPoint>& points) {
  const std::size_t nq = points.size();
  begin_.assign(nq + 1, 0);
  for (std::size_t q = 0; q < nq; ++q) {
    const BasisPoint& p = points[q];
    const std::size_t m = p.ctrl.size();
    SHELLMPM_CHECK(p.N.size() == m && p.N1.size() == m && p.N2.size() == m && p.N11.size() == m &&
                       p.N12.size() == m && p.N22.size() == m,
                   "quadrature point " << q << " has inconsistent basis arrays");
    begin_[q + 1] = begin_[q] + m;
  }
  const std::size_t ne = begin_[nq];
  ctrl_.resize(ne);
  coef_.resize(5 * ne);
  value_.resize(ne);
  area_.resize(nq);
  B_.resize(4 * nq * num_layers_);
  B0_.resize(4 * nq);
}

template <class T>
PointKinematics<double> KirchhoffLoveShellT<T>::load_point(
    std::size_t q, const BasisPoint& p, const std::vector<Eigen::Matrix<double, 3, 1>>& rest) {
  using V3d = Eigen::Matrix<double, 3, 1>;
  V3d a1 = V3d::Zero(), a2 = V3d::Zero(), a11 = V3d::Zero(), a12 = V3d::Zero(), a22 = V3d::Zero();
  for (std::size_t i = 0; i < p.ctrl.size(); ++i) {
    const std::size_t e = begin_[q] + i;
    const int j = p.ctrl[i];
    SHELLMPM_CHECK(j >= 0 && std::size_t(j) < num_ctrl_, "control point "
                                                             << j << " of quadrature point " << q
                                                             << " out of range " << num_ctrl_);
    ctrl_[e] = j;
    value_[e] = T(p.N[i]);
    coef_[5 * e + 0] = T(p.N1[i]);
    coef_[5 * e + 1] = T(p.N2[i]);
    coef_[5 * e + 2] = T(p.N11[i]);
    coef_[5 * e + 3] = T(p.N12[i]);
    coef_[5 * e + 4] = T(p.N22[i]);
    const V3d& xj = rest[j];
    a1 += p.N1[i] * xj;
    a2 += p.N2[i] * xj;
    a11 += p.N11[i] * xj;
    a12 += p.N12[i] * xj;
    a22 += p.N22[i] * xj;
  }
  PointKinematics<double> k;
  k.a1 = a1;
  k.a2 = a2;
  k.a11 = a11;
  k.a12 = a12;
  k.a22 = a22;
  compute_kinematics(k);
  return k;
}

template <class T>
void KirchhoffLoveShellT<T>::build_gather_map() {
  // Entries by control point (ascending entry order).
  SHELLMPM_CHECK(ctrl_.size() < (std::size_t(1) << 32), "too many basis entries: " << ctrl_.size());
  std::vector<std::size_t> order;
  counting_sort(
      ctrl_.size(), num_ctrl_, [&](std::size_t e) { return ctrl_[e]; }, gather_begin_, order);
  slot_.resize(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) slot_[order[i]] = static_cast<std::uint32_t>(i);
}

template <class T>
void KirchhoffLoveShellT<T>::set_plasticity_in_energy(bool on) {
  if constexpr (std::is_same_v<T, float>) {
    SHELLMPM_CHECK(!on, "plasticity in the energy is for the double (implicit) shell");
  }
  in_energy_ = on && has_plasticity();
  // denting.h clamps Sum = l_1 + l_2 at sigma_y / (mu + lambda) and Diff = l_1 - l_2 at
  // sigma_y / (sqrt(3) mu).
  yield_sum_max_ = yield_ / (mu_ + lambda_);
  yield_diff_max_ = yield_ / (std::sqrt(T(3)) * mu_);
}

template <class T>
void KirchhoffLoveShellT<T>::reset_plastic_state() {
  for (std::size_t i = 0; i < fp_inv_.size(); i += 4) {
    fp_inv_[i] = T(1);
    fp_inv_[i + 1] = T(0);
    fp_inv_[i + 2] = T(0);
    fp_inv_[i + 3] = T(1);
  }
}

template <class T>
void KirchhoffLoveShellT<T>::set_plastic_state(const std::vector<T>& state) {
  SHELLMPM_CHECK(state.size() == fp_inv_.size(),
                 "plastic state size " << state.size() << " expected " << fp_inv_.size());
  fp_inv_ = state;
}

template <class T>
void KirchhoffLoveShellT<T>::eval_point(std::size_t q, const Vec3T* x, T* grad, double& e_total,
                                        double* e_membrane) const {
  PointKinematics<T> k;
  gather_kinematics(begin_, ctrl_, coef_, q, x, k);
  eval_kinematics(q, k, grad, e_total, e_membrane);
}

template <class T>
void KirchhoffLoveShellT<T>::eval_points(std::size_t q0, std::size_t n, const Vec3T* x, T* fe,
                                         double& e_total, double* e_membrane) const {
  T grad[15];
  for (std::size_t q = q0; q < q0 + n; ++q) {
    eval_point(q, x, fe ? grad : nullptr, e_total, e_membrane);
    if (fe) entry_shares(q, grad, fe);
  }
}

template <class T>
void KirchhoffLoveShellT<T>::entry_shares(std::size_t q, const T* G, T* fe) const {
  // dE/dx_j from entry (q, j): N1 Ga1 + N2 Ga2 + N11 G11 + N12 G12 + N22 G22.
  for (std::size_t e = begin_[q]; e < begin_[q + 1]; ++e) {
    const T* c = &coef_[5 * e];
    T* out = &fe[4 * std::size_t(slot_[e])];
    for (int d = 0; d < 3; ++d)
      out[d] = c[0] * G[d] + c[1] * G[3 + d] + c[2] * G[6 + d] + c[3] * G[9 + d] + c[4] * G[12 + d];
    out[3] = T(0);
  }
}

template <class T>
double KirchhoffLoveShellT<T>::membrane_energy(std::size_t q, const Vec3T& a1,
                                               const Vec3T& a2) const {
  // Mid-surface layer (xi3 = 0), whole thickness, with the layers' Gauss-weighted mean
  // plastic part.
  const T* B0 = &B0_[4 * q];
  T Bp0[4];
  if (!fp_inv_.empty()) {
    T fp_mean[4] = {0, 0, 0, 0};
    T wsum = 0;
    for (int l = 0; l < num_layers_; ++l) {
      const T* Fi = &fp_inv_[4 * (q * num_layers_ + l)];
      for (int i = 0; i < 4; ++i) fp_mean[i] += layer_w_[l] * Fi[i];
      wsum += layer_w_[l];
    }
    for (int i = 0; i < 4; ++i) fp_mean[i] /= wsum;
    mul2(B0, fp_mean, Bp0);
    B0 = Bp0;
  }
  return double(area_[q] * thickness_ *
                layer_psi(mu_, lambda_, stiffening_, B0, a1.dot(a1), a1.dot(a2), a2.dot(a2),
                          static_cast<T*>(nullptr)));
}

template <class T>
void KirchhoffLoveShellT<T>::eval_kinematics(std::size_t q, const kl::PointKinematics<T>& k,
                                             T* grad, double& e_total, double* e_membrane) const {
  using V3 = Vec3T;

  const bool plastic = !fp_inv_.empty();
  const kl::LayerYield<T> bounds{yield_sum_max_, yield_diff_max_};
  const T area = area_[q];
  V3 Ga1 = V3::Zero(), Ga2 = V3::Zero(), Gv1 = V3::Zero(), Gv2 = V3::Zero();
  T energy = 0;
  for (int l = 0; l < num_layers_; ++l) {
    const std::size_t ql = q * num_layers_ + l;
    const T xi3 = layer_xi3_[l];
    const V3 g1 = k.a1 + xi3 * k.v1, g2 = k.a2 + xi3 * k.v2;
    const T m11 = g1.dot(g1), m12 = g1.dot(g2), m22 = g2.dot(g2);
    const T* B = &B_[4 * ql];
    T Bp[4];
    if (plastic) {
      const T* Fi = &fp_inv_[4 * ql];
      mul2(B, Fi, Bp);
      B = Bp;
    }
    const T V = area * layer_w_[l];
    T S[3];
    energy += V * layer_psi(mu_, lambda_, stiffening_, B, m11, m12, m22, grad ? S : nullptr,
                            in_energy_ ? &bounds : nullptr);
    if (grad) {
      const T s = T(2) * V;
      const V3 dg1 = s * (S[0] * g1 + S[1] * g2);
      const V3 dg2 = s * (S[1] * g1 + S[2] * g2);
      Ga1 += dg1;
      Ga2 += dg2;
      Gv1 += xi3 * dg1;
      Gv2 += xi3 * dg2;
    }
  }
  e_total += double(energy);
  if (e_membrane) *e_membrane += membrane_energy(q, k.a1, k.a2);
  if (!grad) return;

  // Backpropagate through v_a = (I - a3 a3^T) m_a / l, l = |n|, n = a1 x a2 (sec. 1):
  // dE/dm_a = P Gv_a / l;
  // dE/dn = -(1/l) sum_a [(a3.t_a) P Gv_a + (a3.Gv_a) v_a + (Gv_a.v_a) a3].
  const V3 PG1 = Gv1 - k.a3 * k.a3.dot(Gv1), PG2 = Gv2 - k.a3 * k.a3.dot(Gv2);
  const V3 cm1 = PG1 * k.inv_l, cm2 = PG2 * k.inv_l;
  const V3 cn = -k.inv_l * (k.a3.dot(k.t1) * PG1 + k.a3.dot(Gv1) * k.v1 + Gv1.dot(k.v1) * k.a3 +
                            k.a3.dot(k.t2) * PG2 + k.a3.dot(Gv2) * k.v2 + Gv2.dot(k.v2) * k.a3);
  // Cross products: c . (u x v) -> dE/du = v x c, dE/dv = c x u.
  // m1 = a11 x a2 + a1 x a12; m2 = a12 x a2 + a1 x a22; n = a1 x a2.
  Ga1 += k.a12.cross(cm1) + k.a22.cross(cm2) + k.a2.cross(cn);
  Ga2 += cm1.cross(k.a11) + cm2.cross(k.a12) + cn.cross(k.a1);
  const V3 G11 = k.a2.cross(cm1);
  const V3 G12 = cm1.cross(k.a1) + k.a2.cross(cm2);
  const V3 G22 = cm2.cross(k.a1);
  for (int i = 0; i < 3; ++i) {
    grad[i] = Ga1[i];
    grad[3 + i] = Ga2[i];
    grad[6 + i] = G11[i];
    grad[9 + i] = G12[i];
    grad[12 + i] = G22[i];
  }
}

template <class T>
typename KirchhoffLoveShellT<T>::Energy KirchhoffLoveShellT<T>::energy(const Vec3T* x,
                                                                       Vec3T* forces, bool serial,
                                                                       bool membrane,
                                                                       bool total) const {
  const std::size_t nq = area_.size();
  // Each basis entry's share of its control point's force, in gather order (eval_points
  // writes every one). The object keeps the array between calls (a fresh one per call, 36 MB
  // on a 100k-point sheet, cost its page faults every time: a third of a force
  // evaluation); a call that finds it in use by another thread takes its own.
  const bool patched = this->patched();
  const std::size_t ne = patched ? patches_.num_entries() : slot_.size();
  std::vector<T> own;
  const bool shared = forces && !scratch_.busy.test_and_set(std::memory_order_acquire);
  std::vector<T>& entry_scratch = shared ? scratch_.shares : own;
  if (forces && entry_scratch.size() < 4 * ne) entry_scratch.resize(4 * ne);
  struct Release {
    std::atomic_flag* flag;
    ~Release() {
      if (flag) flag->clear(std::memory_order_release);
    }
  } release{shared ? &scratch_.busy : nullptr};
  T* const fe = forces ? entry_scratch.data() : nullptr;
  // Per chunk: total and membrane energy.
  // (On patches, chunks of kPointGrain points' worth of patches.)
  const std::size_t n = patched ? patches_.num_patches() : nq;
  // (Patch chunks start at multiples of the lane blocks: kl_patches.h, B_lanes.)
  constexpr std::size_t kLB = kl::Patches::kLaneBlock;
  const std::size_t grain =
      patched ? std::max(kLB, kPointGrain / std::size_t(patches_.points) / kLB * kLB) : kPointGrain;
  const std::vector<std::array<double, 2>> parts =
      chunk_parts(n, grain, serial, std::array<double, 2>{0.0, 0.0},
                  [&](std::size_t b, std::size_t e, std::array<double, 2>& part) {
                    double et = 0.0, em = 0.0;
                    if constexpr (std::is_same_v<T, float>) {
                      if (patched) {
                        eval_patch_range(b, e - b, x, fe, total || membrane ? &et : nullptr,
                                         membrane ? &em : nullptr);
                        part = {et, em};
                        return;
                      }
                    }
                    eval_points(b, e - b, x, fe, et, membrane ? &em : nullptr);
                    part = {et, em};
                  });
  double et = 0.0, em = 0.0;
  for (const std::array<double, 2>& part : parts) {
    et += part[0];
    em += part[1];
  }
  if (forces) {
    // Gather: dE/dx_j = the sum of its entries' shares, contiguous in gather order
    // (ascending entry order).
    parallel_for(
        num_ctrl_, kGatherGrain,
        [&](std::size_t b, std::size_t e) {
          const std::vector<std::size_t>& start = patched ? patches_.gather_begin : gather_begin_;
          for (std::size_t j = b; j < e; ++j) {
            Vec3T f = Vec3T::Zero();
            for (std::size_t i = start[j]; i < start[j + 1]; ++i)
              for (int d = 0; d < 3; ++d) f[d] += fe[4 * i + d];
            forces[j] -= f;
          }
        },
        serial);
  }
  Energy out;
  out.total = total || membrane ? T(et) : std::numeric_limits<T>::quiet_NaN();
  out.membrane = membrane ? T(em) : std::numeric_limits<T>::quiet_NaN();
  out.bending = membrane ? T(et - em) : std::numeric_limits<T>::quiet_NaN();
  return out;
}

template <class T>
std::vector<T> KirchhoffLoveShellT<T>::lumped_masses(std::size_t num_control_points) const {
  std::vector<double> m(num_control_points, 0.0);
  for (std::size_t q = 0; q < area_.size(); ++q)
    for (std::size_t e = begin_[q]; e < begin_[q + 1]; ++e) {
      const std::size_t j = std::size_t(ctrl_[e]);
      if (j < num_control_points)
        m[j] += rho_ * thickness_d_ * double(area_[q]) * double(value_[e]);
    }
  return std::vector<T>(m.begin(), m.end());
}

template class KirchhoffLoveShellT<float>;
template class KirchhoffLoveShellT<double>;

}  // namespace shellmpm
