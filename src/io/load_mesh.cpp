// Mesh loading through assimp: one well-kept reader for OBJ, OFF, STL, PLY and more.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <system_error>

#include "tightbvh/mesh.hpp"

namespace tightbvh {

Mesh load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(name + ": no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name + ": not a regular file");

  Assimp::Importer importer;
  // No JoinIdenticalVertices: we keep the file's vertices and indices as they are, so that
  // errors name the file's own indices. Triangulate splits polygons; points and lines are dropped.
  const aiScene* scene = importer.ReadFile(name, aiProcess_Triangulate | aiProcess_SortByPType);
  if (scene == nullptr) throw InputError(name + ": cannot read mesh: " + importer.GetErrorString());

  Mesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* sub = scene->mMeshes[m];
    if ((sub->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < sub->mNumVertices; ++v) {
      const aiVector3D& p = sub->mVertices[v];
      mesh.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < sub->mNumFaces; ++f) {
      const aiFace& face = sub->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  validate(mesh, name);
  return mesh;
}

}  // namespace tightbvh
