#include "io/shell_mesh_writer.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>
#include "sim/scene/scene_words.h"

#include "io/atomic_file.h"
#include "sim/core/check.h"
#include "sim/scene/output_axes.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the PLY and GLB writers copy little-endian memory as is");

namespace shellmpm {

MeshFormat parse_mesh_format(const std::string& name) {
  if (const std::optional<MeshFormat> f = enum_of_word<MeshFormat>(name)) return *f;
  throw std::invalid_argument("unknown mesh format '" + name + "' (expected ply, obj or glb)");
}

const char* mesh_format_extension(MeshFormat format) {
  // The scene-format words are string literals, so their data is null-terminated.
  for (const Word<MeshFormat>& w : EnumWords<MeshFormat>::table)
    if (w.value == format) return w.text.data();
  return "";
}

namespace {

/// Float data of one frame, as it goes into every format.
struct Attributes {
  std::vector<float> positions;       // 3 per vertex
  std::vector<float> normals;         // 3 per vertex, unit length (or zero)
  std::vector<float> uvs;             // 2 per vertex (origin bottom-left), empty if none
  std::vector<float> velocities;      // 3 per vertex [m/s], empty if none
  std::vector<std::int32_t> indices;  // 3 per triangle
};

/// The frame's float data in the simulation's axes (Y up); see to_file_axes.
Attributes gather(const MeshFrame& m) {
  const std::size_t n = m.num_vertices;
  Attributes a;
  a.positions.resize(3 * n);
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) a.positions[3 * v + k] = static_cast<float>(m.positions[v][k]);

  a.indices.resize(3 * m.num_triangles);
  for (std::size_t t = 0; t < m.num_triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const int i = m.triangles[t][k];
      SHELLMPM_CHECK(i >= 0 && static_cast<std::size_t>(i) < n,
                     "triangle " << t << " has vertex index " << i << ", num_vertices " << n);
      a.indices[3 * t + k] = i;
    }

  std::vector<Vec3d> normals(n, Vec3d::Zero());
  if (m.normals) {
    for (std::size_t v = 0; v < n; ++v) normals[v] = m.normals[v].template cast<double>();
  } else {
    // Area-weighted: the unnormalized face normal (twice the area) goes to each corner.
    for (std::size_t t = 0; t < m.num_triangles; ++t) {
      const Eigen::Vector3i& f = m.triangles[t];
      const Vec3d p0 = m.positions[f[0]].template cast<double>();
      const Vec3d fn = (m.positions[f[1]].template cast<double>() - p0)
                           .cross(m.positions[f[2]].template cast<double>() - p0);
      for (int k = 0; k < 3; ++k) normals[f[k]] += fn;
    }
  }
  a.normals.resize(3 * n);
  for (std::size_t v = 0; v < n; ++v) {
    const double len = normals[v].norm();
    const Vec3d u = len > 0 ? Vec3d(normals[v] / len) : Vec3d::Zero();
    for (int k = 0; k < 3; ++k) a.normals[3 * v + k] = static_cast<float>(u[k]);
  }

  if (m.uvs) {
    a.uvs.resize(2 * n);
    for (std::size_t v = 0; v < n; ++v)
      for (int k = 0; k < 2; ++k) a.uvs[2 * v + k] = static_cast<float>(m.uvs[v][k]);
  }
  if (m.velocities) {
    a.velocities.resize(3 * n);
    for (std::size_t v = 0; v < n; ++v)
      for (int k = 0; k < 3; ++k) a.velocities[3 * v + k] = static_cast<float>(m.velocities[v][k]);
  }
  return a;
}

/// Turns the vectors of `a` into the axes `up` (exact: a permutation and a sign).
void to_file_axes(Attributes& a, UpAxis up) {
  to_output_axes(a.positions.data(), a.positions.size() / 3, up);
  to_output_axes(a.normals.data(), a.normals.size() / 3, up);
  to_output_axes(a.velocities.data(), a.velocities.size() / 3, up);
}

template <class T>
void append_raw(std::string& out, const T* data, std::size_t count) {
  out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

void append_float(std::string& out, float x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);  // shortest round trip
  out.append(buf, r.ptr);
}

void append_int(std::string& out, long long x) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, r.ptr);
}

std::string format_double(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

/// The name on one line without spaces (OBJ "o", PLY comment).
std::string single_token(const std::string& name) {
  std::string s = name;
  for (char& c : s)
    if (static_cast<unsigned char>(c) <= ' ') c = '_';
  return s;
}

// ---------------------------------------------------------------------------- PLY

std::string encode_ply(const MeshFrame& m, const Attributes& a) {
  const std::size_t n = m.num_vertices, nt = m.num_triangles;
  const bool uv = !a.uvs.empty(), vel = !a.velocities.empty();
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment shellmpm shell mesh\n";
  if (!m.name.empty()) header += "comment name " + single_token(m.name) + "\n";
  header += "comment frame " + std::to_string(m.frame) + "\n";
  header += "comment time " + format_double(m.time) + "\n";
  if (mesh_file_up_axis(MeshFormat::Ply, m.up_axis) == UpAxis::Z) header += "comment up_axis z\n";
  header += "element vertex " + std::to_string(n) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uv) header += "property float s\nproperty float t\n";
  if (vel) header += "property float vx\nproperty float vy\nproperty float vz\n";
  header += "element face " + std::to_string(nt) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";

  const std::size_t stride = 6 + (uv ? 2 : 0) + (vel ? 3 : 0);
  std::string out;
  out.reserve(header.size() + n * stride * 4 + nt * 13);
  out += header;
  std::vector<float> record(n * stride);
  for (std::size_t v = 0; v < n; ++v) {
    float* r = &record[v * stride];
    std::memcpy(r, &a.positions[3 * v], 3 * sizeof(float));
    std::memcpy(r + 3, &a.normals[3 * v], 3 * sizeof(float));
    if (uv) std::memcpy(r + 6, &a.uvs[2 * v], 2 * sizeof(float));
    if (vel) std::memcpy(r + (uv ? 8 : 6), &a.velocities[3 * v], 3 * sizeof(float));
  }
  append_raw(out, record.data(), record.size());
  std::string faces(nt * 13, '\0');
  for (std::size_t t = 0; t < nt; ++t) {
    faces[13 * t] = 3;
    std::memcpy(&faces[13 * t + 1], &a.indices[3 * t], 3 * sizeof(std::int32_t));
  }
  out += faces;
  return out;
}

// ---------------------------------------------------------------------------- OBJ

std::string encode_obj(const MeshFrame& m, const Attributes& a) {
  const std::size_t n = m.num_vertices, nt = m.num_triangles;
  const bool uv = !a.uvs.empty();
  std::string out;
  out.reserve(n * (uv ? 100 : 75) + nt * 40 + 256);
  out += "# shellmpm shell mesh: one v, vn";
  out += uv ? ", vt" : "";
  out += " per vertex, in simulation order\n";
  out += "# frame " + std::to_string(m.frame) + " time " + format_double(m.time) + "\n";
  if (mesh_file_up_axis(MeshFormat::Obj, m.up_axis) == UpAxis::Z) out += "# up_axis z\n";
  if (!m.name.empty()) out += "o " + single_token(m.name) + "\n";
  const auto lines = [&](const char* tag, const std::vector<float>& values, int dim) {
    for (std::size_t v = 0; v < n; ++v) {
      out += tag;
      for (int k = 0; k < dim; ++k) {
        out += ' ';
        append_float(out, values[dim * v + k]);
      }
      out += '\n';
    }
  };
  lines("v", a.positions, 3);
  lines("vn", a.normals, 3);
  if (uv) lines("vt", a.uvs, 2);
  for (std::size_t t = 0; t < nt; ++t) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      const long long i = a.indices[3 * t + k] + 1LL;
      out += ' ';
      append_int(out, i);
      out += '/';
      if (uv) append_int(out, i);
      out += '/';
      append_int(out, i);
    }
    out += '\n';
  }
  return out;
}

// ---------------------------------------------------------------------------- GLB

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string json_float(float x) {
  std::string s;
  append_float(s, x);
  return s;
}

/// The BIN chunk: positions, normals, [uvs], [velocities], indices; every block is a
/// multiple of 4 bytes. `index_offset` gets where the indices start.
std::string glb_bin(const Attributes& a, std::size_t n, std::size_t nt, std::size_t& index_offset) {
  const bool uv = !a.uvs.empty(), vel = !a.velocities.empty();
  std::string bin;
  bin.reserve(n * (24 + (uv ? 8 : 0) + (vel ? 12 : 0)) + nt * 12);
  append_raw(bin, a.positions.data(), a.positions.size());
  append_raw(bin, a.normals.data(), a.normals.size());
  if (uv) {
    std::vector<float> flipped(a.uvs);
    for (std::size_t v = 0; v < n; ++v) flipped[2 * v + 1] = 1.0f - flipped[2 * v + 1];
    append_raw(bin, flipped.data(), flipped.size());
  }
  if (vel) append_raw(bin, a.velocities.data(), a.velocities.size());
  index_offset = bin.size();
  append_raw(bin, a.indices.data(), a.indices.size());
  return bin;
}

/// The bufferViews and accessors, one per attribute, in the BIN order; POSITION carries
/// its bounds.
std::string glb_views_and_accessors(const Attributes& a, std::size_t n, std::size_t nt,
                                    std::size_t index_offset) {
  const bool uv = !a.uvs.empty(), vel = !a.velocities.empty();
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = a.positions[k];
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], a.positions[3 * v + k]);
      hi[k] = std::max(hi[k], a.positions[3 * v + k]);
    }
  std::string views = "\"bufferViews\":[", accessors = "\"accessors\":[";
  std::size_t offset = 0;
  int view = 0;
  const auto add = [&](std::size_t bytes, int target, int component, std::size_t count,
                       const char* type, const std::string& extra) {
    if (view > 0) {
      views += ',';
      accessors += ',';
    }
    views += "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
             ",\"byteLength\":" + std::to_string(bytes) + ",\"target\":" + std::to_string(target) +
             "}";
    accessors += "{\"bufferView\":" + std::to_string(view) +
                 ",\"componentType\":" + std::to_string(component) +
                 ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"" + extra + "}";
    offset += bytes;
    ++view;
  };
  const std::string minmax = ",\"min\":[" + json_float(lo[0]) + "," + json_float(lo[1]) + "," +
                             json_float(lo[2]) + "],\"max\":[" + json_float(hi[0]) + "," +
                             json_float(hi[1]) + "," + json_float(hi[2]) + "]";
  constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
  constexpr int kFloat = 5126, kUnsignedInt = 5125;
  add(12 * n, kArrayBuffer, kFloat, n, "VEC3", minmax);
  add(12 * n, kArrayBuffer, kFloat, n, "VEC3", "");
  if (uv) add(8 * n, kArrayBuffer, kFloat, n, "VEC2", "");
  if (vel) add(12 * n, kArrayBuffer, kFloat, n, "VEC3", "");
  SHELLMPM_CHECK(offset == index_offset, "offset " << offset << " vs " << index_offset);
  add(12 * nt, kElementArrayBuffer, kUnsignedInt, 3 * nt, "SCALAR", "");
  return views + "]," + accessors + "]";
}

std::string encode_glb(const MeshFrame& m, const Attributes& a) {
  const std::size_t n = m.num_vertices, nt = m.num_triangles;
  const bool uv = !a.uvs.empty(), vel = !a.velocities.empty();
  std::size_t index_offset = 0;
  const std::string bin = glb_bin(a, n, nt, index_offset);

  const std::string name = json_string(m.name.empty() ? "shell" : m.name);
  std::string j = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"shellmpm\"},";
  j += "\"scene\":0,\"scenes\":[{\"nodes\":[0],\"extras\":{\"frame\":" + std::to_string(m.frame) +
       ",\"time\":" + format_double(m.time) + "}}],";
  j += "\"nodes\":[{\"name\":" + name + ",\"mesh\":0}],";
  j += "\"meshes\":[{\"name\":" + name + ",\"primitives\":[{\"attributes\":{";
  // Accessors in BIN order: POSITION, NORMAL, [TEXCOORD_0], [_VELOCITY], indices.
  int accessor = 2;
  j += "\"POSITION\":0,\"NORMAL\":1";
  if (uv) j += ",\"TEXCOORD_0\":" + std::to_string(accessor++);
  if (vel) j += ",\"_VELOCITY\":" + std::to_string(accessor++);
  j += "},\"indices\":" + std::to_string(accessor) + ",\"mode\":4}]}],";
  j += "\"buffers\":[{\"byteLength\":" + std::to_string(bin.size()) + "}],";
  j += glb_views_and_accessors(a, n, nt, index_offset) + "}";
  while (j.size() % 4) j += ' ';  // the JSON chunk is padded with spaces

  const auto u32 = [](std::string& out, std::uint32_t x) { append_raw(out, &x, 1); };
  std::string out;
  out.reserve(12 + 8 + j.size() + 8 + bin.size());
  u32(out, 0x46546C67u);  // "glTF"
  u32(out, 2);
  u32(out, static_cast<std::uint32_t>(12 + 8 + j.size() + 8 + bin.size()));
  u32(out, static_cast<std::uint32_t>(j.size()));
  u32(out, 0x4E4F534Au);  // "JSON"
  out += j;
  u32(out, static_cast<std::uint32_t>(bin.size()));
  u32(out, 0x004E4942u);  // "BIN\0"
  out += bin;
  return out;
}

}  // namespace

void write_shell_mesh(const std::string& path, const MeshFrame& mesh, MeshFormat format) {
  SHELLMPM_CHECK(mesh.num_vertices > 0 && mesh.positions, "num_vertices " << mesh.num_vertices);
  SHELLMPM_CHECK(mesh.num_triangles > 0 && mesh.triangles, "num_triangles " << mesh.num_triangles);
  SHELLMPM_CHECK(mesh.num_vertices <= 0x7fffffffu && 3 * mesh.num_triangles <= 0x7fffffffu,
                 "mesh too large: " << mesh.num_vertices << " vertices, " << mesh.num_triangles
                                    << " triangles");
  Attributes a = gather(mesh);
  to_file_axes(a, mesh_file_up_axis(format, mesh.up_axis));
  std::string bytes;
  switch (format) {
    case MeshFormat::Ply:
      bytes = encode_ply(mesh, a);
      break;
    case MeshFormat::Obj:
      bytes = encode_obj(mesh, a);
      break;
    case MeshFormat::Glb:
      bytes = encode_glb(mesh, a);
      break;
  }
  write_bytes_atomic(path, bytes.data(), bytes.size());
}

}  // namespace shellmpm
