// Mesh import (io/mesh_reader) and mesh signed distance fields (io/mesh_sdf).
#include <unistd.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "io/mesh_reader.h"
#include "io/mesh_sdf.h"
#include "io/user_error.h"
#include "tests/support/temp_dir.h"

namespace fs = std::filesystem;
using namespace shellmpm;
using shellmpm_test::TempDir;

namespace {

/// Unit cube [-0.5, 0.5]^3 as 6 quads (assimp triangulates them), optionally with UVs.
std::string cube_obj(bool uvs, bool drop_top = false) {
  std::string s = "# cube\n";
  for (int i = 0; i < 8; ++i)
    s += "v " + std::string(i & 1 ? "0.5" : "-0.5") + " " + (i & 2 ? "0.5" : "-0.5") + " " +
         (i & 4 ? "0.5" : "-0.5") + "\n";
  if (uvs) s += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  const int faces[6][4] = {{1, 3, 7, 5}, {2, 6, 8, 4}, {1, 5, 6, 2},
                           {3, 4, 8, 7}, {1, 2, 4, 3}, {5, 7, 8, 6}};
  for (int f = 0; f < 6; ++f) {
    if (drop_top && f == 3) continue;  // the +y face
    s += "f";
    for (int k = 0; k < 4; ++k)
      s += " " + std::to_string(faces[f][k]) + (uvs ? "/" + std::to_string(k + 1) : "");
    s += "\n";
  }
  return s;
}

/// A UV sphere of radius r as ASCII PLY: 2 + (nlat-1) nlon vertices, 2 nlon (nlat-1) triangles.
std::string sphere_ply(double r, int nlat, int nlon, int* nv, int* nt) {
  std::string v, f;
  *nv = 0;
  *nt = 0;
  auto vert = [&](double x, double y, double z) {
    v += std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
    return (*nv)++;
  };
  auto tri = [&](int a, int b, int c) {
    f += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
    ++*nt;
  };
  const int top = vert(0, r, 0);
  for (int i = 1; i < nlat; ++i) {
    const double th = M_PI * i / nlat;
    for (int j = 0; j < nlon; ++j) {
      const double ph = 2 * M_PI * j / nlon;
      vert(r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph));
    }
  }
  const int bottom = vert(0, -r, 0);
  auto ring = [&](int i, int j) { return 1 + (i - 1) * nlon + (j % nlon); };
  for (int j = 0; j < nlon; ++j) {
    tri(top, ring(1, j + 1), ring(1, j));
    tri(bottom, ring(nlat - 1, j), ring(nlat - 1, j + 1));
  }
  for (int i = 1; i < nlat - 1; ++i)
    for (int j = 0; j < nlon; ++j) {
      tri(ring(i, j), ring(i, j + 1), ring(i + 1, j + 1));
      tri(ring(i, j), ring(i + 1, j + 1), ring(i + 1, j));
    }
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(*nv) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(*nt) + "\nproperty list uchar int vertex_indices\nend_header\n" + v + f;
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned n =
        (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += {t[n >> 18], t[(n >> 12) & 63], t[(n >> 6) & 63], t[n & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned n = (unsigned char)in[i] << 16;
    out += {t[n >> 18], t[(n >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned n = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += {t[n >> 18], t[(n >> 12) & 63], t[(n >> 6) & 63], '='};
  }
  return out;
}

/// One triangle (0,0,0), (1,0,0), (0,1,0) under a node scaled by 2 whose child is
/// translated by (1,2,3): world vertices 2 (p + (1,2,3)).
std::string triangle_gltf() {
  std::string buf;
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const unsigned short idx[4] = {0, 1, 2, 0};
  buf.append(reinterpret_cast<const char*>(pos), sizeof pos);
  buf.append(reinterpret_cast<const char*>(idx), sizeof idx);
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
 "nodes":[{"scale":[2,2,2],"children":[1]},{"translation":[1,2,3],"mesh":0}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
 "buffers":[{"byteLength":44,"uri":"data:application/octet-stream;base64,)" +
         base64(buf) + R"("}],
 "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},
                {"buffer":0,"byteOffset":36,"byteLength":6}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
               "min":[0,0,0],"max":[1,1,0]},
              {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]})";
}

/// Distance from p to the surface of the box [-a, a]^3, signed (negative inside).
double box_sdf(const Vec3d& p, double a) {
  const Vec3d q = p.cwiseAbs() - Vec3d::Constant(a);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

fs::path asset(const std::string& name) {
#ifdef SHELLMPM_SOURCE_DIR
  const fs::path root = SHELLMPM_SOURCE_DIR;
#else
  const fs::path root = fs::path(__FILE__).parent_path().parent_path().parent_path();
#endif
  return root / "scenes" / "assets" / name;
}

}  // namespace

TEST_CASE("read_mesh: OBJ cube is triangulated and welded", "[mesh]") {
  TempDir dir("mesh_obj");
  const TriMesh m =
      read_mesh(dir.write("cube.obj", cube_obj(false)), "s.yaml:3: sources[0].shape.path");
  CHECK(m.vertices.size() == 8);
  CHECK(m.triangles.size() == 12);
  CHECK(m.uvs.empty());
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) CHECK((t[k] >= 0 && t[k] < 8));
  for (const auto& v : m.vertices) CHECK(v.cwiseAbs().maxCoeff() == Approx(0.5));

  // With per-corner UVs the corners differ in an attribute and are not joined.
  const TriMesh u = read_mesh(dir.write("cube_uv.obj", cube_obj(true)), "s.yaml");
  CHECK(u.triangles.size() == 12);
  CHECK(u.uvs.size() == u.vertices.size());
  CHECK(u.vertices.size() > 8);
}

TEST_CASE("read_mesh: PLY sphere and glTF node transforms", "[mesh]") {
  TempDir dir("mesh_ply");
  int nv = 0, nt = 0;
  const std::string ply = dir.write("sphere.ply", sphere_ply(0.5, 12, 24, &nv, &nt));
  const TriMesh m = read_mesh(ply, "s.yaml");
  CHECK(static_cast<int>(m.vertices.size()) == nv);
  CHECK(static_cast<int>(m.triangles.size()) == nt);
  for (const auto& v : m.vertices) CHECK(v.norm() == Approx(0.5).epsilon(1e-4));

  const TriMesh g = read_mesh(dir.write("tri.gltf", triangle_gltf()), "s.yaml");
  REQUIRE(g.vertices.size() == 3);
  REQUIRE(g.triangles.size() == 1);
  const Vec3d expect[3] = {{2, 4, 6}, {4, 4, 6}, {2, 6, 6}};
  for (int k = 0; k < 3; ++k) {
    INFO("vertex " << k << ": " << g.vertices[g.triangles[0][k]].transpose());
    CHECK((g.vertices[g.triangles[0][k]] - expect[k]).norm() < 1e-6);
  }
}

TEST_CASE("read_mesh: bad files are user errors naming the file and key", "[mesh]") {
  TempDir dir("mesh_bad");
  const std::string where = "shot.yaml:14: colliders[0].shape.path";
  auto expect_error = [&](const std::string& path, const std::string& what) {
    try {
      read_mesh(path, where);
      FAIL("no error for " << path);
    } catch (const UserError& e) {
      INFO(e.what());
      CHECK(e.file == "shot.yaml");
      CHECK(e.line == 14);
      CHECK(e.key == "colliders[0].shape.path");
      CHECK(e.message.find(path) != std::string::npos);
      CHECK(e.message.find(what) != std::string::npos);
      CHECK(std::string(e.what()).rfind("shot.yaml:14: colliders[0].shape.path: ", 0) == 0);
    }
  };
  expect_error((dir.path / "missing.obj").string(), "does not exist");
  expect_error(dir.write("bad.ply",
                         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                         "element face 1\nend_header\n1\n2\n"),
               "cannot read mesh");
  expect_error(dir.write("noise.stl", std::string(200, '\x7f')), "");
  // assimp's validation rejects a mesh without faces before we see it.
  expect_error(dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), "no faces");
  expect_error(dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n"), "no triangles");
  expect_error(dir.write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "non-finite");
}

TEST_CASE("mesh_to_sdf: cube and sphere distances", "[mesh]") {
  TempDir dir("mesh_sdf");
  const double h = 0.05;
  SECTION("cube: exact box distance, full interior") {
    const TriMesh m = read_mesh(dir.write("cube.obj", cube_obj(false)), "s.yaml");
    auto sdf = mesh_to_sdf(m, h, 3, "s.yaml");
    REQUIRE(sdf);
    CHECK(sdf->spacing == h);
    CHECK(sdf->sample(Vec3d(0, 0, 0)) == Approx(-0.5).margin(h));
    CHECK(sdf->sample(Vec3d(0.6, 0.1, 0)) == Approx(0.1).margin(0.2 * h));
    CHECK(sdf->sample(Vec3d(0.65, 0.65, 0.65)) > 0.0);
    CHECK(sdf->sample(Vec3d(3, 0, 0)) > 2.0);  // far outside: beyond the box
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-0.62, 0.62);
    for (int i = 0; i < 300; ++i) {
      const Vec3d p(u(rng), u(rng), u(rng));
      const double exact = box_sdf(p, 0.5);
      if (exact > 2.5 * h) continue;  // the band is 3 voxels outside
      INFO(p.transpose() << " exact " << exact);
      CHECK(std::abs(sdf->sample(p) - exact) < h);
    }
  }
  SECTION("sphere: negative inside, positive outside, |sdf| ~ distance near the surface") {
    int nv = 0, nt = 0;
    const TriMesh m = read_mesh(dir.write("s.ply", sphere_ply(0.5, 24, 48, &nv, &nt)), "s.yaml");
    auto sdf = mesh_to_sdf(m, h, 3, "s.yaml");
    CHECK(sdf->sample(Vec3d(0, 0, 0)) == Approx(-0.5).margin(h));
    CHECK(sdf->sample(Vec3d(0.8, 0, 0)) > 0.0);
    std::mt19937 rng(2);
    std::normal_distribution<double> n;
    std::uniform_real_distribution<double> r(0.3, 0.62);
    for (int i = 0; i < 300; ++i) {
      const Vec3d p = Vec3d(n(rng), n(rng), n(rng)).normalized() * r(rng);
      INFO(p.transpose());
      CHECK(std::abs(sdf->sample(p) - (p.norm() - 0.5)) < h);
      if (std::abs(p.norm() - 0.5) > 0.01) CHECK((sdf->sample(p) < 0) == (p.norm() < 0.5));
    }
    // Gradient points outward with unit length.
    const Vec3d g = sdf->gradient(Vec3d(0.45, 0, 0));
    CHECK(g.normalized().x() == Approx(1.0).margin(0.02));
    CHECK(g.norm() == Approx(1.0).margin(0.1));
  }
  SECTION("an open mesh is a user error") {
    const TriMesh m = read_mesh(dir.write("open.obj", cube_obj(false, true)), "s.yaml");
    CHECK(m.triangles.size() == 10);
    CHECK_THROWS_AS(mesh_to_sdf(m, h, 3, "s.yaml: sources[1].shape.path"), UserError);
    try {
      mesh_to_sdf(m, h, 3, "s.yaml: sources[1].shape.path");
    } catch (const UserError& e) {
      CHECK(e.key == "sources[1].shape.path");
      CHECK(e.message.find("does not enclose") != std::string::npos);
      CHECK(e.message.find("4 open edges") != std::string::npos);
    }
  }
}

TEST_CASE("load_scene_assets fills mesh sources and colliders", "[mesh]") {
  TempDir dir("mesh_scene");
  Scene scene;
  scene.path = "shot.yaml";
  scene.shot.dx = 0.04;
  SourceDesc src;
  src.shape.kind = ShapeDesc::Kind::Mesh;
  src.shape.mesh_path = dir.write("cube.obj", cube_obj(false));
  src.shape.mesh_scale = 0.5;
  src.shape.mesh_translate = Vec3d(1, 0, 0);
  scene.sources.push_back(src);
  SourceDesc box;  // not a mesh: untouched
  box.shape.kind = ShapeDesc::Kind::Box;
  scene.sources.push_back(box);
  ColliderDesc col;
  col.shape = src.shape;
  scene.colliders.push_back(col);
  load_scene_assets(scene);
  REQUIRE(scene.sources[0].shape.sdf);
  CHECK_FALSE(scene.sources[1].shape.sdf);
  REQUIRE(scene.colliders[0].shape.sdf);
  const SdfGrid& s = *scene.sources[0].shape.sdf;
  CHECK(s.spacing == Approx(0.02));
  CHECK(s.sample(Vec3d(1, 0, 0)) == Approx(-0.25).margin(0.02));
  CHECK(s.sample(Vec3d(1.3, 0, 0)) == Approx(0.05).margin(0.01));
  CHECK(s.sample(Vec3d(0, 0, 0)) > 0.0);
  // Colliders get a wider band outside.
  CHECK(scene.colliders[0].shape.sdf->sample(Vec3d(1.39, 0, 0)) == Approx(0.14).margin(0.01));

  scene.colliders[0].shape.sdf.reset();
  scene.colliders[0].shape.mesh_path = (dir.path / "gone.obj").string();
  try {
    load_scene_assets(scene);
    FAIL("no error");
  } catch (const UserError& e) {
    CHECK(e.file == "shot.yaml");
    CHECK(e.key == "colliders[0].shape.path");
    CHECK(e.message.find("gone.obj") != std::string::npos);
  }
}

TEST_CASE("example assets: torus and bowl are closed meshes", "[mesh]") {
  const fs::path torus = asset("torus.obj"), bowl = asset("bowl.obj");
  if (!fs::exists(torus) || !fs::exists(bowl)) {
    WARN("scenes/assets not found next to " << __FILE__ << "; skipped");
    return;
  }
  const TriMesh t = read_mesh(torus.string(), "torus");
  CHECK(t.vertices.size() == 800);
  CHECK(t.triangles.size() == 1600);
  auto ts = mesh_to_sdf(t, 0.01, 3, "torus");
  CHECK(ts->sample(Vec3d(0.3, 0, 0)) == Approx(-0.12).margin(0.01));
  CHECK(ts->sample(Vec3d(0, 0, -0.3)) == Approx(-0.12).margin(0.01));
  CHECK(ts->sample(Vec3d(0, 0, 0)) > 0.0);  // the hole

  const TriMesh b = read_mesh(bowl.string(), "bowl");
  CHECK(b.triangles.size() == 1600);
  auto bs = mesh_to_sdf(b, 0.01, 8, "bowl");
  CHECK(bs->sample(Vec3d(0, 0.025, 0)) == Approx(-0.025).margin(0.01));  // bottom wall
  CHECK(bs->sample(Vec3d(0, 0.15, 0)) == Approx(0.08).margin(0.01));     // cavity, band-clamped
  CHECK(bs->sample(Vec3d(0.225, 0.25, 0)) < 0.0);                        // in the wall near the rim
  CHECK(bs->sample(Vec3d(0, -0.05, 0)) == Approx(0.05).margin(0.01));    // below
}
