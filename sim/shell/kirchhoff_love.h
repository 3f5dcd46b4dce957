// Kirchhoff-Love ("laminate") shell elasticity with optional denting plasticity.
// Guo et al. 2018, supplement sections 1 (forces), 3-4 (laminate stress, QR) and 7
// (denting); METHOD.md "Kinematics of the shell" and "Kirchhoff-Love elasticity".
//
// Kinematics (supplement sec. 1): at an in-plane quadrature point
//   a_a = sum_j x_j N_j,a;  a_3 = a_1 x a_2 / |a_1 x a_2|;
//   a_3,a = (I - a_3 a_3^T)(a_1,a x a_2 + a_1 x a_2,a) / |a_1 x a_2|;
//   g_a = a_a + xi3 a_3,a;  g_3 = a_3;  F = sum_i g_i (x) gbar^i,
// with gbar^i the dual basis of the rest g-bar_i at the same xi3 (rest curvature
// included, so any rest shape is stress free).
// Energy (sec. 3, 4): F = r_ab q_a (x) e_b + q_3 (x) e_3 in an orthonormal rest frame
// (e_1 along gbar_1, e_3 = abar_3). Only the in-plane 2x2 block r matters: with the
// stored plastic part, r^E = r (F^P)^-1 = U diag(s) V^T and
//   psi = mu |log s|^2 + lambda_ps / 2 (tr log s)^2,  lambda_ps = 2 mu lambda / (lambda + 2 mu)
// (plane stress: membrane stiffness E t / (1 - nu^2), bending E t^3 / (12 (1 - nu^2))).
// The kernel never forms q or U: s^2 are the eigenvalues of
// C = (r^E)^T r^E = Bp^T M Bp, with M_ab = g_a . g_b and Bp = B (F^P)^-1,
// B_ba = gbar^b . e_a fixed at rest; log C is evaluated in closed form.
//
// Large-stretch stiffening (our addition beyond the supplement, which has plain Hencky;
// issue 10). Hencky's force along a principal stretch, dpsi/ds_a = (2 mu log s_a +
// lambda_ps tr log s) / s_a, peaks near s_a = e and then falls: a sheet pulled past ~2.7x
// necks without bound. Beyond a stretch limit s_l (ShellMaterialDesc::stretch_limit,
// default 1.5) each singular value adds
//   psi_s = k sum_a max(s_a - s_l, 0)^2,   k = 0.45 (mu + lambda_ps) = 0.225 E / (1 - nu).
// - C1 at s_l: energy and force are continuous, d2psi/ds_a^2 jumps by 2k. Where both
//   s_a <= s_l the energy and forces are bitwise those of plain Hencky.
// - Range of the guarantee: 0 <= nu < 1/2, 1 < s_l <= kMaxStretchLimit = 1.9, a the larger
//   stretch (s_b <= s_a). There
//     d2psi/ds_a^2 = (d (1 - log s_a) - lambda_ps log s_b) / s_a^2 + 2k [s_a > s_l],
//   d = 2 mu + lambda_ps = E / (1 - nu^2), is positive for every s_a: the Hencky part is
//   positive up to log s_a = 1 / (1 + nu) (>= 2/3: s_a >= 1.95 > s_l), and its most
//   negative value, -(mu + lambda_ps) e^{-1 - 2/(1+nu)} > -0.097 (mu + lambda_ps) (at
//   s_b = s_a, log s_a = 1/2 + 1/(1+nu); with s_b = 1 it is -d e^{-3} / 2 at
//   s_a = e^{3/2}), is above -2k = -0.9 (mu + lambda_ps). So the force along the larger
//   principal stretch rises monotonically for all s_a and the energy grows without bound.
// - The smaller stretch keeps Hencky's Poisson coupling: its curvature is positive while
//   log s_a < (1 - log s_b) / nu.
// - Time step: past s_l = 1.5 (with s_b >= 1) the tangent, at most 0.26 d from Hencky plus
//   2k = 0.45 (1 + nu) d (<= 0.675 d), stays below the small-strain d, so the rest wave
//   speed in ShellObject::stable_dt still bounds the step. k is as stiff as that allows:
//   with k = (mu + lambda_ps) / 8, 2 kg of sand on a cloth held at four single points
//   stretched its corners to 8x and diverged (scenes/stress/sand_cloth_point_pins.yaml);
//   with 0.45 it peaks at 4.3x and holds.
// - Denting (denting.h) returns with the Hencky stress; with a yield stress << E its
//   elastic stretches stay far below s_l.
//
// Quadrature and volume: V_{q,k} = w_q |abar_1 x abar_2| (t/2) w_k (mid-surface area
// times the Gauss layer thickness; the curvature shift of the volume element,
// det(gbar) / det(abar) = 1 + O(t kappa), is NOT included, a standard thin-shell choice).
// Layers sit at xi3 = (t/2) zeta_k with Gauss-Legendre (zeta_k, w_k).
//
// Membrane / bending split (diagnostic only): membrane = t sum_q w_q |abar_1 x abar_2|
// psi(xi3 = 0), evaluated with the mid-surface rest basis and the Gauss-weighted mean of
// the layers' plastic parts; bending = total - membrane (may be slightly negative when
// plasticity makes layers disagree).
//
// Plastic state (sec. 7): per (quadrature point, layer) the inverse plastic part
// (F^P)^-1 as a 2x2 matrix in that layer's orthonormal rest frame (e_1, e_2), identity at
// rest. Only allocated when yield_stress > 0.
#pragma once
#include <Eigen/Core>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "sim/core/types.h"
#include "sim/scene/scene.h"
#include "sim/shell/kl_patches.h"

#if __has_include("sim/shell/loop_basis.h")
#include "sim/shell/loop_basis.h"
#else
namespace shellmpm {
/// Basis functions at one parametric point: values, first and second derivatives
/// (d/dxi1, d/dxi2, d2/dxi1^2, d2/dxi1 dxi2, d2/dxi2^2) for the control points `ctrl`.
struct BasisPoint {
  std::vector<int> ctrl;
  std::vector<double> N, N1, N2, N11, N12, N22;
};
}  // namespace shellmpm
#endif

namespace shellmpm {

/// Rest data and plastic state for all quadrature points of one shell.
/// T is the evaluation scalar (float or double); rest data is computed in double.
namespace kl {
template <class T>
struct PointKinematics;  // sim/shell/kl_kinematics.h
struct BatchData;        // sim/shell/kl_batch.h
}  // namespace kl

template <class T>
class KirchhoffLoveShellT {
 public:
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  using Mat2T = Eigen::Matrix<T, 2, 2>;

  /// Largest allowed ShellMaterialDesc::stretch_limit (see the file comment: below
  /// e^{2/3} = 1.95 the Hencky term is convex along the larger stretch for any nu in [0, 1/2)).
  static constexpr double kMaxStretchLimit = 1.9;
  /// k = kStretchStiffening (mu + lambda_ps): the coefficient of (s_a - s_l)^2 [Pa].
  static constexpr double kStretchStiffening = 0.45;

  /// points: one BasisPoint per in-plane quadrature point; inplane_weights: their
  /// parametric weights (sum 1/2 per triangle; the area factor |abar_1 x abar_2| is
  /// computed here from `rest`); rest: control point rest positions [m];
  /// thickness_points: Gauss points through the thickness (1..5).
  /// Throws InvariantError on inconsistent sizes, bad indices or a degenerate rest tangent.
  KirchhoffLoveShellT(std::vector<BasisPoint> points, std::vector<double> inplane_weights,
                      const std::vector<Eigen::Matrix<double, 3, 1>>& rest,
                      const ShellMaterialDesc& mat, int thickness_points);

  struct Energy {
    T membrane, bending, total;  ///< [J]
  };

  /// Elastic energy [J] at control positions x (num_control_points() entries). If
  /// forces != nullptr, adds -dE/dx_j [N] into forces[j] (exact gradient of the discrete
  /// energy). Results are bitwise independent of the thread count (fixed chunks, sums in
  /// chunk order, forces gathered per control point in a fixed order); serial = no threads.
  /// membrane: split the energy into membrane and bending (a diagnostic: one more energy
  /// evaluation per quadrature point, measured 4% of a force evaluation on a 20k-point
  /// sheet); without it Energy::membrane and ::bending are NaN and only total is set.
  /// total: sum the energy (without it, and without membrane, every part is NaN: the
  /// forces alone, for the explicit step, which has no use for the energy).
  Energy energy(const Vec3T* x, Vec3T* forces, bool serial = false, bool membrane = true,
                bool total = true) const;

  /// Denting return mapping (supplement sec. 7) for every quadrature point and layer at
  /// positions x; updates the stored plastic state. Returns the plastic work dissipated
  /// in this call [J] = sum V tau . (l_trial - l) >= 0 (denting_project_layer). No-op (returns 0)
  /// when yield_stress == 0; a layer below yield is left bitwise unchanged.
  T project_plasticity(const Vec3T* x, bool serial = false);

  /// The stiffness d^2E/dx^2 at x as 3x3 blocks per coupled pair of control points: for
  /// each (i, j) of a quadrature point's entries, add(i, j, block) is called (in a fixed
  /// order; the same pair comes from several points, and add must sum). Each point's
  /// energy depends on x only through (a_1, a_2, a_11, a_12, a_22), linear in x, so its
  /// Hessian is J^T H J with H (15 x 15) from forward differences of the point's exact
  /// adjoints (step h_rel |a_alpha|, symmetrised): 16 point evaluations, where finite
  /// differences of the whole force field take one force evaluation per colour and axis
  /// (150 on a Loop sheet). Double only. With psd, each point's H is replaced by its
  /// positive semi-definite part (negative eigenvalues set to zero: the compressed
  /// membrane's geometric stiffness), so the sum is positive semi-definite.
  void stiffness_blocks(const Vec3T* x, double h_rel,
                        const std::function<void(int, int, const Eigen::Matrix<T, 3, 3>&)>& add,
                        bool serial = false, bool psd = false) const;

  /// Largest |log s_a| (principal elastic Hencky strain, either sign) over all
  /// quadrature points and layers.
  T max_strain(const Vec3T* x, bool serial = false) const;

  /// Lumped masses sum_q rho t w_q |abar_1 x abar_2| N_j [kg] for control points
  /// 0..num_control_points-1 (control points outside every support get 0).
  std::vector<T> lumped_masses(std::size_t num_control_points) const;

  /// Plastic state: 4 values per (quadrature point, layer), layer fastest, each the
  /// row-major 2x2 (F^P)^-1 in the layer's rest frame. Empty when yield_stress == 0.
  const std::vector<T>& plastic_state() const { return fp_inv_; }
  /// Restores a state from plastic_state() (bitwise). Size must match.
  void set_plastic_state(const std::vector<T>& state);
  /// Resets every layer to F^P = I.
  void reset_plastic_state();

  /// Plasticity in the energy (the implicit solves; double only): with on, each layer's
  /// energy beyond yield is the denting return's incremental potential (laminate_energy.h,
  /// Huber's function of the clamped log-stretch sum and difference from the stored
  /// plastic part), so energy() and its forces are those of the stress that
  /// project_plasticity() will return to at the same positions, and stiffness_blocks()
  /// that potential's Hessian. Below yield, bitwise the elastic energy. The stored state
  /// is unchanged: project_plasticity() after the step updates it.
  void set_plasticity_in_energy(bool on);
  bool plasticity_in_energy() const { return in_energy_; }

  std::size_t num_quadrature_points() const { return area_.size(); }
  int num_layers() const { return num_layers_; }
  std::size_t num_control_points() const { return num_ctrl_; }
  bool has_plasticity() const { return yield_ > 0; }
  T mu() const { return mu_; }
  T lambda_plane_stress() const { return lambda_; }
  /// Stretch limit s_l and stiffening coefficient k [Pa] of psi_s = k sum (s_a - s_l)_+^2.
  T stretch_limit() const { return stiffening_.limit; }
  T stretch_stiffness() const { return stiffening_.k; }
  /// Whether forces run on patches (sim/shell/kl_patches.h: float, points in runs sharing
  /// their control points); use_patches(false) makes them run point by point (the same
  /// energy and point adjoints, force shares summed in another order: for comparisons).
  bool patched() const { return !patches_.empty() && use_patches_; }
  void use_patches(bool on) { use_patches_ = on; }
  /// Rest area of the shell sum_q w_q |abar_1 x abar_2| [m^2].
  double rest_area() const { return rest_area_; }

 private:
  // Construction steps.
  /// begin_ from the points' entry counts; the per-entry and per-point arrays sized.
  void size_entries(const std::vector<BasisPoint>& points);
  /// Point q's entries (control points, N and its derivatives) and its rest kinematics.
  kl::PointKinematics<double> load_point(std::size_t q, const BasisPoint& p,
                                         const std::vector<Eigen::Matrix<double, 3, 1>>& rest);
  /// gather_begin_, gather_ from ctrl_.
  void build_gather_map();
  // Per quadrature point: adjoints of (a_1, a_2, a_11, a_12, a_22) in `grad`
  // (15 values); returns energy and membrane energy.
  void eval_point(std::size_t q, const Vec3T* x, T* grad, double& e_total,
                  double* e_membrane) const;
  /// The same from point q's kinematics (without the membrane diagnostic where
  /// e_membrane is null).
  void eval_kinematics(std::size_t q, const kl::PointKinematics<T>& k, T* grad, double& e_total,
                       double* e_membrane) const;

  /// eval_point for points q0 .. q0 + n - 1 in order (energies added in that order), each
  /// point's adjoints turned into its entries' force shares (entry_shares) when fe is not
  /// null. The float specialisation (sim/shell/kl_batch.cpp) runs 4, 8 or 16 points per
  /// register (SSE, AVX2, AVX-512), with the same bits on each.
  void eval_points(std::size_t q0, std::size_t n, const Vec3T* x, T* fe, double& e_total,
                   double* e_membrane) const;
  /// The float kernel's view of the arrays (sim/shell/kl_batch.cpp).
  kl::BatchData batch_data() const;
  /// eval_points for the patches at positions i0 .. i0 + n - 1 of patches_.order (their
  /// points' energies added in that order, point by point), each patch entry's force share
  /// at its slot in the patches' gather order. Float only (sim/shell/kl_batch.cpp). A
  /// null e_total: no energies summed (the forces alone).
  void eval_patch_range(std::size_t i0, std::size_t n, const Vec3T* x, T* fe, double* e_total,
                        double* e_membrane) const;
  /// From point q's adjoints G (15 values), writes each of its entries' dE/dx share (3
  /// values and a zero, so that one SSE store writes a share) at the entry's slot in gather
  /// order: fe[4 slot_[e] ..].
  void entry_shares(std::size_t q, const T* G, T* fe) const;
  /// The membrane diagnostic of point q: its mid-surface layer energy [J] (file comment).
  double membrane_energy(std::size_t q, const Vec3T& a1, const Vec3T& a2) const;

  /// The large-stretch term: s_l, log s_l and k.
  struct Stiffening {
    T limit = 0, log_limit = 0, k = 0;
  };

  std::size_t num_ctrl_ = 0;
  int num_layers_ = 0;
  T mu_ = 0, lambda_ = 0, yield_ = 0, thickness_ = 0;
  Stiffening stiffening_;
  bool in_energy_ = false;                    // set_plasticity_in_energy
  T yield_sum_max_ = 0, yield_diff_max_ = 0;  // its bounds (laminate_energy.h LayerYield)
  double rho_ = 0, thickness_d_ = 0, rest_area_ = 0;
  std::vector<std::size_t> begin_;      // entries of quadrature point q: [begin_[q], begin_[q+1])
  std::vector<int> ctrl_;               // control point of each entry
  std::vector<T> coef_;                 // 5 per entry: N1, N2, N11, N12, N22
  std::vector<T> value_;                // N per entry (masses)
  std::vector<T> area_;                 // w_q |abar_1 x abar_2| per point
  std::vector<T> layer_xi3_, layer_w_;  // xi3 = (t/2) zeta_k, (t/2) w_k
  std::vector<T> B_;                    // 4 per (q, layer), row-major B
  std::vector<T> B0_;                   // 4 per q: mid-surface B
  std::vector<T> fp_inv_;               // 4 per (q, layer) (empty without plasticity)
  // Gather map for forces: the entries touching control point j hold the slots
  // gather_begin_[j] .. gather_begin_[j+1] - 1, in ascending entry order; slot_[e] is
  // entry e's.
  std::vector<std::size_t> gather_begin_;
  std::vector<std::uint32_t> slot_;
  kl::Patches patches_;  // float only; empty where the points form no patches
  bool use_patches_ = true;
  // energy()'s per-entry force shares (4 per entry), kept between calls; busy marks it in
  // use (a concurrent call takes its own). A copy of the object starts without one.
  struct ForceScratch {
    std::vector<T> shares;
    std::atomic_flag busy = ATOMIC_FLAG_INIT;
    ForceScratch() = default;
    ForceScratch(const ForceScratch&) {}
    ForceScratch& operator=(const ForceScratch&) { return *this; }
  };
  mutable ForceScratch scratch_;
};

/// The batched float kernel (sim/shell/kl_batch.cpp).
template <>
void KirchhoffLoveShellT<float>::eval_points(std::size_t q0, std::size_t n, const Vec3T* x,
                                             float* fe, double& e_total, double* e_membrane) const;

template <>
kl::BatchData KirchhoffLoveShellT<float>::batch_data() const;
template <>
void KirchhoffLoveShellT<float>::eval_patch_range(std::size_t i0, std::size_t n, const Vec3T* x,
                                                  float* fe, double* e_total,
                                                  double* e_membrane) const;
using KirchhoffLoveShell = KirchhoffLoveShellT<Real>;

extern template class KirchhoffLoveShellT<float>;
extern template class KirchhoffLoveShellT<double>;

}  // namespace shellmpm
