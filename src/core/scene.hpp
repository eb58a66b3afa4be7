// Scene: materials, meshes and objects. An object places one mesh with a transform; several objects that
// reference the same mesh are instances of it (stored once, drawn as often as they are referenced).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/image.hpp"
#include "core/mesh.hpp"

namespace lodstream {

struct Material {
  std::string name;
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // linear RGBA
  std::string base_color_texture;                // absolute path of an image file, or empty
  // The texture already decoded (an image embedded in a package); when set, it is drawn instead of the file.
  std::shared_ptr<const Image> base_color_image;
};

struct Object {
  std::string name;
  glm::mat4 transform{1.0f};  // object to world
  uint32_t mesh = 0;          // index into Scene::meshes
};

struct Scene {
  std::vector<Material> materials;  // at least one when there are meshes
  std::vector<Mesh> meshes;
  std::vector<Object> objects;

  // Triangles as drawn: an instanced mesh counts once per object that references it.
  size_t triangle_count() const;
  // Triangles stored: each mesh counts once.
  size_t unique_triangle_count() const;
  size_t vertex_count() const;  // as drawn, like triangle_count()
  // World-space bounds of every object.
  Bounds bounds() const;
};

// A scene of one object holding `mesh` with a default material.
Scene make_scene(Mesh mesh, std::string name = "mesh");

}  // namespace lodstream
