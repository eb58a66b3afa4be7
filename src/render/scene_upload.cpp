#include "render/scene_upload.hpp"

#include <map>

#include "core/error.hpp"
#include "core/image.hpp"

namespace lodstream::render {

std::vector<DrawMaterial> upload_materials(Renderer& renderer, const std::vector<Material>& materials,
                                           SceneUpload& upload) {
  std::vector<DrawMaterial> draw_materials;
  std::map<std::string, TextureHandle> by_file;  // kNoTexture for files that could not be read
  std::map<const Image*, TextureHandle> by_image;
  for (const Material& material : materials) {
    DrawMaterial draw{material.base_color, kNoTexture};
    const std::string& file = material.base_color_texture;
    if (material.base_color_image) {
      auto [it, inserted] = by_image.try_emplace(material.base_color_image.get(), kNoTexture);
      if (inserted) {
        it->second = renderer.upload_texture(*material.base_color_image);
        upload.textures.push_back(it->second);
      }
      draw.texture = it->second;
    } else if (!file.empty()) {
      auto [it, inserted] = by_file.try_emplace(file, kNoTexture);
      if (inserted) {
        try {
          it->second = renderer.upload_texture(load_image(file));
          upload.textures.push_back(it->second);
        } catch (const Error& e) {
          upload.warnings.push_back("material '" + material.name + "': " + e.what() +
                                    "; drawn in its base colour");
        }
      }
      draw.texture = it->second;
    }
    draw_materials.push_back(draw);
  }
  return draw_materials;
}

SceneUpload upload_scene(Renderer& renderer, const Scene& scene) {
  SceneUpload upload;
  for (const Mesh& mesh : scene.meshes) upload.meshes.push_back(renderer.upload_mesh(mesh));
  const std::vector<DrawMaterial> materials = upload_materials(renderer, scene.materials, upload);

  for (const Object& object : scene.objects) {
    if (object.mesh >= scene.meshes.size())
      throw Error("scene object '" + object.name + "' refers to mesh " + std::to_string(object.mesh) +
                  " of " + std::to_string(scene.meshes.size()));
    const Mesh& mesh = scene.meshes[object.mesh];
    if (mesh.material >= materials.size())
      throw Error("scene mesh " + std::to_string(object.mesh) + " refers to material " +
                  std::to_string(mesh.material) + " of " + std::to_string(materials.size()));
    upload.items.push_back({upload.meshes[object.mesh], object.transform, materials[mesh.material]});
    upload.triangles += mesh.triangle_count();
  }
  return upload;
}

void release_scene(Renderer& renderer, const SceneUpload& upload) {
  for (MeshHandle mesh : upload.meshes) renderer.release_mesh(mesh);
  for (TextureHandle texture : upload.textures) renderer.release_texture(texture);
}

}  // namespace lodstream::render
