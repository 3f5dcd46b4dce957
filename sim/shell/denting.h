// Denting: von Mises plasticity on the in-plane (plane stress) Kirchhoff stress of the
// Kirchhoff-Love layers. Supplement (Guo et al. 2018) section 7, eqs. (27)-(37).
//
// Conventions (choices documented here, used by KirchhoffLoveShellT):
// - Strains are the log singular values l_a = log(sigma_a) of the 2x2 in-plane elastic
//   block r^E (eq. 31); principal Kirchhoff stresses tau_a = 2 mu l_a + lambda (l_1 + l_2)
//   (eq. 33) with the plane-stress lambda (see KirchhoffLoveShellT).
// - `yield_stress` sigma_y is the uniaxial yield stress: the von Mises ellipse of eq. (28)
//   in the (tau_1, tau_2) plane is tau_1^2 + tau_2^2 - tau_1 tau_2 <= sigma_y^2, i.e.
//   c_vM = sqrt(2/3) sigma_y in eq. (27).
// - The ellipse is replaced (as the supplement says) by the region bounded by lines of
//   slope +-1: the rectangle, rotated by 45 degrees, whose sides touch the ellipse at the
//   ends of its axes:  |tau_1 + tau_2| <= 2 sigma_y (equi-biaxial yield at sigma_y) and
//   |tau_1 - tau_2| <= 2 sigma_y / sqrt(3) (pure shear yield at sigma_y / sqrt(3)).
// - The return is perpendicular to the boundary (closest point in the (tau_1, tau_2)
//   plane): clamp tau_1 + tau_2 and tau_1 - tau_2 separately (corners go to the corner).
//   The elastic moduli matrix of eq. (36) has eigenvectors (1, 1) and (1, -1), so this
//   is also the closest point in the energy norm, and the elastic energy never rises.
#pragma once
#include <Eigen/Core>

namespace shellmpm {

/// Principal Kirchhoff stresses (tau_1, tau_2) [Pa] from log singular values (eq. 33).
template <class T>
Eigen::Matrix<T, 2, 1> denting_principal_stress(T mu, T lambda, const Eigen::Matrix<T, 2, 1>& l);

/// Dimensionless yield function of the slope +-1 region: <= 0 feasible, 0 on the boundary.
/// f = max(|tau_1 + tau_2| / (2 sigma_y), sqrt(3) |tau_1 - tau_2| / (2 sigma_y)) - 1.
template <class T>
T denting_yield_function(T tau1, T tau2, T yield_stress);

/// Return mapping on the log singular values (eqs. 33, 36). Returns false and leaves `l`
/// untouched (bitwise) when the trial stress is feasible; otherwise projects the
/// stress perpendicular to the boundary, recovers l from eq. (36) and returns true.
template <class T>
bool denting_return_map(T mu, T lambda, T yield_stress, Eigen::Matrix<T, 2, 1>& l);

/// Elastic energy density mu |l|^2 + lambda/2 (l_1 + l_2)^2 [J/m^3].
template <class T>
T denting_energy_density(T mu, T lambda, const Eigen::Matrix<T, 2, 1>& l);

/// Return mapping of one Kirchhoff-Love layer, in its orthonormal rest frame.
/// Ce: trial elastic right Cauchy-Green tensor (r^E)^T r^E (2x2, symmetric positive),
/// where r^E = r Fp_inv and r is the in-plane block of the QR of F (eq. 31).
/// Fp_inv: the stored inverse plastic part (F^P)^-1 (2x2). On yield, with
/// Ce = V diag(sigma^2) V^T, the elastic singular values become sigma' (eq. 36) with the
/// same U, V (eq. 37), so F^P = (F^E)^-1 F gives Fp_inv <- Fp_inv V diag(sigma'/sigma) V^T.
/// Returns the plastic work density tau(l) . (l_trial - l) >= 0 [J/m^3] (the returned
/// principal stresses times the plastic log-strain increment: the dissipation of the
/// return, whatever the trial's overshoot; the elastic energy released,
/// psi(trial) - psi(projected), exceeds it by the overshoot's own energy, which at long
/// implicit steps is most of it); 0 and Fp_inv untouched (bitwise) below yield.
/// `yielded` (optional) reports the branch.
template <class T>
T denting_project_layer(T mu, T lambda, T yield_stress, const Eigen::Matrix<T, 2, 2>& Ce,
                        Eigen::Matrix<T, 2, 2>& Fp_inv, bool* yielded = nullptr);

}  // namespace shellmpm
