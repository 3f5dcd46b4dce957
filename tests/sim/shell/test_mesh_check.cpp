// Tests of the shell control-mesh checks (sim/shell/mesh_check.h): every problem kind is
// found on a small crafted mesh, and good meshes give none.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "sim/shell/loop_basis.h"
#include "sim/shell/mesh_check.h"

using namespace shellmpm;

namespace {

using Tris = std::vector<Eigen::Vector3i>;

/// A 2 x 2 square of quads split into 8 triangles, in the z = 0 plane.
void square(std::vector<Vec3d>& x, Tris& t) {
  x.clear();
  t.clear();
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) x.emplace_back(i, j, 0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = j * 3 + i;
      t.emplace_back(a, a + 1, a + 3);
      t.emplace_back(a + 1, a + 4, a + 3);
    }
}

int count(const std::vector<MeshProblem>& ps, MeshProblemKind k) {
  return static_cast<int>(
      std::count_if(ps.begin(), ps.end(), [k](const MeshProblem& p) { return p.kind == k; }));
}

const MeshProblem& first(const std::vector<MeshProblem>& ps, MeshProblemKind k) {
  return *std::find_if(ps.begin(), ps.end(), [k](const MeshProblem& p) { return p.kind == k; });
}

}  // namespace

TEST_CASE("mesh check: good meshes have no problems and LoopBasis accepts them", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  REQUIRE(check_shell_mesh(x, t).empty());
  REQUIRE_NOTHROW(LoopBasis(static_cast<int>(x.size()), t));
  // Closed octahedron.
  const std::vector<Vec3d> ox = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                 {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  const Tris ot = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                   {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  REQUIRE(check_shell_mesh(ox, ot).empty());
}

TEST_CASE("mesh check: degenerate indices", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  t.emplace_back(0, 1, 99);
  t.emplace_back(4, 4, 5);
  t.emplace_back(-1, 2, 3);
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(count(ps, MeshProblemKind::DegenerateIndex) == 3);
  REQUIRE(first(ps, MeshProblemKind::DegenerateIndex).faces == std::vector<int>{8});
  REQUIRE(first(ps, MeshProblemKind::DegenerateIndex).message.find("face 8") != std::string::npos);
  REQUIRE(first(ps, MeshProblemKind::DegenerateIndex).message.find("99") != std::string::npos);
  REQUIRE(ps.size() == 3u);  // the bad faces are left out of the other checks
}

TEST_CASE("mesh check: non-manifold edge", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  x.emplace_back(0.5, 0.5, 1.0);  // vertex 9: a fin on the boundary edge 0-1
  t.emplace_back(1, 0, 9);        // face 8: fine, edge 0-1 now has two faces
  REQUIRE(check_shell_mesh(x, t).empty());
  x.emplace_back(0.5, -0.5, 1.0);  // vertex 10: a third face on edge 0-1
  t.emplace_back(1, 0, 10);
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(count(ps, MeshProblemKind::NonManifoldEdge) == 1);
  const MeshProblem& p = first(ps, MeshProblemKind::NonManifoldEdge);
  REQUIRE(p.vertices == std::vector<int>{0, 1});
  REQUIRE(p.faces == std::vector<int>{0, 8, 9});
  REQUIRE(ps.front().kind == MeshProblemKind::NonManifoldEdge);
  REQUIRE_THROWS_AS(LoopBasis(static_cast<int>(x.size()), t), std::invalid_argument);
}

TEST_CASE("mesh check: non-manifold vertex (bow tie)", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  // A second triangle touching the square only at corner vertex 8.
  x.emplace_back(3, 3, 0);
  x.emplace_back(2, 3, 0.5);
  t.emplace_back(8, 9, 10);
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(ps.size() == 1u);
  REQUIRE(ps[0].kind == MeshProblemKind::NonManifoldVertex);
  REQUIRE(ps[0].vertices == std::vector<int>{8});
  REQUIRE(ps[0].message.find("vertex 8") != std::string::npos);
  REQUIRE_THROWS_AS(LoopBasis(static_cast<int>(x.size()), t), std::invalid_argument);
}

TEST_CASE("mesh check: duplicate vertices", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  // Re-point the faces of the right column at copies of vertices 1, 4, 7 (a seam).
  for (int v : {1, 4, 7}) x.push_back(x[v]);
  for (int f : {2, 3, 6, 7})
    for (int k = 0; k < 3; ++k) {
      const int v = t[f][k];
      if (v == 1 || v == 4 || v == 7) t[f][k] = 9 + (v - 1) / 3;
    }
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(count(ps, MeshProblemKind::DuplicateVertex) == 3);
  REQUIRE(first(ps, MeshProblemKind::DuplicateVertex).vertices == std::vector<int>{1, 9});
  REQUIRE(ps.size() == 3u);
}

TEST_CASE("mesh check: zero-area faces", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  x[4] = 0.5 * (x[1] + x[3]);  // centre vertex onto the diagonal 1-3: face 1 collapses
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(count(ps, MeshProblemKind::ZeroAreaFace) == 1);
  REQUIRE(first(ps, MeshProblemKind::ZeroAreaFace).faces == std::vector<int>{1});
  // Coincident corners (without duplicate indices) are also zero area.
  std::vector<Vec3d> y = {{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const auto q = check_shell_mesh(y, Tris{{0, 2, 3}, {1, 2, 0}});
  REQUIRE(count(q, MeshProblemKind::ZeroAreaFace) == 1);
  REQUIRE(count(q, MeshProblemKind::DuplicateVertex) == 1);
}

TEST_CASE("mesh check: inconsistent orientation", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  std::swap(t[1][0], t[1][1]);  // flip face 1
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(count(ps, MeshProblemKind::InconsistentOrientation) == 3);  // its three inner edges
  for (const MeshProblem& p : ps) {
    REQUIRE(p.kind == MeshProblemKind::InconsistentOrientation);
    REQUIRE(std::find(p.faces.begin(), p.faces.end(), 1) != p.faces.end());
  }
  REQUIRE_THROWS_AS(LoopBasis(static_cast<int>(x.size()), t), std::invalid_argument);
}

TEST_CASE("mesh check: isolated vertices", "[meshcheck]") {
  std::vector<Vec3d> x;
  Tris t;
  square(x, t);
  x.emplace_back(5, 5, 5);
  const auto ps = check_shell_mesh(x, t);
  REQUIRE(ps.size() == 1u);
  REQUIRE(ps[0].kind == MeshProblemKind::IsolatedVertex);
  REQUIRE(ps[0].vertices == std::vector<int>{9});
  REQUIRE(ps[0].message == "isolated vertex: vertex 9 (used by no face)");
}
