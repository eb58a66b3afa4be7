#include "scene_bounds.hpp"

namespace lodstream::cli {

Bounds world_bounds(const package::PackageScene& scene) {
  Bounds b;
  for (const package::ObjectRecord& o : scene.objects)
    b.add(transform_bounds(scene.representations[o.representation].bounds, o.transform));
  return b;
}

}  // namespace lodstream::cli
