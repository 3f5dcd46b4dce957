// Shared by the assimp-based readers (io/mesh_reader.cpp, io/shell_mesh_reader.cpp):
// turning one aiMesh into triangles. Internal to io/; includes assimp.
#pragma once
#include <assimp/scene.h>

#include <vector>

#include "sim/core/types.h"

namespace shellmpm {
namespace detail {

/// Appends the triangles of `am`, its vertices transformed by `m`. Meshes without
/// triangles add nothing and return false; faces that are not triangles are skipped.
/// UVs (channel 0) are appended only while every mesh so far had them: a mesh without
/// them clears `all_have_uvs`.
inline bool append_triangles(const aiMesh* am, const aiMatrix4x4& m, std::vector<Vec3d>& vertices,
                             std::vector<Eigen::Vector2d>& uvs,
                             std::vector<Eigen::Vector3i>& triangles, bool& all_have_uvs) {
  if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) return false;
  const int offset = static_cast<int>(vertices.size());
  for (unsigned v = 0; v < am->mNumVertices; ++v) {
    const aiVector3D p = m * am->mVertices[v];
    vertices.emplace_back(p.x, p.y, p.z);
  }
  all_have_uvs = all_have_uvs && am->HasTextureCoords(0);
  if (all_have_uvs)
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      uvs.emplace_back(am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y);
  for (unsigned f = 0; f < am->mNumFaces; ++f) {
    const aiFace& face = am->mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines
    triangles.emplace_back(offset + static_cast<int>(face.mIndices[0]),
                           offset + static_cast<int>(face.mIndices[1]),
                           offset + static_cast<int>(face.mIndices[2]));
  }
  return true;
}

}  // namespace detail
}  // namespace shellmpm
