#include "io/assimp_reader.hpp"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>

#include "core/error.hpp"
#include "io/mapped_file.hpp"

namespace lodstream {

namespace {

glm::mat4 to_glm(const aiMatrix4x4& m) {
  // assimp matrices are row-major (a1..a4 is the first row); glm is column-major.
  glm::mat4 r;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) r[col][row] = m[row][col];
  return r;
}

// True when the glTF's JSON names KHR_mesh_quantization (.gltf: the whole file; .glb: its JSON chunk).
bool uses_mesh_quantization(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".gltf" && ext != ".glb") return false;
  MappedFile map(file);
  std::string_view json(map.data(), map.size());
  if (ext == ".glb" && map.size() >= 20) {
    uint32_t chunk_length = 0;
    std::memcpy(&chunk_length, map.data() + 12, 4);
    json = std::string_view(map.data() + 20, std::min<size_t>(chunk_length, map.size() - 20));
  }
  return json.find("KHR_mesh_quantization") != std::string_view::npos;
}

std::string texture_of(const aiMaterial* m, const std::filesystem::path& dir, const std::string& file) {
  for (aiTextureType type : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
    aiString path;
    if (m->GetTextureCount(type) == 0 || m->GetTexture(type, 0, &path) != AI_SUCCESS) continue;
    std::string name = path.C_Str();
    if (name.empty()) continue;
    if (name[0] == '*') {
      std::fprintf(stderr,
                   "lodstream: warning: %s: embedded textures are not supported; material '%s' drops one\n",
                   file.c_str(), m->GetName().C_Str());
      return {};
    }
    std::replace(name.begin(), name.end(), '\\', '/');
    std::filesystem::path p(name);
    if (p.is_relative()) p = dir / p;
    return std::filesystem::absolute(p).lexically_normal().string();
  }
  return {};
}

}  // namespace

Scene read_with_assimp(const std::filesystem::path& path) {
  const std::string file = path.string();
  if (uses_mesh_quantization(path))
    throw Error(file +
                ": uses KHR_mesh_quantization, which assimp 5.2 misreads; export it with float positions "
                "(for example gltfpack -noq)");
  Assimp::Importer importer;
  // Only lines and points are removed; welding, normals and validation are lodstream's own (weld.hpp).
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* ai = importer.ReadFile(file, aiProcess_Triangulate | aiProcess_SortByPType);
  if (!ai) throw Error(file + ": " + importer.GetErrorString());
  if (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) throw Error(file + ": assimp read an incomplete scene");
  if (!ai->mRootNode) throw Error(file + ": no scene graph");

  const std::filesystem::path dir =
      path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  Scene scene;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
    const aiMaterial* m = ai->mMaterials[i];
    Material mat;
    mat.name = m->GetName().C_Str();
    aiColor4D color;
    if (m->Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS ||
        m->Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS)
      mat.base_color = glm::vec4(color.r, color.g, color.b, color.a);
    float opacity = 1.0f;
    if (m->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && opacity < mat.base_color.a)
      mat.base_color.a = opacity;
    mat.base_color_texture = texture_of(m, dir, file);
    scene.materials.push_back(std::move(mat));
  }
  if (scene.materials.empty()) scene.materials.emplace_back().name = "default";  // base colour 0.8 grey

  // assimp mesh i → scene mesh (or none when it has no triangles).
  std::vector<int64_t> mesh_of(ai->mNumMeshes, -1);
  for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
    const aiMesh* am = ai->mMeshes[i];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || am->mNumFaces == 0) continue;
    Mesh mesh;
    mesh.positions.resize(am->mNumVertices);
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      mesh.positions[v] = glm::vec3(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    if (am->mNormals) {
      mesh.normals.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v)
        mesh.normals[v] = glm::vec3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
    }
    if (am->mTextureCoords[0]) {
      mesh.uvs.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v)
        mesh.uvs[v] = glm::vec2(am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y);
    }
    if (am->mColors[0]) {
      mesh.colors.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v) {
        const aiColor4D& c = am->mColors[0][v];
        mesh.colors[v] = glm::vec4(c.r, c.g, c.b, c.a);
      }
    }
    mesh.indices.reserve(3 * am->mNumFaces);
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.indices.insert(mesh.indices.end(), face.mIndices, face.mIndices + 3);
    }
    mesh.material = am->mMaterialIndex < scene.materials.size() ? am->mMaterialIndex : 0;
    mesh_of[i] = static_cast<int64_t>(scene.meshes.size());
    scene.meshes.push_back(std::move(mesh));
  }

  // Depth-first over the node tree with an explicit stack (a hostile file may nest deeply).
  struct Item {
    const aiNode* node;
    glm::mat4 parent;
    size_t depth;
  };
  std::vector<Item> stack{{ai->mRootNode, glm::mat4(1.0f), 0}};
  while (!stack.empty()) {
    Item item = stack.back();
    stack.pop_back();
    if (item.depth > 10000) throw Error(file + ": node hierarchy deeper than 10000");
    const glm::mat4 world = item.parent * to_glm(item.node->mTransformation);
    for (unsigned k = 0; k < item.node->mNumMeshes; ++k) {
      unsigned i = item.node->mMeshes[k];
      if (i >= ai->mNumMeshes || mesh_of[i] < 0) continue;
      std::string name = item.node->mName.C_Str();
      if (name.empty()) name = ai->mMeshes[i]->mName.C_Str();
      if (item.node->mNumMeshes > 1) name += "#" + std::to_string(k);
      scene.objects.push_back(Object{std::move(name), world, static_cast<uint32_t>(mesh_of[i])});
    }
    for (unsigned c = item.node->mNumChildren; c-- > 0;)
      if (item.node->mChildren[c]) stack.push_back({item.node->mChildren[c], world, item.depth + 1});
  }
  return scene;
}

}  // namespace lodstream
