#include "io/shell_mesh_reader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "io/assimp_mesh.h"
#include "io/mesh_reader.h"

namespace shellmpm {

namespace {

using Range = std::pair<std::size_t, std::size_t>;  // [first, last) triangle

/// Collects meshes like read_mesh's collector and records, per name, the triangle
/// ranges its meshes and nodes contributed (a DFS appends each subtree contiguously).
struct Collector {
  const aiScene* scene;
  ShellMesh mesh;
  bool all_have_uvs = true;
  std::map<std::string, std::vector<Range>> named;

  void name_range(const aiString& name, std::size_t first) {
    const std::string s = name.C_Str();
    if (s.empty() || s == "defaultobject" || first == mesh.triangles.size()) return;
    named[s].emplace_back(first, mesh.triangles.size());
  }

  void visit(const aiNode* node, const aiMatrix4x4& parent, bool is_root) {
    const aiMatrix4x4 m = parent * node->mTransformation;
    const std::size_t first = mesh.triangles.size();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) add(scene->mMeshes[node->mMeshes[i]], m);
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], m, false);
    if (!is_root || node->mNumMeshes > 0) name_range(node->mName, first);
  }

  void add(const aiMesh* am, const aiMatrix4x4& m) {
    const std::size_t first = mesh.triangles.size();
    if (detail::append_triangles(am, m, mesh.vertices, mesh.uvs, mesh.triangles, all_have_uvs))
      name_range(am->mName, first);
  }
};

struct PositionKey {
  std::uint64_t bits[3];
  bool operator==(const PositionKey& o) const {
    return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2];
  }
};

struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint64_t b : k.bits) h = (h ^ b) * 1099511628211ull + (h >> 29);
    return static_cast<std::size_t>(h);
  }
};

PositionKey key_of(const Vec3d& p) {
  PositionKey k;
  for (int i = 0; i < 3; ++i) {
    const double x = p[i] + 0.0;  // -0 becomes +0
    std::memcpy(&k.bits[i], &x, sizeof x);
  }
  return k;
}

}  // namespace

ShellMesh read_shell_mesh(const std::string& path, const std::string& where) {
  Assimp::Importer importer;
  const aiScene* scene = detail::import_triangles(importer, path, where);

  Collector c{scene, {}, true, {}};
  c.visit(scene->mRootNode, aiMatrix4x4(), true);
  ShellMesh& in = c.mesh;
  if (!c.all_have_uvs) in.uvs.clear();
  if (in.triangles.empty())
    throw detail::user_error_at(where, "mesh '" + path + "' has no triangles");
  for (std::size_t v = 0; v < in.vertices.size(); ++v)
    if (!in.vertices[v].allFinite()) {
      std::ostringstream os;
      os << "mesh '" << path << "' has a non-finite coordinate at vertex " << v << " ("
         << in.vertices[v].transpose() << ")";
      throw detail::user_error_at(where, os.str());
    }

  // One control point per position, numbered in order of first occurrence; and one UV
  // entry per distinct (control point, UV) pair, numbered the same way, so that a mesh
  // without seams has uv index == control point index.
  ShellMesh out;
  const bool has_uvs = !in.uvs.empty();
  std::vector<int> remap(in.vertices.size()), uv_remap(has_uvs ? in.vertices.size() : 0);
  std::unordered_map<PositionKey, int, PositionHash> first_at;
  std::unordered_map<PositionKey, int, PositionHash> uv_at;  // (point, u, v) bits -> uv index
  first_at.reserve(in.vertices.size());
  for (std::size_t v = 0; v < in.vertices.size(); ++v) {
    const auto [it, inserted] =
        first_at.emplace(key_of(in.vertices[v]), static_cast<int>(out.vertices.size()));
    if (inserted) out.vertices.push_back(in.vertices[v]);
    remap[v] = it->second;
    if (!has_uvs) continue;
    PositionKey k = key_of(Vec3d(in.uvs[v].x(), in.uvs[v].y(), 0.0));
    k.bits[2] = static_cast<std::uint64_t>(it->second);
    const auto [u, uv_new] = uv_at.emplace(k, static_cast<int>(out.uvs.size()));
    if (uv_new) out.uvs.push_back(in.uvs[v]);
    uv_remap[v] = u->second;
  }
  out.triangles.reserve(in.triangles.size());
  if (has_uvs) out.uv_triangles.reserve(in.triangles.size());
  for (std::size_t t = 0; t < in.triangles.size(); ++t) {
    const Eigen::Vector3i& ft = in.triangles[t];
    const Eigen::Vector3i f(remap[ft[0]], remap[ft[1]], remap[ft[2]]);
    if (has_uvs) out.uv_triangles.emplace_back(uv_remap[ft[0]], uv_remap[ft[1]], uv_remap[ft[2]]);
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) {
      std::ostringstream os;
      os << "mesh '" << path << "': triangle " << t
         << " has two corners at the same position (a shell needs one control point per "
            "position; remove the degenerate triangle)";
      throw detail::user_error_at(where, os.str());
    }
    out.triangles.push_back(f);
  }

  for (const auto& [name, ranges] : c.named) {
    std::vector<int>& g = out.groups[name];
    for (const Range& r : ranges)
      for (std::size_t t = r.first; t < r.second; ++t)
        for (int k = 0; k < 3; ++k) g.push_back(out.triangles[t][k]);
    std::sort(g.begin(), g.end());
    g.erase(std::unique(g.begin(), g.end()), g.end());
  }
  return out;
}

}  // namespace shellmpm
