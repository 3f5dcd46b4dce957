#include "io/mesh_reader.h"

#include "io/assimp_mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace shellmpm {

namespace detail {
UserError user_error_at(const std::string& where, const std::string& message) {
  // Split "file:line: key" / "file: key" / "file". The file part may itself hold ':'.
  const auto sep = where.find(": ");
  std::string head = sep == std::string::npos ? where : where.substr(0, sep);
  const std::string key = sep == std::string::npos ? "" : where.substr(sep + 2);
  int line = 0;
  const auto colon = head.rfind(':');
  if (colon != std::string::npos && colon + 1 < head.size()) {
    const std::string digits = head.substr(colon + 1);
    bool all_digits = digits.size() < 9;
    for (char c : digits) all_digits = all_digits && std::isdigit(static_cast<unsigned char>(c));
    if (all_digits) {
      line = std::stoi(digits);
      head = head.substr(0, colon);
    }
  }
  return UserError(head, line, key, message);
}
}  // namespace detail

namespace {

struct Collector {
  const aiScene* scene;
  TriMesh mesh;
  bool all_have_uvs = true;
  std::size_t meshes_used = 0;

  void visit(const aiNode* node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 m = parent * node->mTransformation;
    for (unsigned i = 0; i < node->mNumMeshes; ++i) add(scene->mMeshes[node->mMeshes[i]], m);
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], m);
  }

  void add(const aiMesh* am, const aiMatrix4x4& m) {
    if (detail::append_triangles(am, m, mesh.vertices, mesh.uvs, mesh.triangles, all_have_uvs))
      ++meshes_used;
  }
};

}  // namespace

namespace detail {

const aiScene* import_triangles(Assimp::Importer& importer, const std::string& path,
                                const std::string& where) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw user_error_at(where, "mesh file '" + path + "' does not exist or is not a file");
  // Keep only what we use: no normals, no materials, no cameras or lights.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (!scene || !scene->mRootNode || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
    std::string why = importer.GetErrorString();
    // aiProcess_SortByPType drops point and line meshes; say so plainly.
    if (why.find("No meshes remaining") != std::string::npos)
      why = "it has no triangles (only points or lines)";
    throw user_error_at(where, "cannot read mesh '" + path + "': " + why);
  }
  return scene;
}

}  // namespace detail

TriMesh read_mesh(const std::string& path, const std::string& where) {
  Assimp::Importer importer;
  const aiScene* scene = detail::import_triangles(importer, path, where);

  Collector c{scene, {}, true, 0};
  c.visit(scene->mRootNode, aiMatrix4x4());
  if (!c.all_have_uvs) c.mesh.uvs.clear();
  if (c.mesh.triangles.empty())
    throw detail::user_error_at(where, "mesh '" + path + "' has no triangles");
  for (std::size_t v = 0; v < c.mesh.vertices.size(); ++v)
    if (!c.mesh.vertices[v].allFinite()) {
      std::ostringstream os;
      os << "mesh '" << path << "' has a non-finite coordinate at vertex " << v << " ("
         << c.mesh.vertices[v].transpose() << ")";
      throw detail::user_error_at(where, os.str());
    }
  return c.mesh;
}

}  // namespace shellmpm
