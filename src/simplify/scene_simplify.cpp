#include "simplify/scene_simplify.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::simplify {
namespace {
// Largest factor by which the transform stretches a length.
double max_scale(const glm::mat4& m) {
  return std::max({glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
}
}  // namespace

SceneResult simplify_scene(const Scene& scene, size_t target_triangles, double max_error,
                           const Options& options) {
  SceneResult out;
  out.input_triangles = scene.triangle_count();
  out.scene.materials = scene.materials;
  out.scene.objects = scene.objects;
  std::vector<double> scale(scene.meshes.size(), 0.0);
  for (const Object& o : scene.objects)
    if (o.mesh < scale.size()) scale[o.mesh] = std::max(scale[o.mesh], max_scale(o.transform));
  const double ratio = target_triangles > 0 && out.input_triangles > 0
                           ? double(target_triangles) / double(out.input_triangles)
                           : (std::isfinite(max_error) ? 0.0 : 1.0);
  std::vector<size_t> uses(scene.meshes.size(), 0);
  for (const Object& ob : scene.objects)
    if (ob.mesh < uses.size()) ++uses[ob.mesh];
  Options o = options;
  size_t done = 0, total = scene.unique_triangle_count();
  std::vector<Result> results;
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& mesh = scene.meshes[i];
    o.target_triangles = size_t(std::llround(double(mesh.triangle_count()) * ratio));
    o.max_error = scale[i] > 0 ? max_error / scale[i] : max_error;
    if (options.progress && total > 0)
      o.progress = [&, base = done, n = mesh.triangle_count()](float f) {
        options.progress(float((double(base) + f * double(n)) / double(total)));
      };
    results.push_back(simplify_mesh(mesh, o));
    done += mesh.triangle_count();
  }
  auto drawn = [&](size_t i) { return results[i].mesh.triangle_count() * uses[i]; };
  size_t output = 0, flexible = 0;
  for (size_t i = 0; i < results.size(); ++i) {
    output += drawn(i);
    if (results[i].target_reached) flexible += drawn(i);
  }
  // With topology change allowed, meshes that met their own target take up, in proportion, what the others
  // (tiny parts that keep a triangle or two) could not: one more round at lower targets.
  if (options.allow_topology_change && target_triangles > 0 &&
      output > target_triangles + target_triangles / 100 && flexible > 0) {
    const double excess = double(output - target_triangles);
    o.progress = nullptr;
    for (size_t i = 0; i < results.size(); ++i) {
      if (!results[i].target_reached || uses[i] == 0) continue;
      const size_t now = results[i].mesh.triangle_count();
      const size_t cut = size_t(std::ceil(excess * double(drawn(i)) / double(flexible) / double(uses[i])));
      o.target_triangles = now > cut ? now - cut : 0;
      o.max_error = scale[i] > 0 ? max_error / scale[i] : max_error;
      results[i] = simplify_mesh(scene.meshes[i], o);
    }
  }
  for (size_t i = 0; i < results.size(); ++i) {
    out.target_reached = out.target_reached && results[i].target_reached;
    out.error_bound = std::max(out.error_bound, results[i].error_bound * scale[i]);
    out.scene.meshes.push_back(std::move(results[i].mesh));
  }
  out.output_triangles = out.scene.triangle_count();
  // Meshes given a target below what they can reach may be made up for by others.
  if (target_triangles > 0 && out.output_triangles <= target_triangles + target_triangles / 100)
    out.target_reached = true;
  return out;
}

}  // namespace lodstream::simplify
