// Shell mesh caches (io/shell_mesh_writer) and shell mesh import with vertex groups
// (io/shell_mesh_reader).
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "io/ply_reader.h"
#include "io/shell_mesh_reader.h"
#include "io/shell_mesh_writer.h"
#include "io/user_error.h"
#include "sim/core/check.h"
#include "tests/support/ply_cache.h"
#include "tests/support/temp_dir.h"

namespace fs = std::filesystem;
using namespace shellmpm;
using shellmpm_test::TempDir;

namespace {

/// An nx-by-ny vertex grid in the xy plane (normal +z), with UVs. Vertex numbers are
/// scrambled (a fixed permutation) so that face-traversal order differs from index
/// order: a writer that renumbers vertices by first use cannot pass.
struct Grid {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // tilted, not unit length: the writer normalizes
  std::vector<Eigen::Vector2d> uvs;
  std::vector<Eigen::Vector3i> triangles;

  Grid(int nx, int ny) {
    const int n = nx * ny;
    std::vector<int> id(n);
    for (int i = 0; i < n; ++i) id[i] = static_cast<int>((static_cast<long long>(i) * 7919) % n);
    REQUIRE(std::set<int>(id.begin(), id.end()).size() == static_cast<std::size_t>(n));
    positions.resize(n);
    normals.resize(n);
    uvs.resize(n);
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j) {
        const int v = id[i * ny + j];
        positions[v] = Vec3(Real(0.1) * i, Real(0.05) * j, Real(0.01) * i * j);
        normals[v] = Vec3(Real(0.1) * i, Real(-0.2) * j, Real(2));
        uvs[v] = Eigen::Vector2d(double(i) / (nx - 1), double(j) / (ny - 1));
      }
    for (int i = 0; i + 1 < nx; ++i)
      for (int j = 0; j + 1 < ny; ++j) {
        const int a = id[i * ny + j], b = id[(i + 1) * ny + j], c = id[(i + 1) * ny + j + 1],
                  d = id[i * ny + j + 1];
        triangles.emplace_back(a, b, c);
        triangles.emplace_back(a, c, d);
      }
  }

  MeshFrame frame(bool with_normals, bool with_uvs) const {
    MeshFrame f;
    f.positions = positions.data();
    f.num_vertices = positions.size();
    f.normals = with_normals ? normals.data() : nullptr;
    f.uvs = with_uvs ? uvs.data() : nullptr;
    f.triangles = triangles.data();
    f.num_triangles = triangles.size();
    f.frame = 7;
    f.time = 0.28;
    f.name = "cloth";
    return f;
  }
};

/// The expected (normalized) normal of vertex v: given, or +z-ish for the computed case.
Vec3d expected_normal(const Grid& g, bool given, std::size_t v) {
  if (given) return g.normals[v].cast<double>().normalized();
  // Area-weighted normal of the neighbouring triangles, computed independently.
  Vec3d n = Vec3d::Zero();
  for (const auto& t : g.triangles)
    for (int k = 0; k < 3; ++k)
      if (static_cast<std::size_t>(t[k]) == v) {
        const Vec3d p0 = g.positions[t[0]].cast<double>();
        n += (g.positions[t[1]].cast<double>() - p0).cross(g.positions[t[2]].cast<double>() - p0);
      }
  return n.normalized();
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// Reads `path` with assimp without joining vertices (the file's vertices as stored).
const aiScene* read_raw(Assimp::Importer& importer, const std::string& path) {
  const aiScene* s = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  INFO(importer.GetErrorString());
  REQUIRE(s != nullptr);
  REQUIRE(s->mNumMeshes == 1);
  return s;
}

/// PLY and GLB store indexed vertices: check count, order, normals, UVs, triangles.
void check_indexed_readback(const std::string& path, const Grid& g, bool normals, bool uvs) {
  Assimp::Importer importer;
  const aiScene* s = read_raw(importer, path);
  const aiMesh* m = s->mMeshes[0];
  REQUIRE(m->mNumVertices == g.positions.size());
  REQUIRE(m->HasNormals());
  REQUIRE(m->HasTextureCoords(0) == uvs);
  for (std::size_t v = 0; v < g.positions.size(); ++v) {
    INFO("vertex " << v);
    const aiVector3D& p = m->mVertices[v];
    REQUIRE(p.x == static_cast<float>(g.positions[v].x()));  // exact: float stored as float
    REQUIRE(p.y == static_cast<float>(g.positions[v].y()));
    REQUIRE(p.z == static_cast<float>(g.positions[v].z()));
    const Vec3d n = expected_normal(g, normals, v);
    REQUIRE(m->mNormals[v].x == Approx(n.x()).margin(1e-6));
    REQUIRE(m->mNormals[v].y == Approx(n.y()).margin(1e-6));
    REQUIRE(m->mNormals[v].z == Approx(n.z()).margin(1e-6));
    if (uvs) {
      REQUIRE(m->mTextureCoords[0][v].x == Approx(g.uvs[v].x()).margin(1e-6));
      REQUIRE(m->mTextureCoords[0][v].y == Approx(g.uvs[v].y()).margin(1e-6));
    }
  }
  REQUIRE(m->mNumFaces == g.triangles.size());
  for (std::size_t t = 0; t < g.triangles.size(); ++t) {
    REQUIRE(m->mFaces[t].mNumIndices == 3);
    for (int k = 0; k < 3; ++k)
      REQUIRE(static_cast<int>(m->mFaces[t].mIndices[k]) == g.triangles[t][k]);
  }
}

}  // namespace

TEST_CASE("parse_mesh_format accepts ply, obj, glb only", "[shellmesh]") {
  CHECK(parse_mesh_format("ply") == MeshFormat::Ply);
  CHECK(parse_mesh_format("obj") == MeshFormat::Obj);
  CHECK(parse_mesh_format("glb") == MeshFormat::Glb);
  CHECK_THROWS_AS(parse_mesh_format("fbx"), std::invalid_argument);
  CHECK_THROWS_AS(parse_mesh_format("PLY"), std::invalid_argument);
  CHECK_THROWS_AS(parse_mesh_format(""), std::invalid_argument);
  CHECK(std::string(mesh_format_extension(MeshFormat::Glb)) == "glb");
}

TEST_CASE("binary PLY and GLB keep vertex count and order, normals, UVs, triangles",
          "[shellmesh]") {
  TempDir dir("shellmesh_indexed");
  const Grid g(3, 3);
  for (const MeshFormat format : {MeshFormat::Ply, MeshFormat::Glb})
    for (const bool normals : {true, false})
      for (const bool uvs : {true, false}) {
        const std::string path = dir.file(std::string("shell.") + (normals ? "n" : "") +
                                          (uvs ? "uv" : "") + "." + mesh_format_extension(format));
        INFO(path);
        write_shell_mesh(path, g.frame(normals, uvs), format);
        check_indexed_readback(path, g, normals, uvs);
      }
  CHECK(dir.temp_files() == 0);
}

TEST_CASE("PLY and GLB files are complete and carry frame and time", "[shellmesh]") {
  TempDir dir("shellmesh_complete");
  const Grid g(4, 3);
  const std::size_t n = g.positions.size(), nt = g.triangles.size();

  const std::string ply = dir.file("shell.0007.ply");
  write_shell_mesh(ply, g.frame(false, true), MeshFormat::Ply);
  write_shell_mesh(ply, g.frame(true, true), MeshFormat::Ply);  // overwrite in place
  const std::string pb = file_bytes(ply);
  const auto header_end = pb.find("end_header\n");
  REQUIRE(header_end != std::string::npos);
  const std::string header = pb.substr(0, header_end);
  CHECK(contains(header, "format binary_little_endian 1.0"));
  CHECK(contains(header, "comment frame 7\n"));
  CHECK(contains(header, "comment time 0.28"));
  CHECK(contains(header, "property float s\nproperty float t\n"));
  CHECK(pb.size() == header_end + 11 + n * 8 * 4 + nt * 13);

  const std::string glb = dir.file("shell.0007.glb");
  write_shell_mesh(glb, g.frame(true, true), MeshFormat::Glb);
  const std::string gb = file_bytes(glb);
  REQUIRE(gb.size() > 20);
  std::uint32_t magic = 0, total = 0, json_len = 0;
  std::memcpy(&magic, gb.data(), 4);
  std::memcpy(&total, gb.data() + 8, 4);
  std::memcpy(&json_len, gb.data() + 12, 4);
  CHECK(magic == 0x46546C67u);
  CHECK(total == gb.size());
  const std::string json = gb.substr(20, json_len);
  CHECK(contains(json, "\"extras\":{\"frame\":7,\"time\":0.28"));
  CHECK(contains(json, "\"name\":\"cloth\""));
  CHECK(gb.size() == 20 + json_len + 8 + n * (12 + 12 + 8) + nt * 12);

  CHECK(dir.temp_files() == 0);
}

namespace {

/// Distinct per-vertex velocities [m/s] for a grid (so a writer that drops, reorders or
/// shifts them cannot pass).
std::vector<Vec3> grid_velocities(const Grid& g) {
  std::vector<Vec3> v(g.positions.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = Vec3(Real(0.5) + Real(0.25) * i, Real(-2) * i, Real(1e-3) * i * i - Real(3));
  return v;
}

/// The JSON chunk of a GLB file.
nlohmann::json glb_json(const std::string& bytes) {
  REQUIRE(bytes.size() > 20);
  std::uint32_t json_len = 0;
  std::memcpy(&json_len, bytes.data() + 12, 4);
  REQUIRE(20 + json_len <= bytes.size());
  return nlohmann::json::parse(bytes.substr(20, json_len));
}

/// The floats of accessor `a` of a GLB file (tightly packed, as the writer stores them).
std::vector<float> glb_floats(const std::string& bytes, const nlohmann::json& j, int a) {
  const nlohmann::json& acc = j["accessors"][a];
  const nlohmann::json& view = j["bufferViews"][acc["bufferView"].get<int>()];
  std::uint32_t json_len = 0;
  std::memcpy(&json_len, bytes.data() + 12, 4);
  const std::size_t bin = 20 + json_len + 8;
  const std::size_t off = bin + view["byteOffset"].get<std::size_t>();
  const std::size_t len = view["byteLength"].get<std::size_t>();
  REQUIRE(off + len <= bytes.size());
  std::vector<float> f(len / 4);
  std::memcpy(f.data(), bytes.data() + off, len);
  return f;
}

}  // namespace

TEST_CASE("PLY and GLB carry per-vertex velocities in vertex order, none when not given",
          "[shellmesh][velocity]") {
  TempDir dir("shellmesh_velocity");
  const Grid g(5, 4);
  const std::size_t n = g.positions.size(), nt = g.triangles.size();
  const std::vector<Vec3> vel = grid_velocities(g);
  for (const bool uvs : {true, false}) {
    INFO("uvs " << uvs);
    MeshFrame f = g.frame(true, uvs);
    f.velocities = vel.data();

    // PLY: float vx vy vz after the other vertex properties, exact float values.
    const std::string ply = dir.file(std::string("v") + (uvs ? "uv" : "") + ".ply");
    write_shell_mesh(ply, f, MeshFormat::Ply);
    const std::string pb = file_bytes(ply);
    const std::string header = pb.substr(0, pb.find("end_header\n"));
    CHECK(contains(header, "property float vx\nproperty float vy\nproperty float vz\n"));
    CHECK(pb.size() == header.size() + 11 + n * (uvs ? 11 : 9) * 4 + nt * 13);
    const shellmpm_test::TriMesh m = shellmpm_test::read_mesh_ply(ply);
    REQUIRE(m.v.size() == n);
    REQUIRE(m.x.size() == n);
    for (std::size_t v = 0; v < n; ++v) {
      INFO("vertex " << v);
      for (int k = 0; k < 3; ++k) {
        REQUIRE(m.v[v][k] == static_cast<float>(vel[v][k]));
        REQUIRE(m.x[v][k] == static_cast<float>(g.positions[v][k]));
      }
    }
    // Extra properties break neither assimp nor the preview renderer's reader.
    check_indexed_readback(ply, g, true, uvs);
    const PlyMesh rp = read_ply(ply);
    REQUIRE(rp.positions.size() == n);
    REQUIRE(rp.normals.size() == n);
    REQUIRE(rp.triangles.size() == nt);
    for (std::size_t v = 0; v < n; ++v) {
      INFO("vertex " << v);
      REQUIRE(rp.positions[v] == g.positions[v].cast<float>());
      REQUIRE(rp.normals[v].x() == Approx(expected_normal(g, true, v).x()).margin(1e-6));
    }
    for (std::size_t t = 0; t < nt; ++t) REQUIRE(rp.triangles[t] == g.triangles[t]);

    // GLB: a VEC3 float accessor _VELOCITY with one element per vertex, the indices last.
    const std::string glb = dir.file(std::string("v") + (uvs ? "uv" : "") + ".glb");
    write_shell_mesh(glb, f, MeshFormat::Glb);
    const std::string gb = file_bytes(glb);
    const nlohmann::json j = glb_json(gb);
    const nlohmann::json& attrs = j["meshes"][0]["primitives"][0]["attributes"];
    REQUIRE(attrs.contains("_VELOCITY"));
    CHECK(attrs.contains("TEXCOORD_0") == uvs);
    const int va = attrs["_VELOCITY"].get<int>();
    const nlohmann::json& acc = j["accessors"][va];
    CHECK(acc["count"].get<std::size_t>() == n);
    CHECK(acc["type"] == "VEC3");
    CHECK(acc["componentType"] == 5126);
    const std::vector<float> gv = glb_floats(gb, j, va);
    REQUIRE(gv.size() == 3 * n);
    for (std::size_t v = 0; v < n; ++v)
      for (int k = 0; k < 3; ++k) REQUIRE(gv[3 * v + k] == static_cast<float>(vel[v][k]));
    const int ia = j["meshes"][0]["primitives"][0]["indices"].get<int>();
    CHECK(j["accessors"][ia]["count"].get<std::size_t>() == 3 * nt);
    CHECK(j["accessors"].size() == (uvs ? 5u : 4u));
    std::uint32_t json_len = 0;
    std::memcpy(&json_len, gb.data() + 12, 4);
    CHECK(gb.size() == 20 + json_len + 8 + n * (12 + 12 + (uvs ? 8 : 0) + 12) + nt * 12);
    check_indexed_readback(glb, g, true, uvs);  // assimp skips the custom attribute

    // OBJ has no per-vertex attributes: the same file with or without velocities.
    const std::string obj_v = dir.file("v.obj"), obj = dir.file("plain.obj");
    write_shell_mesh(obj_v, f, MeshFormat::Obj);
    write_shell_mesh(obj, g.frame(true, uvs), MeshFormat::Obj);
    CHECK(file_bytes(obj_v) == file_bytes(obj));
  }

  // Without velocities: no vx property, no _VELOCITY attribute.
  const std::string ply = dir.file("plain.ply"), glb = dir.file("plain.glb");
  write_shell_mesh(ply, g.frame(true, true), MeshFormat::Ply);
  write_shell_mesh(glb, g.frame(true, true), MeshFormat::Glb);
  const shellmpm_test::TriMesh m = shellmpm_test::read_mesh_ply(ply);
  CHECK(m.v.empty());
  CHECK(std::find(m.vertex_properties.begin(), m.vertex_properties.end(), "vx") ==
        m.vertex_properties.end());
  const nlohmann::json j = glb_json(file_bytes(glb));
  CHECK_FALSE(j["meshes"][0]["primitives"][0]["attributes"].contains("_VELOCITY"));
  CHECK(dir.temp_files() == 0);
}

TEST_CASE("OBJ keeps vertex count and order: one v/vn/vt per vertex, faces i/i/i", "[shellmesh]") {
  TempDir dir("shellmesh_obj");
  const Grid g(3, 3);
  for (const bool uvs : {true, false}) {
    const std::string path = dir.file(uvs ? "uv.obj" : "plain.obj");
    INFO(path);
    write_shell_mesh(path, g.frame(true, uvs), MeshFormat::Obj);

    // The file itself: v, vn, vt in vertex order, faces with the given indices.
    std::istringstream in(file_bytes(path));
    std::vector<Eigen::Vector3d> v, vn;
    std::vector<Eigen::Vector2d> vt;
    std::vector<std::string> faces;
    std::string line;
    bool has_o = false;
    while (std::getline(in, line)) {
      std::istringstream ls(line);
      std::string tag;
      ls >> tag;
      double a = 0, b = 0, c = 0;
      if (tag == "v" && ls >> a >> b >> c) v.emplace_back(a, b, c);
      if (tag == "vn" && ls >> a >> b >> c) vn.emplace_back(a, b, c);
      if (tag == "vt" && ls >> a >> b) vt.emplace_back(a, b);
      if (tag == "f") faces.push_back(line);
      if (tag == "o") has_o = line == "o cloth";
    }
    CHECK(has_o);
    REQUIRE(v.size() == g.positions.size());
    REQUIRE(vn.size() == g.positions.size());
    REQUIRE(vt.size() == (uvs ? g.positions.size() : 0));
    for (std::size_t i = 0; i < v.size(); ++i) {
      INFO("vertex " << i);
      // Shortest round-trip text: the float parses back to the same float.
      CHECK(static_cast<float>(v[i].x()) == static_cast<float>(g.positions[i].x()));
      CHECK(static_cast<float>(v[i].y()) == static_cast<float>(g.positions[i].y()));
      CHECK(static_cast<float>(v[i].z()) == static_cast<float>(g.positions[i].z()));
      CHECK((vn[i] - expected_normal(g, true, i)).norm() < 1e-6);
      if (uvs) CHECK((vt[i] - g.uvs[i]).norm() < 1e-6);
    }
    REQUIRE(faces.size() == g.triangles.size());
    for (std::size_t t = 0; t < faces.size(); ++t) {
      std::string expect = "f";
      for (int k = 0; k < 3; ++k) {
        const std::string i = std::to_string(g.triangles[t][k] + 1);
        expect += " " + i + "/" + (uvs ? i : "") + "/" + i;
      }
      CHECK(faces[t] == expect);
    }

    // assimp's reading (without joining: one vertex per face corner) agrees.
    Assimp::Importer importer;
    const aiScene* s = read_raw(importer, path);
    const aiMesh* m = s->mMeshes[0];
    REQUIRE(m->mNumFaces == g.triangles.size());
    REQUIRE(m->HasTextureCoords(0) == uvs);
    for (std::size_t t = 0; t < g.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const unsigned c = m->mFaces[t].mIndices[k];
        const int want = g.triangles[t][k];
        CHECK(m->mVertices[c].x == static_cast<float>(g.positions[want].x()));
        CHECK(m->mVertices[c].y == static_cast<float>(g.positions[want].y()));
        CHECK(m->mVertices[c].z == static_cast<float>(g.positions[want].z()));
        CHECK(m->mNormals[c].z == Approx(expected_normal(g, true, want).z()).margin(1e-6));
        if (uvs) CHECK(m->mTextureCoords[0][c].y == Approx(g.uvs[want].y()).margin(1e-6));
      }
  }
  CHECK(dir.temp_files() == 0);
}

TEST_CASE("read_shell_mesh turns OBJ o/g names into vertex groups", "[shellmesh]") {
  TempDir dir("shellmesh_groups");
  // Two quads sharing the edge x = 1; a third face group "pin" on one triangle.
  const std::string path = dir.write("strip.obj",
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                                     "o strip\n"
                                     "g left\nf 1 2 3 4\n"
                                     "g right\nf 2 5 6 3\n"
                                     "g left\n");
  const ShellMesh m = read_shell_mesh(path, "scene.yaml:3: shells[0].mesh");
  REQUIRE(m.vertices.size() == 6);  // the shared edge is one set of control points
  REQUIRE(m.triangles.size() == 4);
  CHECK(m.groups.count("defaultobject") == 0);
  CHECK(m.groups.count("strip.obj") == 0);
  REQUIRE(m.groups.count("left") == 1);
  REQUIRE(m.groups.count("right") == 1);
  const auto positions_of = [&](const std::vector<int>& g) {
    std::set<std::pair<double, double>> s;
    for (int i : g) s.emplace(m.vertices[i].x(), m.vertices[i].y());
    return s;
  };
  const std::vector<int>& left = m.groups.at("left");
  CHECK(std::is_sorted(left.begin(), left.end()));
  CHECK(positions_of(left) == std::set<std::pair<double, double>>{{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  CHECK(positions_of(m.groups.at("right")) ==
        std::set<std::pair<double, double>>{{1, 0}, {2, 0}, {2, 1}, {1, 1}});
  // Shared edge vertices are the same control points in both groups.
  std::vector<int> shared;
  std::set_intersection(left.begin(), left.end(), m.groups.at("right").begin(),
                        m.groups.at("right").end(), std::back_inserter(shared));
  CHECK(shared.size() == 2);

  // Faces before any o/g are no group; an `o` name is one.
  const std::string path2 = dir.write("mixed.obj",
                                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                      "f 1 2 3\no hem\nf 1 3 4\n");
  const ShellMesh m2 = read_shell_mesh(path2, "scene.yaml");
  CHECK(m2.groups.size() == 1);
  REQUIRE(m2.groups.count("hem") == 1);
  CHECK(m2.groups.at("hem").size() == 3);
}

TEST_CASE("read_shell_mesh merges a UV-seamed cube to 8 control points, UVs kept per corner",
          "[shellmesh]") {
  TempDir dir("shellmesh_cube");
  // Unit cube, each face with its own 4 UVs and its own normal: assimp's joining keeps
  // 24 vertices; a shell wants the 8 corners.
  std::string s;
  for (int i = 0; i < 8; ++i)
    s += "v " + std::string(i & 1 ? "0.5" : "-0.5") + " " + (i & 2 ? "0.5" : "-0.5") + " " +
         (i & 4 ? "0.5" : "-0.5") + "\n";
  for (int f = 0; f < 6; ++f)
    for (int k = 0; k < 4; ++k)
      s += "vt " + std::to_string(0.1 * f + 0.01 * k) + " " + std::to_string(0.5 + 0.1 * k) + "\n";
  s += "vn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\nvn 0 0 1\nvn 0 0 -1\n";
  // +x, -x, -y, +y, -z, +z (1-based v); normal index per face.
  const int faces[6][4] = {{2, 4, 8, 6}, {1, 5, 7, 3}, {1, 2, 6, 5},
                           {3, 7, 8, 4}, {1, 3, 4, 2}, {5, 6, 8, 7}};
  const int normal[6] = {1, 2, 4, 3, 6, 5};
  for (int f = 0; f < 6; ++f) {
    s += "f";
    for (int k = 0; k < 4; ++k)
      s += " " + std::to_string(faces[f][k]) + "/" + std::to_string(4 * f + k + 1) + "/" +
           std::to_string(normal[f]);
    s += "\n";
  }
  const std::string path = dir.write("cube.obj", s);
  const ShellMesh m = read_shell_mesh(path, "scene.yaml");
  REQUIRE(m.vertices.size() == 8);
  // Every corner of the cube is on three faces with three different UVs: 24 UV entries.
  REQUIRE(m.uvs.size() == 24);
  REQUIRE(m.uv_triangles.size() == 12);
  REQUIRE(m.triangles.size() == 12);
  std::set<std::tuple<double, double, double>> corners;
  for (const auto& v : m.vertices) corners.emplace(v.x(), v.y(), v.z());
  CHECK(corners.size() == 8);
  // Closed: every edge is shared by exactly two triangles, in opposite directions.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  CHECK(directed.size() == 36);
  for (const auto& [e, count] : directed) {
    CHECK(count == 1);
    CHECK(directed.count({e.second, e.first}) == 1);
  }
  // Every triangle corner keeps its face's UV: triangulated quad f holds triangles 2f and
  // 2f + 1; each corner is the quad corner at its position.
  for (int f = 0; f < 6; ++f)
    for (int half = 0; half < 2; ++half) {
      const Eigen::Vector3i& t = m.triangles[2 * f + half];
      const Eigen::Vector3i& ut = m.uv_triangles[2 * f + half];
      for (int c = 0; c < 3; ++c) {
        int quad_corner = -1;
        for (int k = 0; k < 4; ++k) {
          const int i = faces[f][k] - 1;
          if (m.vertices[t[c]] ==
              Vec3d((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5))
            quad_corner = k;
        }
        INFO("face " << f << " triangle " << half << " corner " << c);
        REQUIRE(quad_corner >= 0);
        CHECK(m.uvs[ut[c]].x() == Approx(0.1 * f + 0.01 * quad_corner).margin(1e-6));
        CHECK(m.uvs[ut[c]].y() == Approx(0.5 + 0.1 * quad_corner).margin(1e-6));
      }
    }
}

TEST_CASE("read_shell_mesh reads back a written frame", "[shellmesh]") {
  TempDir dir("shellmesh_roundtrip");
  const Grid g(5, 4);
  for (const MeshFormat format : {MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Glb}) {
    const std::string path = dir.file(std::string("rt.") + mesh_format_extension(format));
    write_shell_mesh(path, g.frame(false, true), format);
    const ShellMesh m = read_shell_mesh(path, "scene.yaml");
    INFO(path);
    CHECK(m.vertices.size() == g.positions.size());
    CHECK(m.triangles.size() == g.triangles.size());
    CHECK(m.uvs.size() == g.positions.size());
  }
}

TEST_CASE("read_shell_mesh reports bad files with the location and the path", "[shellmesh]") {
  TempDir dir("shellmesh_errors");
  const std::string where = "shot.yaml:12: shells[1].mesh";
  const auto expect_error = [&](const std::string& path, const std::string& part) {
    INFO(path);
    try {
      (void)read_shell_mesh(path, where);
      FAIL("no UserError");
    } catch (const UserError& e) {
      INFO(e.what());
      CHECK(e.file == "shot.yaml");
      CHECK(e.line == 12);
      CHECK(e.key == "shells[1].mesh");
      CHECK(contains(e.message, path));
      CHECK(contains(e.message, part));
    }
  };
  expect_error(dir.file("missing.obj"), "does not exist");
  expect_error(dir.path.string(), "not a file");
  expect_error(dir.write("garbage.ply", "ply\nthis is not a ply file\n"), "cannot read");
  expect_error(dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\n"), "no triangles");
  expect_error(dir.write("nan.obj", "v 0 0 0\nv nan 0 0\nv 1 1 0\nf 1 2 3\n"), "");
  // Two vertices at one position in one triangle: degenerate once merged.
  expect_error(
      dir.write("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n"),
      "same position");
  // A truncated binary PLY written by us.
  const Grid g(3, 3);
  const std::string ply = dir.file("cut.ply");
  write_shell_mesh(ply, g.frame(true, true), MeshFormat::Ply);
  const std::string bytes = file_bytes(ply);
  std::ofstream(ply, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  expect_error(ply, "");
}

TEST_CASE("write_shell_mesh rejects out-of-range triangles", "[shellmesh]") {
  TempDir dir("shellmesh_bad_input");
  Grid g(3, 3);
  g.triangles[2][1] = 9;
  CHECK_THROWS_AS(write_shell_mesh(dir.file("bad.ply"), g.frame(true, true), MeshFormat::Ply),
                  InvariantError);
  CHECK_FALSE(fs::exists(dir.file("bad.ply")));
  CHECK(dir.temp_files() == 0);
}

TEST_CASE("write_shell_mesh timing for a 100k-vertex mesh", "[shellmesh][timing]") {
  TempDir dir("shellmesh_timing");
  const Grid g(317, 317);  // 100489 vertices, 199712 triangles
  for (const MeshFormat format : {MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Glb}) {
    const std::string path = dir.file(std::string("big.") + mesh_format_extension(format));
    const auto t0 = std::chrono::steady_clock::now();
    write_shell_mesh(path, g.frame(false, true), format);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    WARN(mesh_format_extension(format)
         << ": wrote " << g.positions.size() << " vertices, " << g.triangles.size()
         << " triangles in " << s << " s (" << fs::file_size(path) / 1e6 << " MB)");
    CHECK(fs::file_size(path) > 0);
  }
}

TEST_CASE("output.up_axis z: PLY and OBJ turned (x, y, z) -> (x, -z, y) exactly, GLB Y-up",
          "[shellmesh][axes]") {
  TempDir dir("shellmesh_up_axis");
  const Grid g(5, 4);
  const std::size_t n = g.positions.size();
  const std::vector<Vec3> vel = grid_velocities(g);
  for (const bool given_normals : {true, false}) {
    INFO("normals given " << given_normals);
    MeshFrame f = g.frame(given_normals, true);
    f.velocities = vel.data();
    const std::string y_ply = dir.file("y.ply"), z_ply = dir.file("z.ply");
    write_shell_mesh(y_ply, f, MeshFormat::Ply);
    f.up_axis = UpAxis::Z;
    write_shell_mesh(z_ply, f, MeshFormat::Ply);
    const PlyMesh y = read_ply(y_ply), z = read_ply(z_ply);
    REQUIRE(z.positions.size() == n);
    REQUIRE(z.normals.size() == n);
    REQUIRE(z.velocities.size() == n);
    CHECK(contains(file_bytes(z_ply), "comment up_axis z\n"));
    CHECK(!contains(file_bytes(y_ply), "up_axis"));
    for (std::size_t v = 0; v < n; ++v) {
      INFO("vertex " << v);
      // A known point: the float of the simulation's (x, y, z), turned.
      const Vec3f p = g.positions[v].cast<float>();
      CHECK(z.positions[v] == Vec3f(p.x(), -p.z(), p.y()));
      CHECK(y.positions[v] == p);
      const Vec3f u = vel[v].cast<float>();
      CHECK(z.velocities[v] == Vec3f(u.x(), -u.z(), u.y()));
      CHECK(z.normals[v] == Vec3f(y.normals[v].x(), -y.normals[v].z(), y.normals[v].y()));
      CHECK(z.uvs[v] == y.uvs[v]);
    }
    CHECK(z.triangles == y.triangles);

    // OBJ: the same through assimp (one vertex per face corner, in face order).
    f.up_axis = UpAxis::Y;
    write_shell_mesh(dir.file("y.obj"), f, MeshFormat::Obj);
    f.up_axis = UpAxis::Z;
    write_shell_mesh(dir.file("z.obj"), f, MeshFormat::Obj);
    Assimp::Importer iy, iz;
    const aiMesh* my = read_raw(iy, dir.file("y.obj"))->mMeshes[0];
    const aiMesh* mz = read_raw(iz, dir.file("z.obj"))->mMeshes[0];
    REQUIRE(my->mNumVertices == mz->mNumVertices);
    for (unsigned v = 0; v < my->mNumVertices; ++v) {
      const aiVector3D a = my->mVertices[v], b = mz->mVertices[v];
      CHECK(b.x == a.x);
      CHECK(b.y == -a.z);
      CHECK(b.z == a.y);
      const aiVector3D na = my->mNormals[v], nb = mz->mNormals[v];
      CHECK(nb.x == na.x);
      CHECK(nb.y == -na.z);
      CHECK(nb.z == na.y);
    }

    // GLB: glTF is Y-up by definition; up_axis does not change a byte.
    f.up_axis = UpAxis::Y;
    write_shell_mesh(dir.file("y.glb"), f, MeshFormat::Glb);
    f.up_axis = UpAxis::Z;
    write_shell_mesh(dir.file("z.glb"), f, MeshFormat::Glb);
    CHECK(file_bytes(dir.file("y.glb")) == file_bytes(dir.file("z.glb")));
  }
}
