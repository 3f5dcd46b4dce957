// The reference problems of the accuracy study (docs/accuracy.md). Each reference is
// computed from the scene as run, so a sweep that changes a parameter keeps its answer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "study/reference_problem.h"
#include "study/series.h"

namespace shellmpm {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

const ShellDesc& shell_named(const Scene& s, const std::string& name) {
  for (const ShellDesc& d : s.shells)
    if (d.name == name) return d;
  throw std::runtime_error(s.path + ": the study expects a shell '" + name + "'");
}

const ShellMaterialDesc& material_of(const Scene& s, const ShellDesc& d) {
  return s.shell_materials.at(d.material);
}

double lowest_y(const std::vector<Vec3d>& x) {
  double lo = INFINITY;
  for (const Vec3d& p : x) lo = std::min(lo, p.y());
  return lo;
}

/// The last component of a key path: "quadrature_inplane" of
/// "shell_materials[0].quadrature_inplane", for short labels.
std::string short_key(const std::string& key) {
  const std::size_t dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

/// A sweep over one integer key.
StudySweep int_sweep(const std::string& name, const std::string& key, std::vector<int> values,
                     const std::string& held) {
  StudySweep w;
  w.name = name;
  w.varied = key;
  w.held = held;
  for (int v : values)
    w.settings.push_back(
        {short_key(key) + "=" + std::to_string(v), {key + "=" + std::to_string(v)}, 0});
  return w;
}

/// A refinement of shot.dx alone (bulk problems: the particles follow the grid).
StudySweep dx_sweep(std::vector<double> values, const std::string& held) {
  StudySweep w;
  w.name = "grid spacing";
  w.varied = "shot.dx";
  w.held = held;
  w.refinement = true;
  for (double h : values) w.settings.push_back({"dx=" + num(h), {"shot.dx=" + num(h)}, h});
  return w;
}

StudySweep number_sweep(const std::string& name, const std::string& key, std::vector<double> values,
                        const std::string& held) {
  StudySweep w;
  w.name = name;
  w.varied = key;
  w.held = held;
  for (double v : values)
    w.settings.push_back({short_key(key) + "=" + num(v), {key + "=" + num(v)}, 0});
  return w;
}

// ---------------------------------------------------------------------------------------
// Shell bending, static.

ReferenceProblem plate() {
  ReferenceProblem p;
  p.name = "plate_simply_supported";
  p.title = "Simply supported square plate under uniform load (static)";
  p.quantity = "centre deflection";
  p.unit = "m";
  p.reference_source =
      "Timoshenko & Woinowsky-Krieger 1959, Table 8: w = 0.00406 q a^4 / D (nu = 0.3)";
  p.reference = [](const Scene& s) {
    const ShellDesc& d = shell_named(s, "plate");
    const ShellMaterialDesc& m = material_of(s, d);
    if (std::abs(m.poisson_ratio - 0.3) > 1e-12)
      throw std::runtime_error("plate reference holds for nu = 0.3 only");
    const double q = m.density * s.shot.gravity.norm() * m.thickness;
    const double D = m.youngs_modulus * std::pow(m.thickness, 3) / (12 * (1 - 0.09));
    return 0.00406 * q * std::pow(d.size[0], 4) / D;
  };
  // At the centre of the limit surface: the scene writes it refined once, so the centre is
  // an output vertex for any n (a control vertex for even n, the midpoint of the centre
  // quad's diagonal for odd n, where the lowest control vertex missed it by h / 2).
  p.measure = [](const RunFolder& r, const Scene& s) {
    const ShellDesc& d = shell_named(s, "plate");
    const Vec3d c = d.translate;
    double best = INFINITY, y = NAN;
    for (const Vec3d& x : r.shell_vertices("plate", r.last_frame())) {
      const double e = std::hypot(x.x() - c.x(), x.z() - c.z());
      if (e < best) best = e, y = x.y();
    }
    if (best > 1e-3 * d.size[0])
      throw std::runtime_error(r.dir() +
                               ": no output vertex at the plate's centre (refine the "
                               "written mesh: shells[0].output_refine)");
    return c.y() - y;
  };
  StudySweep res;
  res.name = "mesh resolution";
  res.varied = "shells[0].geometry.resolution (n x n quads)";
  res.held = "3 in-plane quadrature points, 3 through the thickness";
  res.refinement = true;
  for (int n : {8, 16, 32, 64}) {
    const std::string v = "[" + std::to_string(n) + ", " + std::to_string(n) + "]";
    res.settings.push_back(
        {"n=" + std::to_string(n), {"shells[0].geometry.resolution=" + v}, 0.2 / n});
  }
  p.sweeps.push_back(res);
  p.sweeps.push_back(int_sweep("in-plane quadrature", "shell_materials[0].quadrature_inplane",
                               {1, 3, 6, 7}, "n = 16, 3 layers"));
  p.sweeps.push_back(int_sweep("layers through the thickness",
                               "shell_materials[0].quadrature_thickness", {2, 3, 5},
                               "n = 16, 3 in-plane points"));
  return p;
}

/// The cantilever's mesh for n elements along the free length L = 0.2 (one row behind the
/// clamp; rows x = -h, 0, h pinned), as overrides.
StudySetting cantilever_mesh(int n) {
  const double L = 0.2, h = L / n;
  const int across = std::max(2, n / 4);
  return {"n=" + std::to_string(n),
          {"shells[0].geometry.size=[" + num(L + h) + ", 0.05]",
           "shells[0].geometry.resolution=[" + std::to_string(n + 1) + ", " +
               std::to_string(across) + "]",
           "shells[0].translate=[" + num(0.5 * (L + h) - h) + ", 0, 0]",
           "shells[0].pins[0].box.max=[" + num(h * (1 + 1e-6)) + ", 1, 1]"},
          h};
}

/// Free length of the cantilever scenes: the sheet minus the row behind the clamp.
double cantilever_length(const ShellDesc& d) {
  return d.size[0] - d.size[0] / d.resolution[0];
}

ReferenceProblem cantilever_static() {
  ReferenceProblem p;
  p.name = "cantilever_gravity";
  p.title = "Cantilevered strip under its own weight (static)";
  p.quantity = "tip deflection";
  p.unit = "m";
  p.reference_source = "Euler-Bernoulli: w = q L^4 / (8 E I) = 1.5 rho g L^4 / (E t^2) (nu = 0)";
  p.reference = [](const Scene& s) {
    const ShellDesc& d = shell_named(s, "strip");
    const ShellMaterialDesc& m = material_of(s, d);
    const double L = cantilever_length(d);
    return 1.5 * m.density * s.shot.gravity.norm() * std::pow(L, 4) /
           (m.youngs_modulus * m.thickness * m.thickness);
  };
  p.measure = [](const RunFolder& r, const Scene& s) {
    return shell_named(s, "strip").translate.y() -
           lowest_y(r.shell_vertices("strip", r.last_frame()));
  };
  StudySweep res;
  res.name = "mesh resolution";
  res.varied = "elements along the strip (size, translate and clamp follow)";
  res.held = "3 in-plane quadrature points, 3 through the thickness";
  res.refinement = true;
  for (int n : {8, 16, 32, 64}) res.settings.push_back(cantilever_mesh(n));
  p.sweeps.push_back(res);
  return p;
}

// ---------------------------------------------------------------------------------------
// Shell dynamics.

ReferenceProblem cantilever_vibration() {
  ReferenceProblem p;
  p.name = "cantilever_vibration";
  p.title = "First bending period of a cantilevered strip (explicit dynamics)";
  p.quantity = "period of the tip's oscillation";
  p.unit = "s";
  p.reference_source =
      "Euler-Bernoulli: f1 = 1.8751^2 sqrt(E I / (rho A L^4)) / (2 pi), period 1 / f1";
  p.reference = [](const Scene& s) {
    const ShellDesc& d = shell_named(s, "strip");
    const ShellMaterialDesc& m = material_of(s, d);
    const double L = cantilever_length(d);
    const double beta = 1.8751040687;
    const double omega =
        beta * beta * std::sqrt(m.youngs_modulus * m.thickness * m.thickness / (12 * m.density)) /
        (L * L);
    return 2 * kPi / omega;
  };
  p.measure = [](const RunFolder& r, const Scene&) {
    std::vector<double> t, y;
    for (int f = r.first_frame(); f <= r.last_frame(); ++f) {
      t.push_back(r.time(f));
      y.push_back(lowest_y(r.shell_vertices("strip", f)));
    }
    const auto T = oscillation_period(t, y);
    if (!T) throw std::runtime_error(r.dir() + ": the tip did not oscillate");
    return *T;
  };
  StudySweep res;
  res.name = "mesh resolution";
  res.varied = "elements along the strip (size, translate and clamp follow)";
  res.held = "CFL 0.3";
  res.refinement = true;
  for (int n : {8, 16, 32}) res.settings.push_back(cantilever_mesh(n));
  p.sweeps.push_back(res);
  p.sweeps.push_back(number_sweep("CFL number", "shot.cfl", {0.1, 0.3, 0.6, 0.9}, "n = 16"));
  // Explicit against implicit (backward Euler, docs/implicit.md) at growing steps: the
  // implicit step is bounded by the frame, so the largest one also samples at 100 fps.
  StudySweep integ;
  integ.name = "integrator";
  integ.varied = "shot.integrator, and the implicit step (shot.dt_max; fps 100 for 1/100 s)";
  integ.held = "n = 16";
  integ.settings.push_back({"explicit", {"shot.integrator=explicit"}, 0});
  integ.settings.push_back(
      {"implicit dt=1/1600", {"shot.integrator=implicit", "shot.dt_max=0.000625"}, 0});
  integ.settings.push_back({"implicit dt=1/400", {"shot.integrator=implicit"}, 0});
  integ.settings.push_back({"implicit dt=1/100",
                            {"shot.integrator=implicit", "shot.fps=100", "shot.frames=[1, 41]"},
                            0});
  p.sweeps.push_back(integ);
  return p;
}

// ---------------------------------------------------------------------------------------
// Frictional contact.

/// Acceleration of a shell's centroid down a slope inclined at th (descending along
/// (cos th, -sin th, 0)), fitted from t = 0.1 s to 0.4 s.
double slope_acceleration(const RunFolder& r, const std::string& shell, double th) {
  const Vec3d down(std::cos(th), -std::sin(th), 0);
  std::vector<double> t, s;
  for (int f = r.first_frame(); f <= r.last_frame(); ++f) {
    const double tf = r.time(f);
    if (tf < 0.1 - 1e-9 || tf > 0.4 + 1e-9) continue;
    Vec3d c = Vec3d::Zero();
    const std::vector<Vec3d> x = r.shell_vertices(shell, f);
    for (const Vec3d& p : x) c += p;
    t.push_back(tf);
    s.push_back((c / x.size()).dot(down));
  }
  return fit_acceleration(t, s);
}

/// The incline's sweeps: dx with the mesh spacing following it, the mesh/grid spacing
/// ratio, and contact samples; `extra` adds the shell_velocities sweep for shell on shell.
std::vector<StudySweep> incline_sweeps(bool on_sheet) {
  const int top = on_sheet ? 1 : 0;  // the sliding sheet's index
  const std::string res_key = "shells[" + std::to_string(top) + "].geometry.resolution";
  std::vector<StudySweep> out;
  StudySweep dx;
  dx.name = "grid spacing";
  dx.varied = on_sheet ? "shot.dx, with both meshes' spacing equal to dx"
                       : "shot.dx, with the sheet's mesh spacing equal to dx";
  dx.held = "contact samples 1, per-shell velocities";
  dx.refinement = true;
  for (double h : {0.04, 0.02, 0.01}) {
    const int n = static_cast<int>(std::lround(0.16 / h));
    StudySetting st{
        "dx=" + num(h),
        {"shot.dx=" + num(h), res_key + "=[" + std::to_string(n) + ", " + std::to_string(n) + "]"},
        h};
    if (on_sheet) {
      const int nb = static_cast<int>(std::lround(0.6 / h));
      st.overrides.push_back("shells[0].geometry.resolution=[" + std::to_string(nb) + ", " +
                             std::to_string(nb) + "]");
    }
    dx.settings.push_back(st);
  }
  out.push_back(dx);
  StudySweep ratio;
  ratio.name = "mesh / grid spacing";
  ratio.varied = "the sliding sheet's resolution (mesh spacing 2, 1, 0.5 dx)";
  ratio.held = "dx 0.02";
  for (int n : {4, 8, 16})
    ratio.settings.push_back({"h/dx=" + num(8.0 / n),
                              {res_key + "=[" + std::to_string(n) + ", " + std::to_string(n) + "]"},
                              0});
  out.push_back(ratio);
  out.push_back(int_sweep("contact samples", "shell_materials[0].contact_samples", {1, 3, 6},
                          "dx 0.02, mesh spacing dx"));
  if (on_sheet) {
    StudySweep v;
    v.name = "shell velocities";
    v.varied = "shot.shell_velocities";
    v.held = "dx 0.02, mesh spacing dx";
    for (const char* w : {"per_shell", "shared"})
      v.settings.push_back(
          {std::string("shell_velocities=") + w, {std::string("shot.shell_velocities=") + w}, 0});
    out.push_back(v);
  }
  return out;
}

ReferenceProblem incline_collider() {
  ReferenceProblem p;
  p.name = "incline_collider";
  p.title = "Cloth sliding on a 30-degree frictional plane (mu 0.3)";
  p.quantity = "acceleration down the slope";
  p.unit = "m/s^2";
  p.reference_source = "Coulomb: a = g (sin th - mu cos th)";
  p.reference = [](const Scene& s) {
    const ColliderDesc& c = s.colliders.at(0);
    const double th = std::acos(c.shape.normal.normalized().y());
    return s.shot.gravity.norm() * (std::sin(th) - c.friction * std::cos(th));
  };
  p.measure = [](const RunFolder& r, const Scene& s) {
    const double th = std::acos(s.colliders.at(0).shape.normal.normalized().y());
    return slope_acceleration(r, "sheet", th);
  };
  p.sweeps = incline_sweeps(false);
  return p;
}

ReferenceProblem incline_sheet() {
  ReferenceProblem p;
  p.name = "incline_sheet";
  p.title = "Cloth sliding on a pinned cloth inclined at 30 degrees (c_F 0.3)";
  p.quantity = "acceleration down the slope";
  p.unit = "m/s^2";
  p.reference_source = "Coulomb: a = g (sin th - c_F cos th)";
  auto angle = [](const Scene& s) { return -shell_named(s, "base").rotate_deg.z() * kPi / 180; };
  p.reference = [angle](const Scene& s) {
    const double th = angle(s);
    const double mu = material_of(s, shell_named(s, "sheet")).friction;
    return s.shot.gravity.norm() * (std::sin(th) - mu * std::cos(th));
  };
  p.measure = [angle](const RunFolder& r, const Scene& s) {
    return slope_acceleration(r, "sheet", angle(s));
  };
  p.sweeps = incline_sweeps(true);
  return p;
}

// ---------------------------------------------------------------------------------------
// Granular flow and elastic bulk.

ReferenceProblem sand_column() {
  ReferenceProblem p;
  p.name = "sand_column";
  p.title = "Collapse of a planar sand column, aspect ratio 1";
  p.quantity = "run-out from the back wall";
  p.unit = "m";
  p.reference_source = "Lube et al. 2005 (planar): (L_inf - L0) / L0 = 1.2 a for a < 1.8";
  p.needs_particles = true;
  p.reference = [](const Scene& s) {
    const ShapeDesc& b = s.sources.at(0).shape;
    const double wall = s.colliders.at(1).shape.point.x();
    const double L0 = b.max.x() - wall, H0 = b.max.y() - b.min.y();
    return L0 * (1 + 1.2 * H0 / L0);
  };
  auto front = [](const RunFolder& r, const Scene& s, int frame) {
    double x_max = -INFINITY;
    for (const Vec3d& x : r.particles(frame)) x_max = std::max(x_max, x.x());
    return x_max - s.colliders.at(1).shape.point.x();
  };
  p.measure = [front](const RunFolder& r, const Scene& s) { return front(r, s, r.last_frame()); };
  // The law is for the deposit at rest: a front still moving by more than 1% of L0 in the
  // last 0.1 s is no run-out (a pile that creeps on, as one did over a ground whose
  // friction the domain walls hid, would otherwise pass for a converged value).
  p.doubt = [front](const RunFolder& r, const Scene& s) -> std::string {
    int f0 = r.last_frame();
    while (f0 > r.first_frame() && r.time(r.last_frame()) - r.time(f0) < 0.1 - 1e-9) --f0;
    const double span = r.time(r.last_frame()) - r.time(f0);
    if (span <= 0) return "";
    const ShapeDesc& b = s.sources.at(0).shape;
    const double L0 = b.max.x() - s.colliders.at(1).shape.point.x();
    const double moved = front(r, s, r.last_frame()) - front(r, s, f0);
    if (std::abs(moved) <= 0.01 * L0) return "";
    char why[128];
    std::snprintf(why, sizeof why,
                  "the flow has not stopped: the front moved %.1f mm in the last %.3f s",
                  1000 * moved, span);
    return why;
  };
  p.sweeps.push_back(dx_sweep({0.02, 0.01, 0.005}, "8 particles per cell"));
  p.sweeps.push_back(
      number_sweep("particles per cell", "sources[0].particles_per_cell", {4, 8, 16}, "dx 0.01"));
  return p;
}

ReferenceProblem bar_impact() {
  ReferenceProblem p;
  p.name = "bar_impact";
  p.title = "Elastic bar hitting a rigid wall: contact time";
  p.quantity = "contact time";
  p.unit = "s";
  p.reference_source = "1-D wave theory: contact lasts 2 L / c, c = sqrt(E / rho) (nu = 0)";
  p.reference = [](const Scene& s) {
    const ShapeDesc& b = s.sources.at(0).shape;
    const MaterialDesc& m = s.materials.at(s.sources.at(0).material);
    return 2 * (b.max.x() - b.min.x()) / std::sqrt(m.youngs_modulus / m.density);
  };
  p.measure = [](const RunFolder& r, const Scene& s) {
    const double v0 = std::abs(s.sources.at(0).velocity.x());
    std::vector<double> t, v;
    for (const nlohmann::json& f : r.frames()) {
      t.push_back(f.at("time").get<double>());
      v.push_back(f.at("momentum").at(0).get<double>() / f.at("mass").get<double>());
    }
    const auto a = first_crossing(t, v, -0.5 * v0, true);
    const auto b = first_crossing(t, v, 0.5 * v0, true);
    if (!a || !b) throw std::runtime_error(r.dir() + ": the bar did not rebound");
    return 2 * (*b - *a);
  };
  p.sweeps.push_back(dx_sweep({0.02, 0.01, 0.005}, "8 particles per cell, APIC, CFL 0.3"));
  p.sweeps.push_back(number_sweep("particles per cell", "sources[0].particles_per_cell", {1, 8, 27},
                                  "dx 0.01, APIC, CFL 0.3"));
  StudySweep tr;
  tr.name = "transfer";
  tr.varied = "shot.transfer";
  tr.held = "dx 0.01, 8 particles per cell, CFL 0.3";
  for (const char* w : {"apic", "mls"})
    tr.settings.push_back({std::string("transfer=") + w, {std::string("shot.transfer=") + w}, 0});
  p.sweeps.push_back(tr);
  p.sweeps.push_back(number_sweep("CFL number", "shot.cfl", {0.1, 0.3, 0.6, 0.9},
                                  "dx 0.01, 8 particles per cell, APIC"));
  return p;
}

// ---------------------------------------------------------------------------------------
// Contact geometry.

ReferenceProblem drape_sphere() {
  ReferenceProblem p;
  p.name = "drape_sphere";
  p.title = "Cloth draped on a sphere: rest gap (negative: penetration)";
  p.quantity = "closest distance of the cloth to the sphere, minus t/2";
  p.unit = "m";
  p.reference_source = "exact contact: the mid-surface rests t/2 outside the sphere (gap 0)";
  p.relative_error = false;
  p.reference = [](const Scene&) { return 0.0; };
  p.measure = [](const RunFolder& r, const Scene& s) {
    const ShapeDesc& ball = s.colliders.at(0).shape;
    const ShellDesc& d = shell_named(s, "cloth");
    double closest = INFINITY;
    for (const Vec3d& x : r.shell_vertices("cloth", r.last_frame()))
      closest = std::min(closest, (x - ball.center).norm() - ball.radius);
    return closest - 0.5 * material_of(s, d).thickness;
  };
  StudySweep dx;
  dx.name = "grid spacing";
  dx.varied = "shot.dx, with the cloth's mesh spacing equal to dx";
  dx.held = "CFL 0.5, contact samples 1";
  dx.refinement = true;
  for (double h : {0.04, 0.02, 0.01}) {
    const int n = static_cast<int>(std::lround(0.3 / h));
    dx.settings.push_back(
        {"dx=" + num(h),
         {"shot.dx=" + num(h),
          "shells[0].geometry.resolution=[" + std::to_string(n) + ", " + std::to_string(n) + "]"},
         h});
  }
  p.sweeps.push_back(dx);
  return p;
}

/// n sheets of thickness t dropped on the ground settle to a pile n t tall (contact at the
/// real distance; the grid's stencils alone held each sheet cells above the one below).
ReferenceProblem stack_height() {
  ReferenceProblem p;
  p.name = "stack_height";
  p.title = "Four 2 mm sheets dropped on the ground: height of the pile";
  p.quantity = "the top sheet's upper surface over the ground";
  p.unit = "m";
  p.reference_source = "n sheets of thickness t stand n t tall";
  p.reference = [](const Scene& s) {
    double h = 0;
    for (const ShellDesc& d : s.shells) h += material_of(s, d).thickness;
    return h;
  };
  p.measure = [](const RunFolder& r, const Scene& s) {
    double top = -INFINITY;
    for (const ShellDesc& d : s.shells) {
      std::vector<double> y;
      for (const Vec3d& x : r.shell_vertices(d.name, r.last_frame()))
        if (std::hypot(x.x(), x.z()) < 0.06) y.push_back(x.y());
      if (y.empty()) continue;
      std::nth_element(y.begin(), y.begin() + std::ptrdiff_t(y.size() / 2), y.end());
      top = std::max(top, y[y.size() / 2] + 0.5 * material_of(s, d).thickness);
    }
    return top - s.colliders.at(0).shape.point.y();
  };
  StudySweep dx;
  dx.name = "grid spacing";
  dx.varied = "shot.dx, with the sheets' mesh spacing equal to dx";
  dx.held = "CFL 0.5, contact at the surfaces";
  dx.refinement = true;
  for (double h : {0.05, 0.025, 0.0125}) {
    const int n = static_cast<int>(std::lround(0.3 / h));
    std::vector<std::string> o = {"shot.dx=" + num(h)};
    for (int k = 0; k < 4; ++k)
      o.push_back("shells[" + std::to_string(k) + "].geometry.resolution=[" + std::to_string(n) +
                  ", " + std::to_string(n) + "]");
    dx.settings.push_back({"dx=" + num(h), o, h});
  }
  p.sweeps.push_back(dx);
  StudySweep at;
  at.name = "contact distance";
  at.varied = "shot.contact_at: surface (the bodies' surfaces) or stencil (the paper's)";
  at.held = "dx 0.025";
  for (const char* w : {"surface", "stencil"})
    at.settings.push_back({w, {std::string("shot.contact_at=") + w}, 0});
  p.sweeps.push_back(at);
  return p;
}

/// The quality presets (shot.quality, io/scene_quality.h) as one more sweep.
StudySweep quality_sweep() {
  StudySweep w;
  w.name = "quality preset";
  w.varied =
      "shot.quality (dx and sheet resolution relative to the scene; CFL, quadrature, contact "
      "samples, particles per cell)";
  w.held = "everything the preset does not set";
  for (const char* q : {"draft", "preview", "production", "final"})
    w.settings.push_back({std::string("quality=") + q, {std::string("shot.quality=") + q}, 0});
  return w;
}

}  // namespace

std::vector<ReferenceProblem> reference_problems() {
  std::vector<ReferenceProblem> all = {
      plate(),         cantilever_static(), cantilever_vibration(), incline_collider(),
      incline_sheet(), sand_column(),       bar_impact(),           drape_sphere(),
      stack_height()};
  // The cantilevers' clamp is built for each resolution (cantilever_mesh), which a preset's
  // scaled resolution would not follow: they have no preset sweep.
  for (ReferenceProblem& p : all)
    if (p.name.rfind("cantilever", 0) != 0) p.sweeps.push_back(quality_sweep());
  return all;
}

}  // namespace shellmpm
