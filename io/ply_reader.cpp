#include "io/ply_reader.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace shellmpm {
namespace {

int type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

/// The little-endian integer at p: an Unsigned one when is_unsigned, else a Signed one.
template <class Unsigned, class Signed>
long long read_integer(const char* p, bool is_unsigned) {
  if (is_unsigned) {
    Unsigned v;
    std::memcpy(&v, p, sizeof v);
    return static_cast<long long>(v);
  }
  Signed v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<long long>(v);
}

long long read_int(const char* p, const std::string& t) {
  switch (type_size(t)) {
    case 1:
      return read_integer<unsigned char, signed char>(p, t[0] == 'u');
    case 2:
      return read_integer<std::uint16_t, std::int16_t>(p, t[0] == 'u');
    default:
      return read_integer<std::uint32_t, std::int32_t>(p, t[0] == 'u');
  }
}

struct Property {
  std::string name, type;
  bool list = false;
  std::string count_type, item_type;
  int offset = 0;
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> props;
  int record = 0;  ///< fixed record size; 0 when it holds a list
};

/// An open PLY file past its header: the elements, and the bytes left to read.
struct PlyFile {
  std::string path;
  std::ifstream in;
  std::vector<Element> elems;
  long long remaining = 0;

  std::runtime_error fail(const std::string& msg) const {
    return std::runtime_error(path + ": " + msg);
  }
};

/// Reads the header into f.elems (with each fixed-size element's record layout).
void read_header(PlyFile& f) {
  std::string line;
  if (!std::getline(f.in, line) || line != "ply") throw f.fail("not a PLY file");
  bool binary_le = false, ended = false;
  while (std::getline(f.in, line)) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string fmt;
      ls >> fmt;
      binary_le = fmt == "binary_little_endian";
    } else if (word == "element") {
      Element e;
      ls >> e.name >> e.count;
      if (!ls || e.count < 0) throw f.fail("bad element line '" + line + "'");
      f.elems.push_back(e);
    } else if (word == "property") {
      if (f.elems.empty()) throw f.fail("property before any element");
      Property p;
      ls >> p.type;
      if (p.type == "list") {
        p.list = true;
        ls >> p.count_type >> p.item_type >> p.name;
        if (type_size(p.count_type) == 0 || type_size(p.item_type) == 0)
          throw f.fail("bad list property");
      } else {
        ls >> p.name;
        if (type_size(p.type) == 0) throw f.fail("unknown property type '" + p.type + "'");
      }
      f.elems.back().props.push_back(p);
    } else if (word == "end_header") {
      ended = true;
      break;
    } else if (word != "comment" && word != "obj_info" && !word.empty()) {
      throw f.fail("unexpected header line '" + line + "'");
    }
  }
  if (!ended) throw f.fail("truncated header (no end_header)");
  if (!binary_le) throw f.fail("only binary_little_endian PLY is read (as shellmpm writes it)");
  for (Element& e : f.elems) {
    int off = 0;
    for (Property& p : e.props) {
      p.offset = off;
      if (p.list) {
        off = -1;
        break;
      }
      off += type_size(p.type);
    }
    e.record = off < 0 ? 0 : off;
  }
  const std::streampos body = f.in.tellg();
  f.in.seekg(0, std::ios::end);
  const long long file_size = static_cast<long long>(f.in.tellg());
  f.in.seekg(body);
  f.remaining = file_size - static_cast<long long>(body);
}

/// The vertex element: float x, y, z (finite), and nx, ny, nz / s, t / vx, vy, vz when all
/// of a group are there.
void read_vertices(PlyFile& f, const Element& e, PlyMesh& mesh) {
  int ox = -1, oy = -1, oz = -1, onx = -1, ony = -1, onz = -1, os = -1, ot = -1;
  int ovx = -1, ovy = -1, ovz = -1;
  for (const Property& p : e.props) {
    if (p.list) throw f.fail("list property in the vertex element");
    const bool fl = p.type == "float" || p.type == "float32";
    if (!fl) continue;
    for (auto [name, offset] : {std::pair<const char*, int*>{"x", &ox},
                                {"y", &oy},
                                {"z", &oz},
                                {"nx", &onx},
                                {"ny", &ony},
                                {"nz", &onz},
                                {"s", &os},
                                {"t", &ot},
                                {"vx", &ovx},
                                {"vy", &ovy},
                                {"vz", &ovz}})
      if (p.name == name) *offset = p.offset;
  }
  if (ox < 0 || oy < 0 || oz < 0) throw f.fail("the vertex element has no float x, y, z");
  const long long bytes = e.count * e.record;
  if (bytes > f.remaining)
    throw f.fail("truncated: " + std::to_string(e.count) + " vertices need " +
                 std::to_string(bytes) + " bytes, the file has " + std::to_string(f.remaining) +
                 " left");
  std::vector<char> buf(static_cast<std::size_t>(bytes));
  f.in.read(buf.data(), bytes);
  if (!f.in) throw f.fail("read error in the vertex data");
  f.remaining -= bytes;
  const bool has_n = onx >= 0 && ony >= 0 && onz >= 0, has_uv = os >= 0 && ot >= 0;
  const bool has_v = ovx >= 0 && ovy >= 0 && ovz >= 0;
  mesh.positions.resize(static_cast<std::size_t>(e.count));
  if (has_n) mesh.normals.resize(static_cast<std::size_t>(e.count));
  if (has_uv) mesh.uvs.resize(static_cast<std::size_t>(e.count));
  if (has_v) mesh.velocities.resize(static_cast<std::size_t>(e.count));
  for (long long i = 0; i < e.count; ++i) {
    const char* r = buf.data() + i * e.record;
    float v[3];
    std::memcpy(&v[0], r + ox, 4);
    std::memcpy(&v[1], r + oy, 4);
    std::memcpy(&v[2], r + oz, 4);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw f.fail("vertex " + std::to_string(i) + " has a non-finite coordinate");
    mesh.positions[static_cast<std::size_t>(i)] = Vec3f(v[0], v[1], v[2]);
    if (has_n) {
      std::memcpy(&v[0], r + onx, 4);
      std::memcpy(&v[1], r + ony, 4);
      std::memcpy(&v[2], r + onz, 4);
      mesh.normals[static_cast<std::size_t>(i)] = Vec3f(v[0], v[1], v[2]);
    }
    if (has_uv) {
      std::memcpy(&v[0], r + os, 4);
      std::memcpy(&v[1], r + ot, 4);
      mesh.uvs[static_cast<std::size_t>(i)] = Eigen::Vector2f(v[0], v[1]);
    }
    if (has_v) {
      std::memcpy(&v[0], r + ovx, 4);
      std::memcpy(&v[1], r + ovy, 4);
      std::memcpy(&v[2], r + ovz, 4);
      mesh.velocities[static_cast<std::size_t>(i)] = Vec3f(v[0], v[1], v[2]);
    }
  }
}

/// The face element: one list per face, triangles only, indices within the vertices.
void read_faces(PlyFile& f, const Element& e, PlyMesh& mesh) {
  if (e.props.size() != 1 || !e.props[0].list) throw f.fail("the face element must be one list");
  const Property& p = e.props[0];
  const int cs = type_size(p.count_type), is = type_size(p.item_type);
  mesh.triangles.resize(static_cast<std::size_t>(e.count));
  char tmp[64];
  for (long long i = 0; i < e.count; ++i) {
    if (f.remaining < cs) throw f.fail("truncated in face " + std::to_string(i));
    f.in.read(tmp, cs);
    const long long n = read_int(tmp, p.count_type);
    if (n != 3)
      throw f.fail("face " + std::to_string(i) + " has " + std::to_string(n) +
                   " corners (need triangles)");
    if (f.remaining < cs + 3 * is) throw f.fail("truncated in face " + std::to_string(i));
    f.in.read(tmp, 3 * is);
    if (!f.in) throw f.fail("read error in face " + std::to_string(i));
    f.remaining -= cs + 3 * is;
    for (int k = 0; k < 3; ++k) {
      const long long idx = read_int(tmp + k * is, p.item_type);
      if (idx < 0 || idx >= static_cast<long long>(mesh.positions.size()))
        throw f.fail("face " + std::to_string(i) + " indexes vertex " + std::to_string(idx) +
                     " of " + std::to_string(mesh.positions.size()));
      mesh.triangles[static_cast<std::size_t>(i)][k] = static_cast<int>(idx);
    }
  }
}

}  // namespace

PlyMesh read_ply(const std::string& path) {
  PlyFile f;
  f.path = path;
  f.in.open(path, std::ios::binary);
  if (!f.in) throw f.fail(std::string("cannot open: ") + std::strerror(errno));
  read_header(f);
  PlyMesh mesh;
  for (const Element& e : f.elems) {
    if (e.name == "vertex") {
      read_vertices(f, e, mesh);
    } else if (e.name == "face") {
      read_faces(f, e, mesh);
    } else {
      if (e.record == 0) break;  // an unknown element with lists: nothing we need follows
      const long long bytes = e.count * e.record;
      if (bytes > f.remaining) throw f.fail("truncated in element '" + e.name + "'");
      f.in.seekg(bytes, std::ios::cur);
      f.remaining -= bytes;
    }
  }
  return mesh;
}

}  // namespace shellmpm
