#include "core/scene.hpp"

namespace lodstream {

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const auto& o : objects) n += meshes[o.mesh].triangle_count();
  return n;
}

size_t Scene::unique_triangle_count() const {
  size_t n = 0;
  for (const auto& m : meshes) n += m.triangle_count();
  return n;
}

size_t Scene::vertex_count() const {
  size_t n = 0;
  for (const auto& o : objects) n += meshes[o.mesh].vertex_count();
  return n;
}

Bounds Scene::bounds() const {
  Bounds b;
  for (const auto& o : objects) b.add(transform_bounds(meshes[o.mesh].bounds(), o.transform));
  return b;
}

Scene make_scene(Mesh mesh, std::string name) {
  Scene scene;
  Material material;
  material.name = "default";  // base colour: the default grey
  scene.materials.push_back(std::move(material));
  mesh.material = 0;
  scene.meshes.push_back(std::move(mesh));
  scene.objects.push_back(Object{std::move(name), glm::mat4(1.0f), 0});
  return scene;
}

}  // namespace lodstream
