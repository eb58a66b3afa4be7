#include "hierarchy/hlod.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "hierarchy/bounding_sphere.hpp"
#include "hierarchy/radii_floor.hpp"
#include "simplify/simplify.hpp"

namespace lodstream::hierarchy {
namespace {

// The BVH's shape before proxies: nodes with their objects, children and parent.
struct Builder {
  std::span<const HlodObject> objects;
  const HlodOptions& options;
  Hlod hlod;

  glm::vec3 centre(uint32_t o) const { return objects[o].bounds.center(); }

  // Splits `ids` in two at the median centre along the longest axis of the centres' extent.
  std::pair<std::vector<uint32_t>, std::vector<uint32_t>> halve(std::vector<uint32_t> ids) const {
    Bounds extent;
    for (uint32_t o : ids) extent.add(centre(o));
    const glm::vec3 size = extent.max - extent.min;
    const int axis = size.x >= size.y && size.x >= size.z ? 0 : (size.y >= size.z ? 1 : 2);
    const auto middle = ids.begin() + ptrdiff_t(ids.size() / 2);
    std::nth_element(ids.begin(), middle, ids.end(), [&](uint32_t a, uint32_t b) {
      return std::make_pair(centre(a)[axis], a) < std::make_pair(centre(b)[axis], b);
    });
    return {std::vector<uint32_t>(ids.begin(), middle), std::vector<uint32_t>(middle, ids.end())};
  }

  // Breadth-first: parents get lower ids than their children.
  void build(std::vector<uint32_t> all) {
    std::vector<std::vector<uint32_t>> parts{std::move(all)};
    std::vector<uint32_t> parent_of{kNoHlodNode};
    for (size_t i = 0; i < parts.size(); ++i) {
      HlodNode node;
      node.parent = parent_of[i];
      node.objects = parts[i];
      std::sort(node.objects.begin(), node.objects.end());
      const uint32_t id = uint32_t(hlod.nodes.size());
      if (node.parent != kNoHlodNode) hlod.nodes[node.parent].children.push_back(id);
      if (parts[i].size() > options.leaf_objects) {
        std::vector<std::vector<uint32_t>> split{parts[i]};
        while (split.size() < std::max<size_t>(2, options.branching)) {
          auto largest = std::max_element(split.begin(), split.end(),
                                          [](const auto& a, const auto& b) { return a.size() < b.size(); });
          if (largest->size() <= 1) break;
          auto [a, b] = halve(std::move(*largest));
          *largest = std::move(a);
          split.push_back(std::move(b));
        }
        for (auto& part : split) {
          parts.push_back(std::move(part));
          parent_of.push_back(id);
        }
      }
      hlod.nodes.push_back(std::move(node));
    }
    hlod.root = 0;
  }
};

// How a proxy keeps the look of what it merges (hlod.hpp, HlodOptions::material_colors): one material for
// all of its parts keeps that material, the parts' UVs (when every part has them) and colours; several
// materials become `mixed_material` with each part's base colour (times its vertex colours) as vertex
// colours.
struct ProxyLook {
  uint32_t material = 0;
  bool uvs = false, colors = false, bake_material = false;
};

ProxyLook proxy_look(const std::vector<const Mesh*>& parts, const HlodOptions& options) {
  ProxyLook look;
  std::map<uint32_t, size_t> per_material;
  bool all_uvs = true, any_colors = false;
  for (const Mesh* part : parts) {
    if (part->triangle_count() == 0) continue;
    per_material[part->material] += part->triangle_count();
    all_uvs = all_uvs && part->has_uvs();
    any_colors = any_colors || part->has_colors();
  }
  if (per_material.empty()) return look;
  look.material =
      std::max_element(per_material.begin(), per_material.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  if (per_material.size() == 1) {
    look.uvs = all_uvs;
    look.colors = any_colors;
  } else if (!options.material_colors.empty()) {
    look.material = options.mixed_material;
    look.colors = look.bake_material = true;
  }  // else: the most used material, positions and normals only
  return look;
}

// Appends `part` (world space) to `merged` with the attributes `look` keeps; normals computed where absent.
void append(Mesh& merged, const Mesh& part, const ProxyLook& look, const HlodOptions& options) {
  Mesh m;
  m.positions = part.positions;
  m.indices = part.indices;
  if (part.has_normals())
    m.normals = part.normals;
  else
    compute_smooth_normals(m);
  const uint32_t base = uint32_t(merged.positions.size());
  merged.positions.insert(merged.positions.end(), m.positions.begin(), m.positions.end());
  merged.normals.insert(merged.normals.end(), m.normals.begin(), m.normals.end());
  if (look.uvs) merged.uvs.insert(merged.uvs.end(), part.uvs.begin(), part.uvs.end());
  if (look.colors) {
    const glm::vec4 tint = look.bake_material && part.material != options.mixed_material &&
                                   part.material < options.material_colors.size()
                               ? options.material_colors[part.material]
                               : glm::vec4(1.0f);
    for (size_t v = 0; v < part.positions.size(); ++v)
      merged.colors.push_back(tint * (part.has_colors() ? part.colors[v] : glm::vec4(1.0f)));
  }
  for (uint32_t i : m.indices) merged.indices.push_back(base + i);
}

float round_up(double value) {
  const float f = float(value);
  return double(f) >= value ? f : std::nextafter(f, INFINITY);
}

// Makes node `id`'s proxy from its children's proxies (or its objects' coarse meshes).
void make_proxy(Hlod& hlod, uint32_t id, std::span<const HlodObject> objects, const HlodOptions& options) {
  HlodNode& node = hlod.nodes[id];
  std::vector<const Mesh*> parts;
  std::vector<Sphere> spheres;
  double replaced_error = 0.0;
  simplify::Options so;  // default attribute weights: UVs and colours are interpolated, not dropped
  // The parts' radii in merge order; a part without them carries its error at every vertex.
  auto carry = [&](const Mesh& part, const std::vector<float>& radii, float error) {
    if (radii.size() == part.positions.size())
      so.vertex_error.insert(so.vertex_error.end(), radii.begin(), radii.end());
    else
      so.vertex_error.resize(so.vertex_error.size() + part.positions.size(), error);
  };
  if (node.children.empty()) {
    for (uint32_t o : node.objects) {
      parts.push_back(&objects[o].coarse);
      spheres.push_back(objects[o].sphere);
      replaced_error = std::max(replaced_error, double(objects[o].error));
      carry(objects[o].coarse, objects[o].coarse_error, objects[o].error);
    }
  } else {
    for (uint32_t c : node.children) {
      const HlodNode& child = hlod.nodes[c];
      parts.push_back(&child.mesh);
      spheres.push_back(child.sphere);
      replaced_error = std::max(replaced_error, double(child.error));
      carry(child.mesh, child.vertex_error, child.error);
      node.level = std::max(node.level, child.level + 1);
    }
  }
  floor_radii(so.vertex_error);
  const ProxyLook look = proxy_look(parts, options);
  Mesh merged;
  for (const Mesh* part : parts) append(merged, *part, look, options);
  so.target_triangles = std::min(options.max_proxy_triangles,
                                 size_t(std::ceil(options.ratio * double(merged.triangle_count()))));
  so.allow_topology_change = true;
  simplify::Result r = simplify::simplify_mesh(merged, so);
  node.mesh = std::move(r.mesh);
  node.mesh.material = look.material;
  node.simplification_bound = r.error_bound;
  node.vertex_error = std::move(r.vertex_error);
  const double tolerance = double(options.position_tolerance);
  double radius = 0.0;
  for (float e : node.vertex_error) radius = std::max(radius, double(e));
  node.error = round_up(std::max(replaced_error, radius + tolerance));
  Sphere s = sphere_of_spheres(spheres, node.mesh.positions);
  s.radius = round_up(double(s.radius) + tolerance);
  node.sphere = s;
}

}  // namespace

Hlod build_hlod(std::span<const HlodObject> objects, const HlodOptions& options) {
  Bounds scene;
  for (const HlodObject& o : objects) scene.add(o.bounds.min), scene.add(o.bounds.max);
  std::vector<float> errors;
  for (const HlodObject& o : objects) errors.push_back(o.error);
  std::nth_element(errors.begin(), errors.begin() + ptrdiff_t(errors.size() / 2), errors.end());
  const double median = errors.empty() ? 0.0 : double(errors[errors.size() / 2]);
  const double coarse = std::max(options.coarse_median_factor * median,
                                 options.coarse_scene_fraction * double(scene.diagonal()));
  std::vector<uint32_t> members;  // the objects the HLOD covers (hlod.hpp: coarse ones stay out)
  for (uint32_t o = 0; o < objects.size(); ++o)
    if (double(objects[o].error) <= coarse) members.push_back(o);
  if (members.size() <= 1) return {};
  Builder b{objects, options, {}};
  b.build(std::move(members));
  Hlod hlod = std::move(b.hlod);
  // Bottom-up by depth (children have higher ids, so deepest first): one depth at a time, in parallel.
  std::vector<uint32_t> depth(hlod.nodes.size(), 0);
  uint32_t max_depth = 0;
  for (uint32_t id = 1; id < hlod.nodes.size(); ++id)
    max_depth = std::max(max_depth, depth[id] = depth[hlod.nodes[id].parent] + 1);
  for (uint32_t d = max_depth + 1; d-- > 0;) {
    std::vector<uint32_t> at;
    for (uint32_t id = 0; id < hlod.nodes.size(); ++id)
      if (depth[id] == d) at.push_back(id);
    tbb::parallel_for(size_t(0), at.size(), [&](size_t i) { make_proxy(hlod, at[i], objects, options); });
  }
  hlod.levels = hlod.nodes[hlod.root].level;
  return hlod;
}

}  // namespace lodstream::hierarchy
