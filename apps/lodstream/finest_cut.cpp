#include "finest_cut.hpp"

#include <algorithm>

namespace lodstream::cli {

std::vector<std::vector<uint32_t>> finest_nodes(const package::PackageScene& scene,
                                                const schedule::NodeSource& records, uint32_t node_count) {
  std::vector<std::vector<uint32_t>> finest(scene.representations.size());
  for (uint32_t id = 0; id < node_count; ++id) {
    const package::NodeRecord* n = records.record(id);
    // HLOD leaves: not geometry; a progressive mesh's finest prefix is all of its steps.
    if (n && (n->children.empty() || n->kind == package::NodeKind::progressive_step) &&
        n->kind != package::NodeKind::hlod_proxy)
      finest[n->representation].push_back(id);
  }
  return finest;
}

std::vector<uint32_t> finest_pages(const schedule::NodeSource& records,
                                   const std::vector<std::vector<uint32_t>>& finest) {
  std::vector<uint32_t> pages;
  for (const auto& nodes : finest)
    for (uint32_t id : nodes) pages.push_back(records.record(id)->page);
  std::sort(pages.begin(), pages.end());
  pages.erase(std::unique(pages.begin(), pages.end()), pages.end());
  return pages;
}

schedule::Cut finest_cut(const package::PackageScene& scene, const schedule::NodeSource& records,
                         const std::vector<std::vector<uint32_t>>& finest, const schedule::View& view) {
  schedule::Cut cut;
  const auto& objects = scene.objects;
  cut.objects.assign(objects.size(), schedule::ObjectState::culled);
  for (uint32_t o = 0; o < objects.size(); ++o) {
    if (!schedule::in_frustum(schedule::object_sphere(scene, o), view)) continue;
    cut.objects[o] = schedule::ObjectState::drawn;
    const double scale = schedule::max_scale(objects[o].transform);
    for (uint32_t id : finest[objects[o].representation]) {
      const package::NodeRecord& n = *records.record(id);
      const double e = schedule::screen_error(
          double(n.error) * scale, schedule::to_world(n.sphere, objects[o].transform, scale), view);
      const bool refined = n.kind == package::NodeKind::progressive_step && !n.children.empty();
      cut.drawn.push_back({o, id, e, n.triangles, refined});
      cut.triangles += n.triangles;
    }
  }
  cut.ideal_triangles = cut.triangles;
  return cut;
}

}  // namespace lodstream::cli
