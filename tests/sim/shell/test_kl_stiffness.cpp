// The Kirchhoff-Love stiffness from per quadrature point Hessians (sim/shell/kl_stiffness.h)
// against finite differences of the whole force field, on a bent, stretched, twisted
// steel sheet with a plastic state.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>

#include "io/scene_reader.h"
#include "sim/shell/kl_stiffness.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

namespace {

/// The steel dent's sheet alone (no contact, no colliders).
Solver steel_sheet() {
  Scene s = read_scene(std::string(SHELLMPM_SOURCE_DIR) + "/scenes/steel_dent.yaml");
  s.shells[0].contact = ShellDesc::Contact::Off;
  s.colliders.clear();
  return Solver(s);
}

}  // namespace

TEST_CASE("KL stiffness: per-point Hessians match finite differences of the forces",
          "[shell][implicit]") {
  const Solver solver = steel_sheet();
  const ShellObject& sh = *solver.shells()[0];
  std::vector<std::vector<int>> coupling;
  const auto kl = sh.double_kl(&coupling);
  const std::size_t n = sh.size();
  std::vector<Vec3d> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d r = sh.x[i].cast<double>();
    // Bend, stretch and twist.
    x[i] = Vec3d(1.01 * r.x(), r.y() - 0.4 * r.x() * r.x() + 0.3 * r.x() * r.z(), 0.995 * r.z());
  }
  // A plastic state (the yield stress is exceeded at this bend), then a different shape.
  const double work = kl->project_plasticity(x.data());
  CHECK(work > 0);
  for (std::size_t i = 0; i < n; ++i) x[i].y() += 0.02 * std::sin(20 * x[i].x()) * x[i].z();

  std::vector<int> dof_of(3 * n);
  for (std::size_t k = 0; k < 3 * n; ++k) dof_of[k] = static_cast<int>(k);
  const int dofs = static_cast<int>(3 * n);
  const SparseMatrixD K = kl_stiffness_matrix(*kl, x, dof_of, dofs);
  const SparseMatrixD Kt = K.transpose();
  CHECK((K - Kt).norm() <= 1e-12 * K.norm());

  // Products with a smooth direction against central differences of the forces.
  auto forces = [&](const std::vector<Vec3d>& p) {
    std::vector<Vec3d> f(n, Vec3d::Zero());
    kl->energy(p.data(), f.data(), true);
    return f;
  };
  Eigen::VectorXd d(dofs);
  for (int k = 0; k < dofs; ++k) d[k] = std::cos(0.37 * k) * (1 + 0.5 * std::sin(0.11 * k));
  const Eigen::VectorXd Kd = K * d;
  double prev = 1e300;
  for (const double h : {1e-5, 1e-6, 1e-7}) {
    std::vector<Vec3d> xp = x, xm = x;
    for (std::size_t i = 0; i < n; ++i) {
      xp[i] += h * d.segment<3>(3 * static_cast<Eigen::Index>(i));
      xm[i] -= h * d.segment<3>(3 * static_cast<Eigen::Index>(i));
    }
    const std::vector<Vec3d> fp = forces(xp), fm = forces(xm);
    Eigen::VectorXd fd(dofs);
    for (std::size_t i = 0; i < n; ++i)
      fd.segment<3>(3 * static_cast<Eigen::Index>(i)) = (fm[i] - fp[i]) / (2 * h);
    const double err = (fd - Kd).norm() / Kd.norm();
    INFO("h " << h << " relative error " << err);
    CHECK(err < 1e-4);
    prev = std::min(prev, err);
  }
  CHECK(prev < 1e-6);

  // The whole matrix against the colour-by-colour finite differences it replaces.
  std::vector<Vec3d> f0 = forces(x);
  const std::vector<std::vector<int>> groups = colour_points(coupling, std::vector<char>(n, 1));
  const PointForceFn ff = [&](const std::vector<Vec3d>& p, std::vector<Vec3d>& f) {
    kl->energy(p.data(), f.data(), true);
  };
  const SparseMatrixD Kfd = fd_stiffness(ff, x, f0, dof_of, dofs, coupling, groups, 1e-9);
  const double scale = Eigen::MatrixXd(K).cwiseAbs().maxCoeff();
  CHECK(Eigen::MatrixXd(K - Kfd).cwiseAbs().maxCoeff() < 1e-4 * scale);
}

TEST_CASE("KL stiffness: the positive semi-definite part of a compressed sheet's",
          "[shell][implicit]") {
  const Solver solver = steel_sheet();
  const ShellObject& sh = *solver.shells()[0];
  const auto kl = sh.double_kl(nullptr);
  const std::size_t n = sh.size();
  // Compressed in plane (2% along x, 1% along z) with a slight bend: the membrane's
  // geometric stiffness is negative along the buckling modes.
  std::vector<Vec3d> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d r = sh.x[i].cast<double>();
    x[i] = Vec3d(0.98 * r.x(), r.y() + 0.01 * r.x() * r.z(), 0.99 * r.z());
  }
  std::vector<int> dof_of(3 * n);
  for (std::size_t k = 0; k < 3 * n; ++k) dof_of[k] = static_cast<int>(k);
  const int dofs = static_cast<int>(3 * n);
  const Eigen::MatrixXd K = Eigen::MatrixXd(kl_stiffness_matrix(*kl, x, dof_of, dofs));
  const Eigen::MatrixXd Kp =
      Eigen::MatrixXd(kl_stiffness_matrix(*kl, x, dof_of, dofs, false, /*psd=*/true));
  const double scale = K.cwiseAbs().maxCoeff();
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K).eigenvalues();
  const Eigen::VectorXd evp = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Kp).eigenvalues();
  INFO("smallest eigenvalue " << ev[0] << ", projected " << evp[0] << ", scale " << scale);
  CHECK(ev[0] < -1e-6 * scale);   // the compressed sheet's Hessian is indefinite
  CHECK(evp[0] > -1e-9 * scale);  // its projection is not
  // Each point's projection adds a positive semi-definite part: Kp >= K in every direction,
  // and the two agree where the sheet is stretched (every point's Hessian semi-definite).
  for (int t = 0; t < 20; ++t) {
    Eigen::VectorXd d(dofs);
    for (int k = 0; k < dofs; ++k) d[k] = std::sin(0.7 * k * (t + 1) + t);
    CHECK(d.dot(Kp * d) >= d.dot(K * d) - 1e-9 * scale * d.squaredNorm());
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d r = sh.x[i].cast<double>();
    x[i] = Vec3d(1.02 * r.x(), r.y(), 1.02 * r.z());
  }
  const Eigen::MatrixXd Ks = Eigen::MatrixXd(kl_stiffness_matrix(*kl, x, dof_of, dofs));
  const Eigen::MatrixXd Ksp =
      Eigen::MatrixXd(kl_stiffness_matrix(*kl, x, dof_of, dofs, false, /*psd=*/true));
  CHECK((Ksp - Ks).cwiseAbs().maxCoeff() <= 1e-9 * Ks.cwiseAbs().maxCoeff());
}
