#include "measure/world_surface.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "core/error.hpp"

namespace lodstream {

void append_world_surface(const Mesh& mesh, const glm::mat4& transform, Mesh& surface,
                          const std::string& what) {
  constexpr uint32_t unmapped = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> remap(mesh.positions.size(), unmapped);
  const size_t index_count = mesh.indices.size() - mesh.indices.size() % 3;  // whole triangles only
  surface.indices.reserve(surface.indices.size() + index_count);
  for (size_t i = 0; i < index_count; ++i) {
    uint32_t v = mesh.indices[i];
    if (v >= mesh.positions.size())
      throw Error(what + ": triangle " + std::to_string(i / 3) + " references vertex " + std::to_string(v) +
                  " of " + std::to_string(mesh.positions.size()));
    if (remap[v] == unmapped) {
      glm::vec3 p = glm::vec3(transform * glm::vec4(mesh.positions[v], 1.0f));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error(what + ": vertex " + std::to_string(v) + " has a non-finite position");
      remap[v] = uint32_t(surface.positions.size());
      surface.positions.push_back(p);
    }
    surface.indices.push_back(remap[v]);
  }
}

Mesh world_surface(const Scene& scene) {
  Mesh surface;
  for (const Object& object : scene.objects) {
    if (object.mesh >= scene.meshes.size())
      throw Error("object '" + object.name + "' references mesh " + std::to_string(object.mesh) + " of " +
                  std::to_string(scene.meshes.size()));
    append_world_surface(scene.meshes[object.mesh], object.transform, surface,
                         "object '" + object.name + "'");
  }
  return surface;
}

}  // namespace lodstream
