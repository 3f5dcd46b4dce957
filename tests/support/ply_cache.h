// Readers for the caches `shellmpm run` writes, written for the tests from the PLY format
// itself (not the tool's own readers): shell meshes `{name}.####.ply` and particle caches
// `particles.####.ply`, both binary little-endian PLY.
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace shellmpm_test {

/// A triangle mesh in double precision.
struct TriMesh {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Vector3i> tri;
  /// Per-vertex velocities (`vx vy vz`) when the file has them, else empty.
  std::vector<Eigen::Vector3d> v;
  /// The vertex property names in file order.
  std::vector<std::string> vertex_properties;
};

/// A particle cache frame: positions [m], velocities [m/s] and stable ids.
struct ParticleFrame {
  std::vector<Eigen::Vector3d> x, v;
  std::vector<std::uint32_t> id;
  /// Floats in the file that were not finite (positions or velocities).
  std::size_t non_finite = 0;
};

namespace detail {

struct PlyProperty {
  std::string type, name;
  bool list = false;
  std::string count_type;  ///< list only
};
struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> props;
};

inline int ply_type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  throw std::runtime_error("PLY: unknown property type '" + t + "'");
}

/// Reads a scalar of PLY type `t` at `p` as double.
inline double ply_value(const std::string& t, const char* p) {
  if (t == "float" || t == "float32") {
    float f;
    std::memcpy(&f, p, 4);
    return f;
  }
  if (t == "double" || t == "float64") {
    double d;
    std::memcpy(&d, p, 8);
    return d;
  }
  if (t == "uchar" || t == "uint8") return static_cast<unsigned char>(*p);
  if (t == "char" || t == "int8") return static_cast<signed char>(*p);
  if (t == "int" || t == "int32") {
    std::int32_t i;
    std::memcpy(&i, p, 4);
    return i;
  }
  if (t == "uint" || t == "uint32") {
    std::uint32_t i;
    std::memcpy(&i, p, 4);
    return i;
  }
  if (t == "short" || t == "int16") {
    std::int16_t i;
    std::memcpy(&i, p, 2);
    return i;
  }
  if (t == "ushort" || t == "uint16") {
    std::uint16_t i;
    std::memcpy(&i, p, 2);
    return i;
  }
  throw std::runtime_error("PLY: unknown property type '" + t + "'");
}

struct PlyFile {
  std::vector<PlyElement> elements;
  std::string body;  ///< everything after end_header
};

inline PlyFile read_ply(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + path);
  std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const std::string end = "end_header\n";
  const auto at = data.find(end);
  if (data.rfind("ply\n", 0) != 0 || at == std::string::npos)
    throw std::runtime_error(path + ": not a PLY file");
  PlyFile ply;
  std::istringstream header(data.substr(0, at));
  std::string line;
  bool binary_le = false;
  while (std::getline(header, line)) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string fmt;
      ls >> fmt;
      binary_le = fmt == "binary_little_endian";
    } else if (word == "element") {
      PlyElement e;
      ls >> e.name >> e.count;
      ply.elements.push_back(e);
    } else if (word == "property") {
      if (ply.elements.empty()) throw std::runtime_error(path + ": property before element");
      PlyProperty p;
      ls >> p.type;
      if (p.type == "list") {
        p.list = true;
        ls >> p.count_type >> p.type;
      }
      ls >> p.name;
      ply.elements.back().props.push_back(p);
    }
  }
  if (!binary_le) throw std::runtime_error(path + ": not binary little-endian PLY");
  ply.body = data.substr(at + end.size());
  return ply;
}

}  // namespace detail

/// Reads a shell mesh frame: vertex positions, velocities when present, and triangles
/// (other properties skipped).
inline TriMesh read_mesh_ply(const std::string& path) {
  const detail::PlyFile ply = detail::read_ply(path);
  TriMesh m;
  bool has_v = false;
  for (const detail::PlyElement& e : ply.elements)
    if (e.name == "vertex")
      for (const detail::PlyProperty& p : e.props) {
        m.vertex_properties.push_back(p.name);
        has_v = has_v || p.name == "vx";
      }
  std::size_t off = 0;
  const std::string& b = ply.body;
  for (const detail::PlyElement& e : ply.elements) {
    for (std::size_t i = 0; i < e.count; ++i) {
      Eigen::Vector3d x(0, 0, 0), vel(0, 0, 0);
      for (const detail::PlyProperty& p : e.props) {
        if (p.list) {
          const int cs = detail::ply_type_size(p.count_type), vs = detail::ply_type_size(p.type);
          if (off + cs > b.size()) throw std::runtime_error(path + ": truncated");
          const int n = static_cast<int>(detail::ply_value(p.count_type, &b[off]));
          off += cs;
          if (off + std::size_t(n) * vs > b.size()) throw std::runtime_error(path + ": truncated");
          if (e.name == "face") {
            if (n != 3) throw std::runtime_error(path + ": a face that is not a triangle");
            Eigen::Vector3i t;
            for (int k = 0; k < 3; ++k)
              t[k] = static_cast<int>(detail::ply_value(p.type, &b[off + k * vs]));
            m.tri.push_back(t);
          }
          off += std::size_t(n) * vs;
        } else {
          const int s = detail::ply_type_size(p.type);
          if (off + s > b.size()) throw std::runtime_error(path + ": truncated");
          if (e.name == "vertex") {
            const double v = detail::ply_value(p.type, &b[off]);
            if (p.name == "x") x.x() = v;
            if (p.name == "y") x.y() = v;
            if (p.name == "z") x.z() = v;
            if (p.name == "vx") vel.x() = v;
            if (p.name == "vy") vel.y() = v;
            if (p.name == "vz") vel.z() = v;
          }
          off += s;
        }
      }
      if (e.name == "vertex") m.x.push_back(x);
      if (e.name == "vertex" && has_v) m.v.push_back(vel);
    }
  }
  return m;
}

/// Reads a particle cache frame (`x y z vx vy vz id`).
inline ParticleFrame read_particle_ply(const std::string& path) {
  const detail::PlyFile ply = detail::read_ply(path);
  ParticleFrame pf;
  std::size_t off = 0;
  const std::string& b = ply.body;
  for (const detail::PlyElement& e : ply.elements) {
    for (std::size_t i = 0; i < e.count; ++i) {
      double val[7] = {0, 0, 0, 0, 0, 0, 0};
      for (const detail::PlyProperty& p : e.props) {
        if (p.list) throw std::runtime_error(path + ": unexpected list property");
        const int s = detail::ply_type_size(p.type);
        if (off + s > b.size()) throw std::runtime_error(path + ": truncated");
        const double v = detail::ply_value(p.type, &b[off]);
        static const char* names[] = {"x", "y", "z", "vx", "vy", "vz", "id"};
        for (int k = 0; k < 7; ++k)
          if (p.name == names[k]) val[k] = v;
        off += s;
      }
      if (e.name != "vertex") continue;
      pf.x.emplace_back(val[0], val[1], val[2]);
      pf.v.emplace_back(val[3], val[4], val[5]);
      pf.id.push_back(static_cast<std::uint32_t>(val[6]));
      for (int k = 0; k < 6; ++k) pf.non_finite += !std::isfinite(val[k]);
    }
  }
  return pf;
}

/// Non-finite vertex coordinates of a mesh.
inline std::size_t non_finite(const TriMesh& m) {
  std::size_t n = 0;
  for (const Eigen::Vector3d& x : m.x) n += !x.allFinite();
  return n;
}

}  // namespace shellmpm_test
