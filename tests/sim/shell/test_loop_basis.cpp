// Tests of the Loop limit basis (sim/shell/loop_basis.h) against OpenSubdiv (the
// independent reference: Far::TopologyRefiner, PatchTable, PatchMap, stencil tables,
// PrimvarRefiner::Limit) and against exact properties (partition of unity, linear
// reproduction, finite differences, continuity across faces).
#include <catch2/catch.hpp>

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "sim/shell/loop_basis.h"

using namespace shellmpm;
using V3 = Eigen::Vector3d;

namespace {

struct TestMesh {
  std::string name;
  std::vector<V3> x;
  std::vector<Eigen::Vector3i> t;
};

void jitter(TestMesh& m, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (V3& p : m.x) p += V3(u(rng), u(rng), u(rng));
}

TestMesh tetrahedron() {
  TestMesh m{"tetrahedron",
             {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}},
             {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}}};
  jitter(m, 0.1, 1);
  return m;
}

TestMesh octahedron() {
  TestMesh m{
      "octahedron",
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}}};
  jitter(m, 0.1, 2);
  return m;
}

TestMesh icosahedron() {
  const double p = (1 + std::sqrt(5.0)) / 2;
  TestMesh m{"icosahedron",
             {{-1, p, 0},
              {1, p, 0},
              {-1, -p, 0},
              {1, -p, 0},
              {0, -1, p},
              {0, 1, p},
              {0, -1, -p},
              {0, 1, -p},
              {p, 0, -1},
              {p, 0, 1},
              {-p, 0, -1},
              {-p, 0, 1}},
             {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
              {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
              {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}}};
  jitter(m, 0.1, 3);
  return m;
}

/// Closed bipyramid: two apexes of valence n, equator vertices of valence 4.
TestMesh bipyramid(int n) {
  TestMesh m;
  m.name = "bipyramid" + std::to_string(n);
  for (int i = 0; i < n; ++i)
    m.x.emplace_back(std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n), 0);
  m.x.emplace_back(0, 0, 1);
  m.x.emplace_back(0, 0, -1);
  for (int i = 0; i < n; ++i) {
    m.t.emplace_back(i, (i + 1) % n, n);
    m.t.emplace_back((i + 1) % n, i, n + 1);
  }
  jitter(m, 0.05, 4 + n);
  return m;
}

/// Open disc: a centre vertex of valence k surrounded by `rings` rings of the regular
/// triangular lattice (all other interior vertices have valence 6).
TestMesh disc(int k, int rings, unsigned seed) {
  TestMesh m;
  m.name = "disc" + std::to_string(k);
  std::vector<int> first(rings + 2, 0);
  m.x.emplace_back(0, 0, 0);
  first[1] = 1;
  for (int r = 1; r <= rings; ++r) {
    for (int j = 0; j < k * r; ++j) {
      const double a = 2 * M_PI * j / (k * r);
      m.x.emplace_back(r * std::cos(a), r * std::sin(a), 0.1 * r * r * std::cos(2 * a));
    }
    first[r + 1] = first[r] + k * r;
  }
  auto id = [&](int r, int j) { return r == 0 ? 0 : first[r] + ((j % (k * r)) + k * r) % (k * r); };
  for (int j = 0; j < k; ++j) m.t.emplace_back(0, id(1, j), id(1, j + 1));
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < k; ++s) {
      for (int a = 0; a <= r; ++a)
        m.t.emplace_back(id(r, s * r + a), id(r + 1, s * (r + 1) + a),
                         id(r + 1, s * (r + 1) + a + 1));
      for (int a = 0; a < r; ++a)
        m.t.emplace_back(id(r, s * r + a), id(r + 1, s * (r + 1) + a + 1), id(r, s * r + a + 1));
    }
  jitter(m, 0.05, seed);
  return m;
}

/// Regular lattice patch nx by ny (quads split along one diagonal). Corners: one with a
/// single face, one with two faces; the rest of the boundary is regular.
TestMesh grid(int nx, int ny, double jit, unsigned seed) {
  TestMesh m;
  m.name = "grid";
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.x.emplace_back(i + 0.5 * j, j * std::sqrt(0.75), 0);
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.t.emplace_back(id(i, j), id(i + 1, j), id(i, j + 1));
      m.t.emplace_back(id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
    }
  if (jit > 0) jitter(m, jit, seed);
  return m;
}

std::vector<TestMesh> all_meshes() {
  return {tetrahedron(),  octahedron(),   icosahedron(),   bipyramid(8),
          bipyramid(12),  disc(3, 3, 11), disc(4, 3, 12),  disc(5, 3, 13),
          disc(7, 3, 14), disc(8, 3, 15), disc(12, 3, 16), grid(5, 4, 0.1, 17)};
}

/// Points per face: interior, on edges, at corners, plus random ones.
std::vector<Eigen::Vector2d> sample_points(unsigned seed, int nrandom) {
  std::vector<Eigen::Vector2d> p = {
      {1.0 / 3, 1.0 / 3}, {0.1, 0.2}, {0.7, 0.1}, {0.05, 0.9}, {0.5, 0.5}, {0.25, 0},
      {0, 0.6},           {0.3, 0.3}, {0, 0},     {1, 0},      {0, 1},     {0.02, 0.01}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < nrandom; ++i) {
    double a = u(rng), b = u(rng);
    if (a + b > 1) {
      a = 1 - a;
      b = 1 - b;
    }
    p.emplace_back(a, b);
  }
  return p;
}

struct Eval {
  V3 d[6];  // position, d/dxi1, d/dxi2, d2/dxi1^2, d2/dxi1dxi2, d2/dxi2^2
};

Eval combine(const BasisPoint& bp, const std::vector<V3>& x) {
  Eval e;
  for (auto& v : e.d) v.setZero();
  const std::vector<double>* q[6] = {&bp.N, &bp.N1, &bp.N2, &bp.N11, &bp.N12, &bp.N22};
  for (std::size_t k = 0; k < bp.ctrl.size(); ++k)
    for (int a = 0; a < 6; ++a) e.d[a] += (*q[a])[k] * x[bp.ctrl[k]];
  return e;
}

Eval eval_ours(const LoopBasis& b, const std::vector<V3>& x, int f, double s, double t) {
  BasisPoint bp;
  b.evaluate(f, s, t, bp);
  return combine(bp, x);
}

namespace osd = OpenSubdiv::Far;
namespace sdc = OpenSubdiv::Sdc;

/// OpenSubdiv reference configured like LoopBasis: Loop scheme, boundary edges and
/// single-face corners sharp (VTX_BOUNDARY_EDGE_AND_CORNER), adaptive patches.
struct OsdReference {
  std::unique_ptr<osd::TopologyRefiner> refiner;
  std::unique_ptr<const osd::PatchTable> patches;
  std::unique_ptr<osd::PatchMap> map;
  std::vector<V3> points;  // base vertices, refined vertices, local points

  static osd::TopologyRefiner* make_refiner(const TestMesh& m) {
    std::vector<int> counts(m.t.size(), 3), idx;
    for (const auto& t : m.t) idx.insert(idx.end(), {t[0], t[1], t[2]});
    osd::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(m.x.size());
    desc.numFaces = static_cast<int>(m.t.size());
    desc.numVertsPerFace = counts.data();
    desc.vertIndicesPerFace = idx.data();
    sdc::Options so;
    so.SetVtxBoundaryInterpolation(sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = osd::TopologyRefinerFactory<osd::TopologyDescriptor>;
    return Factory::Create(desc, Factory::Options(sdc::SCHEME_LOOP, so));
  }

  OsdReference(const TestMesh& m, int isolation) {
    refiner.reset(make_refiner(m));
    osd::PatchTableFactory::Options po(isolation);
    po.SetEndCapType(osd::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    po.SetPatchPrecision<double>();
    po.useInfSharpPatch = true;
    refiner->RefineAdaptive(po.GetRefineAdaptiveOptions());
    patches.reset(osd::PatchTableFactory::Create(*refiner, po));
    map = std::make_unique<osd::PatchMap>(*patches);
    using SF = osd::StencilTableFactoryReal<double>;
    SF::Options so;
    so.generateOffsets = true;
    so.generateIntermediateLevels = true;
    std::unique_ptr<const osd::StencilTableReal<double>> st(SF::Create(*refiner, so));
    if (const auto* local = patches->GetLocalPointStencilTable<double>()) {
      st.reset(SF::AppendLocalPointStencilTable(*refiner, st.get(), local));
    }
    points = m.x;
    for (int i = 0; i < st->GetNumStencils(); ++i) {
      const auto s = st->GetStencil(i);
      V3 p = V3::Zero();
      for (int k = 0; k < s.GetSize(); ++k) p += s.GetWeights()[k] * m.x[s.GetVertexIndices()[k]];
      points.push_back(p);
    }
  }

  Eval eval(int face, double u, double v) const {
    const osd::PatchTable::PatchHandle* h = map->FindPatch(face, u, v);
    REQUIRE(h != nullptr);
    double w[6][20];
    patches->EvaluateBasis(*h, u, v, w[0], w[1], w[2], w[3], w[4], w[5]);
    const auto cvs = patches->GetPatchVertices(*h);
    Eval e;
    for (int a = 0; a < 6; ++a) {
      e.d[a].setZero();
      for (int k = 0; k < cvs.size(); ++k) e.d[a] += w[a][k] * points[cvs[k]];
    }
    // OpenSubdiv 3.5 scales the derivatives of a rotated triangular sub-patch by
    // -2^depth, also for the second derivatives, which should get (-2^depth)^2: their sign
    // is wrong there (our second derivatives are checked by finite differences below).
    if (patches->GetPatchParam(*h).IsTriangleRotated())
      for (int a = 3; a < 6; ++a) e.d[a] = -e.d[a];
    return e;
  }

  /// Exact limit positions of the base vertices (limit masks).
  static std::vector<V3> vertex_limits(const TestMesh& m) {
    std::unique_ptr<osd::TopologyRefiner> r(make_refiner(m));
    struct P {
      V3 p = V3::Zero();
      void Clear() { p.setZero(); }
      void AddWithWeight(const P& s, double w) { p += w * s.p; }
    };
    std::vector<P> src(m.x.size()), dst(m.x.size());
    for (std::size_t i = 0; i < m.x.size(); ++i) src[i].p = m.x[i];
    osd::PrimvarRefinerReal<double>(*r).Limit(src, dst);
    std::vector<V3> out;
    for (const P& p : dst) out.push_back(p.p);
    return out;
  }
};

/// Distance in parameter space from (s, t) to the nearest corner of `face` whose vertex
/// is irregular (interior valence != 6, boundary with != 3 faces); 10 if none.
double distance_to_irregular_corner(const TestMesh& m, int face, double s, double t) {
  std::vector<int> nfaces(m.x.size(), 0);
  std::vector<std::vector<int>> nbr(m.x.size());
  for (const auto& tr : m.t)
    for (int k = 0; k < 3; ++k) {
      ++nfaces[tr[k]];
      for (int q = 1; q < 3; ++q) {
        auto& nb = nbr[tr[k]];
        if (std::find(nb.begin(), nb.end(), tr[(k + q) % 3]) == nb.end())
          nb.push_back(tr[(k + q) % 3]);
      }
    }
  const double cxy[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  double best = 10;
  for (int k = 0; k < 3; ++k) {
    const int v = m.t[face][k];
    const bool boundary = static_cast<int>(nbr[v].size()) != nfaces[v];
    const bool regular = boundary ? nfaces[v] == 3 : nfaces[v] == 6;
    if (!regular) best = std::min(best, std::hypot(s - cxy[k][0], t - cxy[k][1]));
  }
  return best;
}

bool verbose() {
  return std::getenv("SHELLMPM_TEST_VERBOSE") != nullptr;
}

}  // namespace

TEST_CASE("Loop basis matches OpenSubdiv limit surface and derivatives", "[loop]") {
  for (const TestMesh& m : all_meshes()) {
    const LoopBasis basis(static_cast<int>(m.x.size()), m.t);
    const OsdReference ref(m, 10);
    double err_reg[3] = {0, 0, 0}, err_irr[3] = {0, 0, 0}, err_near = 0;
    const auto pts = sample_points(42, 8);
    for (int f = 0; f < basis.num_faces(); ++f)
      for (const auto& p : pts) {
        const Eval a = eval_ours(basis, m.x, f, p[0], p[1]);
        const Eval b = ref.eval(f, p[0], p[1]);
        double e[3] = {(a.d[0] - b.d[0]).norm(),
                       std::max((a.d[1] - b.d[1]).norm(), (a.d[2] - b.d[2]).norm()),
                       std::max({(a.d[3] - b.d[3]).norm(), (a.d[4] - b.d[4]).norm(),
                                 (a.d[5] - b.d[5]).norm()})};
        const double dist = distance_to_irregular_corner(m, f, p[0], p[1]);
        if (dist > 5.0) {  // regular patch: exact box spline in both
          for (int q = 0; q < 3; ++q) err_reg[q] = std::max(err_reg[q], e[q]);
        } else if (dist > 0.01) {  // OpenSubdiv has exact sub-patches here (isolation 10)
          for (int q = 0; q < 3; ++q) err_irr[q] = std::max(err_irr[q], e[q]);
        } else {  // Gregory end caps: approximate
          err_near = std::max(err_near, e[0]);
        }
      }
    if (verbose())
      std::printf(
          "%-12s regular: pos %.2e d1 %.2e d2 %.2e | irregular (>0.01): pos %.2e d1 %.2e "
          "d2 %.2e | near EV pos %.2e\n",
          m.name.c_str(), err_reg[0], err_reg[1], err_reg[2], err_irr[0], err_irr[1], err_irr[2],
          err_near);
    INFO(m.name);
    CHECK(err_reg[0] < 1e-12);
    CHECK(err_reg[1] < 1e-11);
    CHECK(err_reg[2] < 1e-10);
    CHECK(err_irr[0] < 1e-10);
    CHECK(err_irr[1] < 1e-9);
    CHECK(err_irr[2] < 1e-7);
    CHECK(err_near < 1e-5);
  }
}

TEST_CASE("Loop basis limit positions at vertices match OpenSubdiv limit masks", "[loop]") {
  for (const TestMesh& m : all_meshes()) {
    const LoopBasis basis(static_cast<int>(m.x.size()), m.t);
    const std::vector<V3> lim = OsdReference::vertex_limits(m);
    double err_w = 0, err_eval = 0;
    std::vector<int> ctrl;
    std::vector<double> w;
    for (int v = 0; v < basis.num_vertices(); ++v) {
      basis.vertex_limit_weights(v, ctrl, w);
      V3 p = V3::Zero();
      for (std::size_t k = 0; k < ctrl.size(); ++k) p += w[k] * m.x[ctrl[k]];
      err_w = std::max(err_w, (p - lim[v]).norm());
    }
    const double cxy[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    for (int f = 0; f < basis.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Eval a = eval_ours(basis, m.x, f, cxy[k][0], cxy[k][1]);
        err_eval = std::max(err_eval, (a.d[0] - lim[m.t[f][k]]).norm());
        for (int q = 0; q < 6; ++q) REQUIRE(a.d[q].allFinite());
      }
    if (verbose())
      std::printf("%-12s vertex limit: weights %.2e, evaluate at corners %.2e\n", m.name.c_str(),
                  err_w, err_eval);
    INFO(m.name);
    CHECK(err_w < 1e-13);
    CHECK(err_eval < 1e-13);
  }
}

TEST_CASE("Loop basis: partition of unity everywhere", "[loop]") {
  for (const TestMesh& m : all_meshes()) {
    const LoopBasis basis(static_cast<int>(m.x.size()), m.t);
    BasisPoint bp;
    for (int f = 0; f < basis.num_faces(); ++f)
      for (const auto& p : sample_points(f, 4)) {
        basis.evaluate(f, p[0], p[1], bp);
        double s[6] = {0, 0, 0, 0, 0, 0}, mag[6] = {0, 0, 0, 0, 0, 0};
        const std::vector<double>* q[6] = {&bp.N, &bp.N1, &bp.N2, &bp.N11, &bp.N12, &bp.N22};
        for (int a = 0; a < 6; ++a) {
          REQUIRE(q[a]->size() == bp.ctrl.size());
          for (double v : *q[a]) {
            s[a] += v;
            mag[a] += std::abs(v);
          }
        }
        INFO(m.name << " face " << f << " xi " << p.transpose());
        REQUIRE(s[0] == Approx(1.0).margin(1e-13));
        REQUIRE(std::abs(s[1]) < 1e-11 * (1 + mag[1]));
        REQUIRE(std::abs(s[2]) < 1e-11 * (1 + mag[2]));
        // Second derivatives at an irregular corner come from a point 1e-9 away, 30
        // levels down: round-off there is about eps * 2^30 (absolute).
        for (int a = 3; a < 6; ++a) REQUIRE(std::abs(s[a]) < 1e-11 * mag[a] + 1e-6);
      }
  }
}

TEST_CASE("Loop basis reproduces linear fields on a regular lattice, boundary included", "[loop]") {
  // Control points on an affine image of the lattice: the limit is the same affine map
  // of the parameter on every face whose corners are regular (interior or boundary).
  TestMesh m = grid(6, 5, 0.0, 0);
  Eigen::Matrix3d A;
  A << 1.0, 0.3, -0.2, 0.1, 0.8, 0.5, 0.4, -0.6, 1.2;
  const V3 b(0.3, -1.0, 2.0);
  for (V3& p : m.x) p = A * p + b;
  const LoopBasis basis(static_cast<int>(m.x.size()), m.t);
  int tested = 0;
  for (int f = 0; f < basis.num_faces(); ++f) {
    if (distance_to_irregular_corner(m, f, 0.5, 0.5) < 5) continue;
    const V3 x0 = m.x[m.t[f][0]], x1 = m.x[m.t[f][1]], x2 = m.x[m.t[f][2]];
    for (const auto& p : sample_points(f, 4)) {
      const Eval e = eval_ours(basis, m.x, f, p[0], p[1]);
      INFO("face " << f << " xi " << p.transpose());
      REQUIRE((e.d[0] - (x0 + p[0] * (x1 - x0) + p[1] * (x2 - x0))).norm() < 1e-12);
      REQUIRE((e.d[1] - (x1 - x0)).norm() < 1e-12);
      REQUIRE((e.d[2] - (x2 - x0)).norm() < 1e-12);
      for (int a = 3; a < 6; ++a) REQUIRE(e.d[a].norm() < 1e-11);
      ++tested;
    }
  }
  REQUIRE(tested > 100);
  // Irregular faces of a planar mesh: the limit stays in the plane (affine invariance).
  TestMesh d = disc(7, 3, 5);
  for (V3& p : d.x) p.z() = 0;
  const LoopBasis bd(static_cast<int>(d.x.size()), d.t);
  for (int f = 0; f < bd.num_faces(); ++f)
    for (const auto& p : sample_points(f, 2)) {
      const Eval e = eval_ours(bd, d.x, f, p[0], p[1]);
      for (int a = 0; a < 6; ++a) REQUIRE(std::abs(e.d[a].z()) < 1e-12 * (1 + e.d[a].norm()));
    }
}

TEST_CASE("Loop basis derivatives match finite differences (error shrinks with h)", "[loop]") {
  for (const TestMesh& m : all_meshes()) {
    const LoopBasis basis(static_cast<int>(m.x.size()), m.t);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0.05, 0.45);
    for (int f = 0; f < basis.num_faces(); f += 3) {
      const double s = u(rng), t = u(rng);
      const Eval e = eval_ours(basis, m.x, f, s, t);
      double err1[2], err2[2];
      const double hs[2] = {1e-3, 1e-4};
      for (int k = 0; k < 2; ++k) {
        const double h = hs[k];
        const Eval ps = eval_ours(basis, m.x, f, s + h, t), ms = eval_ours(basis, m.x, f, s - h, t);
        const Eval pt = eval_ours(basis, m.x, f, s, t + h), mt = eval_ours(basis, m.x, f, s, t - h);
        err1[k] = std::max(((ps.d[0] - ms.d[0]) / (2 * h) - e.d[1]).norm(),
                           ((pt.d[0] - mt.d[0]) / (2 * h) - e.d[2]).norm());
        err2[k] = std::max({((ps.d[1] - ms.d[1]) / (2 * h) - e.d[3]).norm(),
                            ((pt.d[1] - mt.d[1]) / (2 * h) - e.d[4]).norm(),
                            ((ps.d[2] - ms.d[2]) / (2 * h) - e.d[4]).norm(),
                            ((pt.d[2] - mt.d[2]) / (2 * h) - e.d[5]).norm()});
      }
      INFO(m.name << " face " << f << " err1 " << err1[0] << " -> " << err1[1] << ", err2 "
                  << err2[0] << " -> " << err2[1]);
      REQUIRE(err1[0] < 1e-3 * (1 + e.d[3].norm() + e.d[5].norm()));
      REQUIRE(err1[1] < 0.2 * err1[0] + 1e-9);
      REQUIRE(err2[0] < 1e-2 * (1 + e.d[3].norm() + e.d[5].norm()));
      REQUIRE(err2[1] < 0.2 * err2[0] + 1e-7);
    }
  }
}

TEST_CASE("Loop basis is continuous across shared edges (value and tangent)", "[loop]") {
  for (const TestMesh& m : all_meshes()) {
    const LoopBasis basis(static_cast<int>(m.x.size()), m.t);
    // Map each directed edge to (face, local edge index).
    std::map<std::pair<int, int>, std::pair<int, int>> half;
    for (int f = 0; f < basis.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) half[{m.t[f][k], m.t[f][(k + 1) % 3]}] = {f, k};
    const double cxy[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    auto at = [&](int f, int k, double a, V3* tangent) {
      // Point a along edge k (from corner k to corner k+1) of face f.
      const double* p0 = cxy[k];
      const double* p1 = cxy[(k + 1) % 3];
      const double s = p0[0] + a * (p1[0] - p0[0]), t = p0[1] + a * (p1[1] - p0[1]);
      const Eval e = eval_ours(basis, m.x, f, s, t);
      *tangent = (p1[0] - p0[0]) * e.d[1] + (p1[1] - p0[1]) * e.d[2];
      return e.d[0];
    };
    for (const auto& [edge, fk] : half) {
      auto it = half.find({edge.second, edge.first});
      if (it == half.end()) continue;
      for (double a : {0.1, 0.37, 0.5, 0.8}) {
        V3 t1, t2;
        const V3 x1 = at(fk.first, fk.second, a, &t1);
        const V3 x2 = at(it->second.first, it->second.second, 1 - a, &t2);
        INFO(m.name << " edge " << edge.first << "-" << edge.second << " a " << a);
        REQUIRE((x1 - x2).norm() < 1e-12);
        REQUIRE((t1 + t2).norm() < 1e-10);
      }
    }
  }
}

TEST_CASE("Loop basis: extraordinary patches need local subdivision, regular ones do not",
          "[loop]") {
  const TestMesh d = disc(7, 3, 1);
  const LoopBasis b(static_cast<int>(d.x.size()), d.t);
  REQUIRE(b.subdivision_depth(0, 0.25, 0.25) >= 1);
  REQUIRE(b.subdivision_depth(0, 1e-6, 1e-6) >= 18);
  REQUIRE(b.subdivision_depth(0, 0.0, 0.0) >= 28);  // nudged 1e-9 off the vertex
  // A face of the second ring not touching the EV is regular.
  int regular_faces = 0;
  for (int f = 0; f < b.num_faces(); ++f) regular_faces += b.subdivision_depth(f, 0.3, 0.3) == 0;
  REQUIRE(regular_faces > 0);
  BasisPoint bp;
  b.evaluate(0, 0.25, 0.25, bp);
  REQUIRE(bp.ctrl.size() == 7 + 6u);  // N + 6 control points for an EV patch
}

TEST_CASE("Loop basis rejects meshes it cannot handle", "[loop]") {
  using Tris = std::vector<Eigen::Vector3i>;
  REQUIRE_THROWS_AS(LoopBasis(3, Tris{{0, 1, 3}}), std::invalid_argument);
  REQUIRE_THROWS_AS(LoopBasis(3, Tris{{0, 1, 1}}), std::invalid_argument);
  // Edge 0-1 with three faces.
  REQUIRE_THROWS_AS(LoopBasis(5, Tris{{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}), std::invalid_argument);
  // Inconsistent orientation.
  REQUIRE_THROWS_AS(LoopBasis(4, Tris{{0, 1, 2}, {0, 1, 3}}), std::invalid_argument);
  // Two fans touching at vertex 0 (bow tie).
  REQUIRE_THROWS_AS(LoopBasis(5, Tris{{0, 1, 2}, {0, 3, 4}}), std::invalid_argument);
  BasisPoint bp;
  const LoopBasis ok(3, Tris{{0, 1, 2}});
  REQUIRE_THROWS_AS(ok.evaluate(0, 0.8, 0.5, bp), std::invalid_argument);
  REQUIRE_THROWS_AS(ok.evaluate(1, 0.2, 0.2, bp), std::invalid_argument);
  REQUIRE_NOTHROW(ok.evaluate(0, 0.2, 0.2, bp));
}
