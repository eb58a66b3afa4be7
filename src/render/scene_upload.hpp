// A whole core Scene onto a Renderer: every mesh once, every material's texture once, one draw item per
// object.
#pragma once

#include <string>
#include <vector>

#include "core/scene.hpp"
#include "render/renderer.hpp"

namespace lodstream::render {

struct SceneUpload {
  std::vector<MeshHandle> meshes;       // meshes[i] holds Scene::meshes[i]
  std::vector<TextureHandle> textures;  // every texture uploaded, once per distinct file
  std::vector<DrawItem> items;          // one per Scene::objects entry, in order
  size_t triangles = 0;                 // as drawn (instances counted each time)
  std::vector<std::string> warnings;    // one line each, e.g. a texture file that cannot be read
};

// Uploads `scene` to `renderer`. A base-colour texture that cannot be read (missing or not an image) gives a
// warning and the material falls back to its base colour; objects referring to a missing mesh or material are
// a lodstream::Error (the Scene is malformed). Cost: the meshes' upload plus decoding each texture file once.
SceneUpload upload_scene(Renderer& renderer, const Scene& scene);

// Uploads the base-colour texture of each of `materials` (once per distinct file; handles appended to
// `upload.textures`, unreadable files to `upload.warnings`, those materials falling back to their base
// colour) and returns their draw materials, in order. What upload_scene() does for a scene's materials.
std::vector<DrawMaterial> upload_materials(Renderer& renderer, const std::vector<Material>& materials,
                                           SceneUpload& upload);

// Releases what upload_scene() uploaded (its meshes and textures); its items must not be drawn again.
void release_scene(Renderer& renderer, const SceneUpload& upload);

}  // namespace lodstream::render
