#include "render/tessellate.h"

#include <cmath>
#include <stdexcept>

namespace shellmpm {
namespace {

void orthonormal_basis(const Vec3d& n, Vec3d& t1, Vec3d& t2) {
  t1 = (std::abs(n.x()) > 0.9 ? Vec3d(0, 1, 0) : Vec3d(1, 0, 0)).cross(n).normalized();
  t2 = n.cross(t1);
}

}  // namespace

RenderMesh tessellate_sphere(const Vec3d& c, double r, int segments) {
  RenderMesh m;
  const int rings = std::max(2, segments / 2);
  for (int j = 0; j <= rings; ++j) {
    const double th = M_PI * j / rings;
    for (int i = 0; i <= segments; ++i) {
      const double ph = 2.0 * M_PI * i / segments;
      const Vec3d n(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
      m.positions.push_back((c + r * n).cast<float>());
      m.normals.push_back(n.cast<float>());
    }
  }
  const int w = segments + 1;
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      const int a = j * w + i, b = a + 1, d = a + w, e = d + 1;
      if (j > 0) m.triangles.emplace_back(a, d, b);
      if (j < rings - 1) m.triangles.emplace_back(b, d, e);
    }
  return m;
}

RenderMesh tessellate_box(const Vec3d& lo, const Vec3d& hi) {
  RenderMesh m;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Vec3d n = Vec3d::Zero();
      n[axis] = side ? 1.0 : -1.0;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const int base = static_cast<int>(m.positions.size());
      for (int k = 0; k < 4; ++k) {
        Vec3d p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        p[v] = (k >= 2) ? hi[v] : lo[v];
        m.positions.push_back(p.cast<float>());
        m.normals.push_back(n.cast<float>());
      }
      // (u, v) is right-handed around +axis: counter-clockwise seen from +axis.
      if (side)
        m.triangles.emplace_back(base, base + 1, base + 2),
            m.triangles.emplace_back(base, base + 2, base + 3);
      else
        m.triangles.emplace_back(base, base + 2, base + 1),
            m.triangles.emplace_back(base, base + 3, base + 2);
    }
  return m;
}

RenderMesh tessellate_cylinder(const Vec3d& c, const Vec3d& axis, double r, double height,
                               int segments) {
  RenderMesh m;
  const Vec3d a = axis.normalized();
  Vec3d t1, t2;
  orthonormal_basis(a, t1, t2);
  const Vec3d bottom = c - 0.5 * height * a, top = c + 0.5 * height * a;
  // side
  for (int i = 0; i <= segments; ++i) {
    const double ph = 2.0 * M_PI * i / segments;
    const Vec3d n = std::cos(ph) * t1 + std::sin(ph) * t2;
    m.positions.push_back((bottom + r * n).cast<float>());
    m.normals.push_back(n.cast<float>());
    m.positions.push_back((top + r * n).cast<float>());
    m.normals.push_back(n.cast<float>());
  }
  for (int i = 0; i < segments; ++i) {
    const int b0 = 2 * i, t0 = b0 + 1, b1 = b0 + 2, tt1 = b0 + 3;
    m.triangles.emplace_back(b0, b1, tt1);
    m.triangles.emplace_back(b0, tt1, t0);
  }
  // caps
  for (int cap = 0; cap < 2; ++cap) {
    const Vec3d n = cap ? a : Vec3d(-a);
    const Vec3d o = cap ? top : bottom;
    const int center = static_cast<int>(m.positions.size());
    m.positions.push_back(o.cast<float>());
    m.normals.push_back(n.cast<float>());
    for (int i = 0; i <= segments; ++i) {
      const double ph = 2.0 * M_PI * i / segments;
      m.positions.push_back((o + r * (std::cos(ph) * t1 + std::sin(ph) * t2)).cast<float>());
      m.normals.push_back(n.cast<float>());
    }
    for (int i = 0; i < segments; ++i) {
      if (cap)
        m.triangles.emplace_back(center, center + 1 + i, center + 2 + i);
      else
        m.triangles.emplace_back(center, center + 2 + i, center + 1 + i);
    }
  }
  return m;
}

RenderMesh tessellate_square(const Vec3d& center, const Vec3d& normal, double half, int n) {
  RenderMesh m;
  const Vec3d nn = normal.normalized();
  Vec3d t1, t2;
  orthonormal_basis(nn, t1, t2);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double u = -half + 2.0 * half * i / n, v = -half + 2.0 * half * j / n;
      m.positions.push_back((center + u * t1 + v * t2).cast<float>());
      m.normals.push_back(nn.cast<float>());
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, d = a + n + 1, e = d + 1;
      // t1 x t2 = n: (a, b, e) is counter-clockwise seen from +n.
      m.triangles.emplace_back(a, b, e);
      m.triangles.emplace_back(a, e, d);
    }
  return m;
}

RenderMesh tessellate_shape(const ShapeDesc& s) {
  switch (s.kind) {
    case ShapeDesc::Kind::Sphere:
      return tessellate_sphere(s.center, s.radius);
    case ShapeDesc::Kind::Box:
      return tessellate_box(s.min, s.max);
    case ShapeDesc::Kind::Cylinder:
      return tessellate_cylinder(s.center, s.axis, s.radius, s.height);
    default:
      throw std::invalid_argument("tessellate_shape: planes and meshes are not analytic solids");
  }
}

std::vector<Vec3f> vertex_normals(const std::vector<Vec3f>& p,
                                  const std::vector<Eigen::Vector3i>& tris) {
  std::vector<Vec3f> n(p.size(), Vec3f::Zero());
  for (const Eigen::Vector3i& t : tris) {
    const Vec3f a = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
    for (int k = 0; k < 3; ++k) n[t[k]] += a;
  }
  for (Vec3f& v : n) {
    const float l = v.norm();
    v = l > 0.0f ? Vec3f(v / l) : Vec3f(0, 1, 0);
  }
  return n;
}

}  // namespace shellmpm
