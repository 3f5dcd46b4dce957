#include "sim/shell/mesh_check.h"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

namespace shellmpm {

const char* to_string(MeshProblemKind kind) {
  switch (kind) {
    case MeshProblemKind::NonManifoldEdge:
      return "non-manifold edge";
    case MeshProblemKind::NonManifoldVertex:
      return "non-manifold vertex";
    case MeshProblemKind::DuplicateVertex:
      return "duplicate vertex";
    case MeshProblemKind::ZeroAreaFace:
      return "zero-area face";
    case MeshProblemKind::InconsistentOrientation:
      return "inconsistent orientation";
    case MeshProblemKind::DegenerateIndex:
      return "degenerate index";
    case MeshProblemKind::IsolatedVertex:
      return "isolated vertex";
  }
  return "unknown";
}

namespace {

std::string list(const char* what, const std::vector<int>& ids) {
  std::ostringstream os;
  os << what << (ids.size() > 1 ? "s " : " ");
  for (std::size_t i = 0; i < ids.size() && i < 8; ++i) os << (i ? ", " : "") << ids[i];
  if (ids.size() > 8) os << ", ... (" << ids.size() << " in all)";
  return os.str();
}

MeshProblem make(MeshProblemKind kind, std::vector<int> faces, std::vector<int> vertices,
                 const std::string& detail) {
  std::ostringstream os;
  os << to_string(kind);
  if (!faces.empty()) os << ": " << list("face", faces);
  if (!vertices.empty()) os << (faces.empty() ? ": " : "; ") << list("vertex", vertices);
  if (!detail.empty()) os << " (" << detail << ")";
  return MeshProblem{kind, std::move(faces), std::move(vertices), os.str()};
}

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

/// Per face: indices in range and distinct (else a DegenerateIndex problem, valid 0),
/// corners not collinear (else a ZeroAreaFace problem).
std::vector<char> check_faces(const std::vector<Vec3d>& vertices,
                              const std::vector<Eigen::Vector3i>& tris,
                              std::vector<MeshProblem>& degenerate,
                              std::vector<MeshProblem>& zero_area) {
  const int nv = static_cast<int>(vertices.size());
  const int nf = static_cast<int>(tris.size());
  std::vector<char> valid(nf, 1);
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = tris[f];
    std::ostringstream os;
    os << "indices (" << t[0] << ", " << t[1] << ", " << t[2] << ")";
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || t[k] >= nv) valid[f] = 0;
    if (!valid[f]) {
      os << " out of range [0, " << nv << ")";
      degenerate.push_back(make(MeshProblemKind::DegenerateIndex, {f}, {}, os.str()));
      continue;
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      valid[f] = 0;
      os << " repeat a vertex";
      degenerate.push_back(make(MeshProblemKind::DegenerateIndex, {f}, {}, os.str()));
      continue;
    }
    const Vec3d& a = vertices[t[0]];
    const Vec3d& b = vertices[t[1]];
    const Vec3d& c = vertices[t[2]];
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const double twice_area = (b - a).cross(c - a).norm();
    if (longest == 0 || twice_area <= 1e-12 * longest)
      zero_area.push_back(make(MeshProblemKind::ZeroAreaFace, {f}, {t[0], t[1], t[2]},
                               "its corners are collinear or coincide"));
  }
  return valid;
}

/// Edges shared by more than two valid faces, or by two running the same way.
void check_edges(const std::vector<Eigen::Vector3i>& tris, const std::vector<char>& valid,
                 std::vector<MeshProblem>& nonmanifold_edge,
                 std::vector<MeshProblem>& orientation) {
  // Undirected key -> faces using it, with direction.
  std::map<std::pair<int, int>, std::vector<std::pair<int, bool>>> edges;
  for (int f = 0; f < static_cast<int>(tris.size()); ++f) {
    if (!valid[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const int a = tris[f][k], b = tris[f][(k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].emplace_back(f, a < b);
    }
  }
  for (const auto& [e, fs] : edges) {
    std::vector<int> faces;
    for (const auto& fd : fs) faces.push_back(fd.first);
    if (fs.size() > 2) {
      nonmanifold_edge.push_back(make(MeshProblemKind::NonManifoldEdge, faces, {e.first, e.second},
                                      std::to_string(fs.size()) + " faces share the edge"));
    } else if (fs.size() == 2 && fs[0].second == fs[1].second) {
      orientation.push_back(make(MeshProblemKind::InconsistentOrientation, faces,
                                 {e.first, e.second},
                                 "both faces run along the edge in the same direction"));
    }
  }
}

/// Vertex fans: faces around v joined through shared edges (v, x) must form one fan.
std::vector<MeshProblem> check_fans(const std::vector<Eigen::Vector3i>& tris,
                                    const std::vector<std::vector<int>>& vfaces) {
  std::vector<MeshProblem> nonmanifold_vertex;
  for (int v = 0; v < static_cast<int>(vfaces.size()); ++v) {
    const std::vector<int>& fs = vfaces[v];
    if (fs.size() < 2) continue;
    std::vector<int> parent(fs.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::map<int, int> first_with;  // neighbour x -> first face index using edge (v, x)
    for (std::size_t i = 0; i < fs.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const int x = tris[fs[i]][k];
        if (x == v) continue;
        auto it = first_with.find(x);
        if (it == first_with.end())
          first_with.emplace(x, static_cast<int>(i));
        else
          parent[find_root(parent, static_cast<int>(i))] = find_root(parent, it->second);
      }
    int fans = 0;
    for (std::size_t i = 0; i < fs.size(); ++i)
      fans += find_root(parent, static_cast<int>(i)) == static_cast<int>(i);
    if (fans > 1)
      nonmanifold_vertex.push_back(
          make(MeshProblemKind::NonManifoldVertex, fs, {v},
               std::to_string(fans) + " separate fans of faces meet there"));
  }
  return nonmanifold_vertex;
}

/// Groups of exactly coincident vertices, ordered by their first vertex.
std::vector<MeshProblem> check_duplicates(const std::vector<Vec3d>& vertices) {
  const int nv = static_cast<int>(vertices.size());
  std::vector<MeshProblem> duplicate;
  std::vector<int> order(nv);
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](int i) {
    return std::array<double, 3>{vertices[i].x(), vertices[i].y(), vertices[i].z()};
  };
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return key(a) != key(b) ? key(a) < key(b) : a < b; });
  for (int i = 0; i < nv;) {
    int j = i + 1;
    while (j < nv && key(order[j]) == key(order[i])) ++j;
    if (j - i > 1) {
      std::vector<int> group(order.begin() + i, order.begin() + j);
      std::ostringstream os;
      os << "all at (" << vertices[group[0]].x() << ", " << vertices[group[0]].y() << ", "
         << vertices[group[0]].z() << "); merge them to connect the faces";
      duplicate.push_back(make(MeshProblemKind::DuplicateVertex, {}, group, os.str()));
    }
    i = j;
  }
  std::sort(duplicate.begin(), duplicate.end(), [](const MeshProblem& a, const MeshProblem& b) {
    return a.vertices[0] < b.vertices[0];
  });
  return duplicate;
}

}  // namespace

std::vector<MeshProblem> check_shell_mesh(const std::vector<Vec3d>& vertices,
                                          const std::vector<Eigen::Vector3i>& tris) {
  const int nv = static_cast<int>(vertices.size());
  std::vector<MeshProblem> degenerate, zero_area, nonmanifold_edge, orientation;
  const std::vector<char> valid = check_faces(vertices, tris, degenerate, zero_area);
  check_edges(tris, valid, nonmanifold_edge, orientation);
  std::vector<std::vector<int>> vfaces(nv);  // valid faces around each vertex
  for (int f = 0; f < static_cast<int>(tris.size()); ++f)
    if (valid[f])
      for (int k = 0; k < 3; ++k) vfaces[tris[f][k]].push_back(f);
  std::vector<MeshProblem> nonmanifold_vertex = check_fans(tris, vfaces);
  std::vector<MeshProblem> duplicate = check_duplicates(vertices);
  std::vector<MeshProblem> isolated;
  for (int v = 0; v < nv; ++v)
    if (vfaces[v].empty())
      isolated.push_back(make(MeshProblemKind::IsolatedVertex, {}, {v}, "used by no face"));

  std::vector<MeshProblem> out;
  for (auto* group : {&nonmanifold_edge, &nonmanifold_vertex, &duplicate, &zero_area, &orientation,
                      &degenerate, &isolated})
    for (MeshProblem& p : *group) out.push_back(std::move(p));
  return out;
}

}  // namespace shellmpm
