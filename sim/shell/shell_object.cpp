#include "sim/shell/shell_object.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/collider/collider.h"
#include "sim/core/check.h"
#include "sim/core/parallel.h"
#include "sim/shell/procedural_mesh.h"
#include "sim/shell/shell_quadrature.h"

namespace shellmpm {
namespace {

/// Basis at every in-plane quadrature point of every face, with parametric weights.
void quadrature_points(const LoopBasis& basis, int num_faces, int inplane_points,
                       std::vector<BasisPoint>& pts, std::vector<double>& weights) {
  const TriangleQuadrature rule = triangle_quadrature(inplane_points);
  pts.clear();
  weights.clear();
  pts.reserve(num_faces * rule.points.size());
  for (int f = 0; f < num_faces; ++f)
    for (std::size_t q = 0; q < rule.points.size(); ++q) {
      BasisPoint bp;
      basis.evaluate(f, rule.points[q].x(), rule.points[q].y(), bp);
      pts.push_back(std::move(bp));
      weights.push_back(rule.weights[q]);
    }
}

/// Adds gravity (lumped masses), pressure on the control mesh and point loads at x.
template <class T>
void add_loads(const ShellDesc& desc, const std::vector<Eigen::Vector3i>& tris,
               const std::vector<Real>& mass, const Vec3d& gravity,
               const std::vector<Eigen::Matrix<T, 3, 1>>& x, std::vector<Eigen::Matrix<T, 3, 1>>& f,
               bool serial) {
  using V3 = Eigen::Matrix<T, 3, 1>;
  const V3 g = gravity.cast<T>();
  parallel_for(
      x.size(), 16384,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) f[i] += static_cast<T>(mass[i]) * g;
      },
      serial);
  if (desc.pressure != 0) {
    // Pressure on the control mesh: p * area * normal, a third to each corner.
    for (const auto& t : tris) {
      const V3 an = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);  // 2 * area * n
      const V3 fc = (static_cast<T>(desc.pressure) / T(6)) * an;
      for (int c = 0; c < 3; ++c) f[t[c]] += fc;
    }
  }
  for (const PointLoadDesc& pl : desc.point_loads) f[pl.index] += pl.force.cast<T>();
}

}  // namespace

ShellMesh build_shell_rest_mesh(const ShellDesc& d) {
  ShellMesh m;
  switch (d.kind) {
    case ShellDesc::Kind::Sheet:
      m = make_sheet(d.size[0], d.size[1], d.resolution[0], d.resolution[1]);
      break;
    case ShellDesc::Kind::Cylinder:
      m = make_cylinder(d.radius, d.height, d.angle_deg, d.resolution[0], d.resolution[1]);
      break;
    case ShellDesc::Kind::Sphere:
      m = make_sphere(d.radius, d.subdivisions);
      break;
    case ShellDesc::Kind::Mesh:
      SHELLMPM_CHECK(d.mesh != nullptr, << "shell mesh not loaded: " << d.mesh_path);
      m = *d.mesh;
      break;
  }
  const Vec3d r = d.rotate_deg * (M_PI / 180.0);
  const Mat3d R =
      (Eigen::AngleAxisd(r.z(), Vec3d::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3d::UnitY()) *
       Eigen::AngleAxisd(r.x(), Vec3d::UnitX()))
          .toRotationMatrix();
  for (Vec3d& p : m.vertices) p = R * (d.scale * p) + d.translate;
  return m;
}

ShellObject::ShellObject(const ShellDesc& desc, const ShellMaterialDesc& mat, ShellMesh rest_mesh)
    : desc_(desc), mat_(mat) {
  tris_ = rest_mesh.triangles;
  rest = rest_mesh.vertices;
  const int nv = static_cast<int>(rest.size());
  basis_ = std::make_unique<LoopBasis>(nv, tris_);
  // Quadrature points: every face with the in-plane rule.
  std::vector<BasisPoint> pts;
  std::vector<double> weights;
  quadrature_points(*basis_, static_cast<int>(tris_.size()), mat.quadrature_inplane, pts, weights);
  kl_ = std::make_unique<KirchhoffLoveShell>(std::move(pts), std::move(weights), rest, mat,
                                             mat.quadrature_thickness);
  limit_ = std::make_unique<LimitMesh>(*basis_, tris_, rest_mesh.uvs, rest_mesh.uv_triangles,
                                       desc.output_refine);
  mass = kl_->lumped_masses(rest.size());
  x.resize(nv);
  v.assign(nv, desc.velocity.cast<Real>());
  for (int i = 0; i < nv; ++i) x[i] = rest[i].cast<Real>();
  // Pins.
  pin_mask.assign(nv, 0);
  pin_of.assign(nv, -1);
  for (int p = 0; p < static_cast<int>(desc.pins.size()); ++p) {
    const PinDesc& pin = desc.pins[p];
    std::uint8_t mask = 0;
    for (int a = 0; a < 3; ++a) mask |= pin.components[a] ? (1u << a) : 0u;
    auto hold = [&](int i) {
      SHELLMPM_CHECK(i >= 0 && i < nv, << "pin index " << i << " of " << nv);
      pin_mask[i] |= mask;
      pin_of[i] = p;
    };
    for (int i : pin.indices) hold(i);
    if (pin.has_box)
      for (int i = 0; i < nv; ++i)
        if ((rest[i].array() >= pin.box_min.array()).all() &&
            (rest[i].array() <= pin.box_max.array()).all())
          hold(i);
    if (!pin.group.empty()) {
      const auto it = rest_mesh.groups.find(pin.group);
      SHELLMPM_CHECK(it != rest_mesh.groups.end(), << "vertex group " << pin.group);
      for (int i : it->second) hold(i);
    }
  }
  for (int i = 0; i < nv; ++i)
    if (pin_mask[i]) v[i].setZero();
  min_edge_ = std::numeric_limits<double>::infinity();
  for (const auto& t : tris_)
    for (int e = 0; e < 3; ++e) {
      const double len = (rest[t[e]] - rest[t[(e + 1) % 3]]).norm();
      if (len < min_edge_) {
        min_edge_ = len;
        min_edge_vertices_ = {t[e], t[(e + 1) % 3]};
      }
    }
}

void ShellObject::forces(const Vec3d& gravity, std::vector<Vec3>& f, bool serial) const {
  const std::size_t n = x.size();
  f.assign(n, Vec3::Zero());
  // The membrane/bending split is a statistic (Solver::measure): not on the hot path.
  kl_->energy(x.data(), f.data(), serial, false, false);
  if (mat_.stiffness_damping > 0) {
    // Rayleigh stiffness damping -beta K v, with K v from the directional derivative of
    // the elastic force: f(x + eps v) - f(x) = -eps K v + O(eps^2).
    // f holds only the elastic force f(x) at this point.
    const Real eps = Real(1e-4);
    std::vector<Vec3> xs(n), f2(n, Vec3::Zero());
    for (std::size_t i = 0; i < n; ++i) xs[i] = x[i] + eps * v[i];
    kl_->energy(xs.data(), f2.data(), serial, false, false);
    const Real c = static_cast<Real>(mat_.stiffness_damping) / eps;
    for (std::size_t i = 0; i < n; ++i) f[i] += c * (f2[i] - f[i]);
  }
  add_loads(desc_, tris_, mass, gravity, x, f, serial);
}

std::unique_ptr<KirchhoffLoveShellT<double>> ShellObject::double_kl(
    std::vector<std::vector<int>>* coupling) const {
  const std::size_t n = x.size();
  std::vector<BasisPoint> pts;
  std::vector<double> weights;
  quadrature_points(*basis_, static_cast<int>(tris_.size()), mat_.quadrature_inplane, pts, weights);
  if (coupling) {
    // Points sharing a quadrature point (the union over each face's points).
    coupling->assign(n, {});
    const std::size_t per_face = pts.size() / std::max<std::size_t>(tris_.size(), 1);
    std::vector<int> face_ctrl;
    for (std::size_t f = 0; f < tris_.size(); ++f) {
      face_ctrl.clear();
      for (std::size_t q = f * per_face; q < (f + 1) * per_face; ++q)
        face_ctrl.insert(face_ctrl.end(), pts[q].ctrl.begin(), pts[q].ctrl.end());
      std::sort(face_ctrl.begin(), face_ctrl.end());
      face_ctrl.erase(std::unique(face_ctrl.begin(), face_ctrl.end()), face_ctrl.end());
      for (int j : face_ctrl)
        (*coupling)[j].insert((*coupling)[j].end(), face_ctrl.begin(), face_ctrl.end());
    }
    for (std::size_t j = 0; j < n; ++j) {
      std::vector<int>& c = (*coupling)[j];
      c.push_back(static_cast<int>(j));
      std::sort(c.begin(), c.end());
      c.erase(std::unique(c.begin(), c.end()), c.end());
    }
  }
  auto kl = std::make_unique<KirchhoffLoveShellT<double>>(std::move(pts), std::move(weights), rest,
                                                          mat_, mat_.quadrature_thickness);
  sync_double_kl(*kl);
  return kl;
}

void ShellObject::sync_double_kl(KirchhoffLoveShellT<double>& kl) const {
  if (!kl.has_plasticity()) return;
  const std::vector<Real>& fp = kl_->plastic_state();
  kl.set_plastic_state(std::vector<double>(fp.begin(), fp.end()));
}

std::vector<Vec3d> ShellObject::load_forces() const {
  std::vector<Vec3d> f;
  if (!has_loads()) return f;
  std::vector<Vec3d> at(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) at[i] = x[i].cast<double>();
  external_forces(Vec3d::Zero(), at, f);
  return f;
}

void ShellObject::external_forces(const Vec3d& gravity, const std::vector<Vec3d>& at,
                                  std::vector<Vec3d>& f) const {
  f.assign(at.size(), Vec3d::Zero());
  add_loads(desc_, tris_, mass, gravity, at, f, true);
}

StaticSolveResult ShellObject::settle(const Vec3d& gravity, double time, double tolerance,
                                      int max_iterations, bool serial) {
  const std::size_t n = x.size();
  StaticSolveOptions opt;
  opt.tolerance = tolerance;
  opt.max_iterations = max_iterations;
  const std::unique_ptr<KirchhoffLoveShellT<double>> kl_ptr = double_kl(&opt.coupling);
  const KirchhoffLoveShellT<double>& kl = *kl_ptr;
  // Pinned components at the pin pose at `time` (released pins are free).
  std::vector<Vec3d> xd(n);
  std::vector<std::uint8_t> free_mask(n, 7);
  for (std::size_t i = 0; i < n; ++i) {
    xd[i] = x[i].cast<double>();
    if (!pin_mask[i]) continue;
    const PinDesc& pin = desc_.pins[pin_of[i]];
    if (pin.release_time && time >= *pin.release_time) continue;
    const Vec3d target = keyframe_pose(pin.keyframes, time).apply(rest[i]);
    for (int a = 0; a < 3; ++a)
      if (pin_mask[i] & (1u << a)) {
        xd[i][a] = target[a];
        free_mask[i] &= static_cast<std::uint8_t>(~(1u << a));
      }
  }
  auto total_force = [&](const std::vector<Vec3d>& p, std::vector<Vec3d>& f) {
    kl.energy(p.data(), f.data(), serial, false);
    add_loads(desc_, tris_, mass, gravity, p, f, serial);
  };
  const StaticSolveResult r = solve_static(xd, free_mask, total_force, opt);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = xd[i].cast<Real>();
    v[i].setZero();
  }
  return r;
}

void ShellObject::pin_targets(double t, double dt, std::vector<std::uint8_t>& held,
                              std::vector<Vec3d>& target) const {
  held.assign(x.size(), 0);
  target.assign(x.size(), Vec3d::Zero());
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!pin_mask[i]) continue;
    const PinDesc& pin = desc_.pins[pin_of[i]];
    if (pin.release_time && t >= *pin.release_time) continue;
    held[i] = pin_mask[i];
    target[i] = keyframe_pose(pin.keyframes, t + dt).apply(rest[i]);
  }
}

double ShellObject::integrate(const std::vector<Vec3>& f, double t, double dt, bool serial) {
  const Real h = static_cast<Real>(dt);
  const Real damp = Real(1) / Real(1 + dt * mat_.damping);
  std::vector<RigidPose> poses(desc_.pins.size());
  std::vector<char> released(desc_.pins.size());
  for (std::size_t p = 0; p < poses.size(); ++p) {
    poses[p] = keyframe_pose(desc_.pins[p].keyframes, t + dt);
    released[p] = desc_.pins[p].release_time && t >= *desc_.pins[p].release_time;
  }
  return ordered_reduce_chunks(x.size(), 4096, serial, 0.0, [&](std::size_t b, std::size_t e) {
    double work = 0;  // the pins': their impulse on held components times the pin's velocity
    for (std::size_t i = b; i < e; ++i) {
      if (mass[i] > 0) v[i] = damp * (v[i] + (h / mass[i]) * f[i]);
      if (pin_mask[i] && !released[pin_of[i]]) {
        const Vec3 target = poses[pin_of[i]].apply(rest[i]).cast<Real>();
        for (int a = 0; a < 3; ++a)
          if (pin_mask[i] & (1u << a)) {
            const Real free = v[i][a];
            v[i][a] = (target[a] - x[i][a]) / h;
            work += static_cast<double>(mass[i]) * static_cast<double>(v[i][a] - free) *
                    static_cast<double>(v[i][a]);
          }
      }
      x[i] += h * v[i];
    }
    return work;
  });
}

double ShellObject::project_plasticity(bool serial) {
  if (!has_denting()) return 0.0;
  return static_cast<double>(kl_->project_plasticity(x.data(), serial));
}

double ShellObject::stable_dt(double cfl) const {
  return shell_stable_dt(mat_, min_edge_, cfl);
}

double shortest_edge(const ShellMesh& mesh) {
  double h = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e)
      h = std::min(h, (mesh.vertices[t[e]] - mesh.vertices[t[(e + 1) % 3]]).norm());
  return h;
}

double shell_stable_dt(const ShellMaterialDesc& mat, double min_edge, double cfl) {
  const double E = mat.youngs_modulus, nu = mat.poisson_ratio, rho = mat.density;
  const double c = std::sqrt(E / (rho * (1 - nu * nu)));     // membrane wave speed
  const double kappa = c * mat.thickness / std::sqrt(12.0);  // bending: omega = kappa k^2
  const double h = min_edge;
  // Loop-basis shells with lumped masses are stable up to about 0.3 h / c (measured on
  // a cantilever; 0.5 h / c diverges), so the shot's CFL is capped at 0.5 and scaled.
  const double k = 0.6 * std::min(cfl, 0.5);
  double dt = k * h / c;
  dt = std::min(dt, k * h * h / (4.0 * kappa));
  if (mat.stiffness_damping > 0) {
    // Central difference with damping ratio xi = beta omega / 2 at the highest frequency
    // omega = 2 / dt is stable for dt <= (2 / omega)(sqrt(1 + xi^2) - xi).
    const double xi = mat.stiffness_damping / dt;
    dt *= std::sqrt(1 + xi * xi) - xi;
  }
  return dt;
}

double ShellObject::kinetic_energy() const {
  double k = 0;
  for (std::size_t i = 0; i < x.size(); ++i) k += 0.5 * mass[i] * v[i].squaredNorm();
  return k;
}

}  // namespace shellmpm
