// UV seams through the whole pipeline (issue 12, item 9): a mesh shell whose file has
// several texture coordinates at some positions is simulated on its welded control mesh,
// and its output meshes (PLY, OBJ, GLB; output_refine 0 and 1) keep every corner's UV by
// splitting vertices at the seam, with the same vertices every frame; positions, normals
// and velocities of the split copies agree. Read back with the project's PLY reader
// (io/ply_reader.h) and with assimp.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "io/ply_reader.h"
#include "io/shell_mesh_reader.h"
#include "tests/app/cli_harness.h"

namespace fs = std::filesystem;
using shellmpm_test::CmdResult;
using shellmpm_test::run_shellmpm;
using shellmpm_test::TempDir;

namespace {

constexpr int kAround = 8, kRings = 4;

/// An open tube around Y (radius 0.2 m, 0.3 m tall) as OBJ: kAround x kRings positions,
/// but (kAround + 1) x kRings texture coordinates, u = i / kAround running once around:
/// the column at u = 0 and u = 1 is a UV seam, its positions carry two UVs each.
std::string tube_obj() {
  std::ostringstream s;
  s.precision(17);
  s << "# open tube with a UV seam along u = 0 / 1\n";
  for (int j = 0; j < kRings; ++j)
    for (int i = 0; i < kAround; ++i) {
      const double th = 2 * M_PI * i / kAround;
      s << "v " << 0.2 * std::cos(th) << " " << 0.6 + 0.1 * j << " " << -0.2 * std::sin(th) << "\n";
    }
  for (int j = 0; j < kRings; ++j)
    for (int i = 0; i <= kAround; ++i)
      s << "vt " << double(i) / kAround << " " << double(j) / (kRings - 1) << "\n";
  const auto corner = [](int i, int j) {
    return std::to_string(1 + j * kAround + i % kAround) + "/" +
           std::to_string(1 + j * (kAround + 1) + i);
  };
  for (int j = 0; j + 1 < kRings; ++j)
    for (int i = 0; i < kAround; ++i) {
      s << "f " << corner(i, j) << " " << corner(i + 1, j) << " " << corner(i, j + 1) << "\n";
      s << "f " << corner(i + 1, j) << " " << corner(i + 1, j + 1) << " " << corner(i, j + 1)
        << "\n";
    }
  return s.str();
}

/// What an OBJ file says per face corner: position index and texture coordinate.
struct ObjCorners {
  std::vector<std::array<int, 3>> v;               ///< 0-based position index
  std::vector<std::array<Eigen::Vector2d, 3>> uv;  ///< the corner's vt
  std::size_t positions = 0;                       ///< "v" lines
  std::set<std::pair<int, int>> distinct;          ///< (v, vt) pairs over all corners
};

/// Parses the v, vt and triangle f lines of an OBJ file written as "f v/vt[/vn] ...".
ObjCorners parse_obj(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in);
  ObjCorners c;
  std::vector<Eigen::Vector2d> vts;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") ++c.positions;
    if (tag == "vt") {
      double u = 0, v = 0;
      ls >> u >> v;
      vts.emplace_back(u, v);
    }
    if (tag != "f") continue;
    std::array<int, 3> vi{};
    std::array<Eigen::Vector2d, 3> uv;
    for (int k = 0; k < 3; ++k) {
      std::string corner;
      ls >> corner;
      const auto slash = corner.find('/');
      REQUIRE(slash != std::string::npos);
      vi[k] = std::stoi(corner.substr(0, slash)) - 1;
      const int t = std::stoi(corner.substr(slash + 1)) - 1;
      REQUIRE(t >= 0);
      REQUIRE(t < static_cast<int>(vts.size()));
      uv[k] = vts[t];
      c.distinct.emplace(vi[k], t);
    }
    c.v.push_back(vi);
    c.uv.push_back(uv);
  }
  return c;
}

/// A cloth tube hanging from its top ring under gravity: it deforms, so positions,
/// normals and velocities change from frame to frame.
std::string scene_text(const std::string& obj, const std::string& out) {
  return R"(version: 1
shot:
  frames: [1, 3]
  fps: 24
  dx: 0.05
  domain: {min: [-1, -0.5, -1], max: [1, 1.5, 1]}
shell_materials:
  - {name: cotton, youngs_modulus: 2.0e4, poisson_ratio: 0.3, density: 400, thickness: 0.001}
shells:
  - name: tube
    material: cotton
    geometry: {type: mesh, path: )" +
         obj + R"(}
    pins: [{box: {min: [-1, 0.85, -1], max: [1, 1, 1]}}]
output:
  directory: )" +
         out + R"(
  density: false
  velocity: true
)";
}

/// One frame as assimp reads it without joining vertices: per face corner, the UV.
std::vector<std::array<Eigen::Vector2d, 3>> assimp_corner_uvs(const std::string& path,
                                                              unsigned* num_vertices) {
  Assimp::Importer importer;
  const aiScene* s = importer.ReadFile(path, aiProcess_Triangulate);
  INFO(path << ": " << importer.GetErrorString());
  REQUIRE(s);
  REQUIRE(s->mNumMeshes == 1);
  const aiMesh* m = s->mMeshes[0];
  REQUIRE(m->HasTextureCoords(0));
  if (num_vertices) *num_vertices = m->mNumVertices;
  std::vector<std::array<Eigen::Vector2d, 3>> out;
  for (unsigned f = 0; f < m->mNumFaces; ++f) {
    REQUIRE(m->mFaces[f].mNumIndices == 3);
    std::array<Eigen::Vector2d, 3> c;
    for (int k = 0; k < 3; ++k) {
      const aiVector3D& t = m->mTextureCoords[0][m->mFaces[f].mIndices[k]];
      c[k] = Eigen::Vector2d(t.x, t.y);
    }
    out.push_back(c);
  }
  return out;
}

bool near(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - b).cwiseAbs().maxCoeff() < 1e-6;  // written as float
}

/// Whether the corner UVs of the 4^levels output triangles of each control triangle are
/// the file's corner UVs interpolated on the refined lattice: with levels 0 the same
/// three; with 1 the corners and the edge midpoints, nothing else.
void check_corner_uvs(const ObjCorners& file,
                      const std::vector<std::array<Eigen::Vector2d, 3>>& written, int levels) {
  const std::size_t per = std::size_t(1) << (2 * levels);
  REQUIRE(written.size() == file.uv.size() * per);
  for (std::size_t t = 0; t < file.uv.size(); ++t) {
    const auto& c = file.uv[t];
    std::vector<Eigen::Vector2d> expected(c.begin(), c.end());
    if (levels == 1)
      for (int k = 0; k < 3; ++k) expected.push_back(0.5 * (c[k] + c[(k + 1) % 3]));
    std::vector<bool> seen(expected.size(), false);
    for (std::size_t s = t * per; s < (t + 1) * per; ++s)
      for (int k = 0; k < 3; ++k) {
        bool found = false;
        for (std::size_t e = 0; e < expected.size(); ++e)
          if (near(written[s][k], expected[e])) {
            found = true;
            seen[e] = true;
          }
        INFO("control triangle " << t << ", output triangle " << s << " corner " << k << ": "
                                 << written[s][k].transpose());
        CHECK(found);
      }
    for (std::size_t e = 0; e < expected.size(); ++e) CHECK(seen[e]);
    if (levels == 0)  // corner by corner, in order
      for (int k = 0; k < 3; ++k) CHECK(near(written[t][k], c[k]));
  }
}

}  // namespace

TEST_CASE("read_shell_mesh welds a UV-seamed tube and keeps every corner's UV", "[shellmesh]") {
  TempDir dir("uv_seam_read");
  const std::string obj = dir.write("tube.obj", tube_obj());
  const ObjCorners file = parse_obj(obj);
  const shellmpm::ShellMesh m = shellmpm::read_shell_mesh(obj, "scene.yaml");
  CHECK(m.vertices.size() == file.positions);  // welded: one control point per position
  REQUIRE(m.triangles.size() == file.v.size());
  CHECK(m.uvs.size() == file.distinct.size());  // one UV per distinct (position, UV) corner
  CHECK(m.uvs.size() > m.vertices.size());
  REQUIRE(m.uv_triangles.size() == m.triangles.size());
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      INFO("triangle " << t << " corner " << k);
      CHECK(near(m.uvs[m.uv_triangles[t][k]], file.uv[t][k]));  // assimp reads floats
    }
}

TEST_CASE("run: a UV-seamed mesh shell keeps per-corner UVs in PLY, OBJ and GLB",
          "[cli][shellmesh]") {
  TempDir dir("uv_seam_run");
  const std::string obj = dir.write("tube.obj", tube_obj());
  const ObjCorners file = parse_obj(obj);
  REQUIRE(file.distinct.size() == (kAround + 1) * kRings);  // the seam: two UVs on 4 points
  REQUIRE(file.positions == kAround * kRings);

  for (const int levels : {0, 1})
    for (const std::string format : {"ply", "obj", "glb"}) {
      CAPTURE(levels, format);
      const std::string out = dir.file("out_" + format + std::to_string(levels));
      const std::string scene = dir.write("tube.yaml", scene_text(obj, out));
      const CmdResult r =
          run_shellmpm("run " + scene + " -q -o " + out + " --set output.shell_format=" + format +
                       " --set 'shells[0].output_refine=" + std::to_string(levels) + "'");
      INFO(r.output);
      REQUIRE(r.code == 0);

      std::vector<std::array<Eigen::Vector2d, 3>> first;
      unsigned first_vertices = 0;
      for (int f = 1; f <= 3; ++f) {
        const std::string path = out + "/tube.000" + std::to_string(f) + "." + format;
        CAPTURE(path);
        REQUIRE(fs::exists(path));
        unsigned nv = 0;
        const auto corners = assimp_corner_uvs(path, &nv);
        check_corner_uvs(file, corners, levels);
        // The same vertices every frame: count, triangles and UVs (as is, not approximately).
        if (format == "obj") nv = static_cast<unsigned>(parse_obj(path).positions);
        if (f == 1) {
          first = corners;
          first_vertices = nv;
        }
        CHECK(nv == first_vertices);
        CHECK(corners == first);
        // Level 0: one output vertex per distinct corner of the file, no more, no fewer.
        if (levels == 0) CHECK(nv == file.distinct.size());
      }
      if (format != "ply") continue;

      // The project's own reader: UVs per vertex, and the split copies of a point share its
      // position, normal and velocity.
      std::vector<shellmpm::PlyMesh> frames;
      for (int f = 1; f <= 3; ++f)
        frames.push_back(shellmpm::read_ply(out + "/tube.000" + std::to_string(f) + ".ply"));
      for (const shellmpm::PlyMesh& p : frames) {
        REQUIRE(p.uvs.size() == p.positions.size());
        REQUIRE(p.velocities.size() == p.positions.size());
        REQUIRE(p.normals.size() == p.positions.size());
        CHECK(p.positions.size() == frames[0].positions.size());
        CHECK(p.triangles == frames[0].triangles);
        CHECK(p.uvs == frames[0].uvs);
        std::vector<std::array<Eigen::Vector2d, 3>> corners;
        for (const Eigen::Vector3i& t : p.triangles)
          corners.push_back(
              {p.uvs[t[0]].cast<double>(), p.uvs[t[1]].cast<double>(), p.uvs[t[2]].cast<double>()});
        check_corner_uvs(file, corners, levels);
        std::map<std::array<float, 3>, std::vector<std::size_t>> at;
        for (std::size_t v = 0; v < p.positions.size(); ++v)
          at[{p.positions[v].x(), p.positions[v].y(), p.positions[v].z()}].push_back(v);
        int split = 0;
        for (const auto& [pos, vs] : at) {
          if (vs.size() < 2) continue;
          ++split;
          for (std::size_t i = 1; i < vs.size(); ++i) {
            CHECK(p.normals[vs[i]] == p.normals[vs[0]]);
            CHECK(p.velocities[vs[i]] == p.velocities[vs[0]]);
            CHECK(p.uvs[vs[i]] != p.uvs[vs[0]]);
          }
        }
        // The seam's points: kRings corners, and at level 1 the kRings - 1 edge midpoints.
        CHECK(split == (levels == 0 ? kRings : 2 * kRings - 1));
      }
      // It moved and bent: velocities are not all equal, positions changed.
      double moved = 0;
      for (std::size_t v = 0; v < frames[2].positions.size(); ++v)
        moved = std::max(moved, double((frames[2].positions[v] - frames[0].positions[v]).norm()));
      CHECK(moved > 1e-3);
    }
}
