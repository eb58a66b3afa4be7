// Simplification of a whole scene: each stored mesh once (instances share it), to a triangle target spread
// over the meshes in proportion to their drawn triangles, or to an error bound in world units.
#pragma once

#include "core/scene.hpp"
#include "simplify/simplify.hpp"

namespace lodstream::simplify {

struct SceneResult {
  Scene scene;
  size_t input_triangles = 0;   // as drawn
  size_t output_triangles = 0;  // as drawn
  double error_bound = 0.0;     // world units: max over objects of mesh bound x the transform's largest scale
  bool target_reached = true;
};

// `target_triangles` counts triangles as drawn (0 = none); `max_error` is in world units. Every other field
// of `options` applies to every mesh. Cost: the sum of simplify_mesh over the stored meshes.
SceneResult simplify_scene(const Scene& scene, size_t target_triangles, double max_error,
                           const Options& options);

}  // namespace lodstream::simplify
