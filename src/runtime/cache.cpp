#include "runtime/cache.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::runtime {

void PageCache::insert(const package::ContentHash& package, uint32_t page, std::vector<uint8_t> bytes) {
  Entry& e = entries_[key(package, page)];
  bytes_ -= e.bytes.size();
  bytes_ += bytes.size();
  e.bytes = std::move(bytes);
  e.last_use = ++clock_;
  e.usefulness = INFINITY;
  evict();
}

void PageCache::set_budget(uint64_t budget_bytes) {
  budget_ = budget_bytes;
  evict();
}

const std::vector<uint8_t>* PageCache::find(const package::ContentHash& package, uint32_t page) {
  auto it = entries_.find(key(package, page));
  if (it == entries_.end()) return nullptr;
  it->second.last_use = ++clock_;
  return &it->second.bytes;
}

bool PageCache::contains(const package::ContentHash& package, uint32_t page) const {
  return entries_.count(key(package, page)) != 0;
}

std::vector<uint32_t> PageCache::pages(const package::ContentHash& package) const {
  std::vector<uint32_t> out;
  for (auto it = entries_.lower_bound(key(package, 0)); it != entries_.end(); ++it) {
    if (it->first.low != package.low || it->first.high != package.high) break;
    out.push_back(it->first.page);
  }
  return out;
}

void PageCache::set_usefulness(const package::ContentHash& package, std::span<const uint32_t> pinned,
                               const std::unordered_map<uint32_t, double>& usefulness) {
  for (auto it = entries_.lower_bound(key(package, 0)); it != entries_.end(); ++it) {
    if (it->first.low != package.low || it->first.high != package.high) break;
    auto u = usefulness.find(it->first.page);
    it->second.usefulness = u == usefulness.end() ? 0.0 : u->second;
    it->second.pinned = false;
  }
  for (uint32_t page : pinned) {
    auto it = entries_.find(key(package, page));
    if (it != entries_.end()) it->second.pinned = true;
  }
  evict();
}

void PageCache::clear(const package::ContentHash& package) {
  auto it = entries_.lower_bound(key(package, 0));
  while (it != entries_.end() && it->first.low == package.low && it->first.high == package.high) {
    bytes_ -= it->second.bytes.size();
    it = entries_.erase(it);
  }
}

void PageCache::evict() {
  if (bytes_ <= budget_) return;
  // Candidates in eviction order: least useful first, then least recently used; among unrated pages the
  // newest first (pages arrive in the scheduler's order, most useful first, so in a burst that overflows the
  // budget before any frame rated them, the last arrivals are the least useful; dropping the first ones
  // dropped the roots and left nothing to draw).
  std::vector<std::map<Key, Entry>::iterator> order;
  for (auto it = entries_.begin(); it != entries_.end(); ++it)
    if (!it->second.pinned) order.push_back(it);
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    const Entry &x = a->second, &y = b->second;
    if (x.usefulness != y.usefulness) return x.usefulness < y.usefulness;
    return std::isinf(x.usefulness) ? x.last_use > y.last_use : x.last_use < y.last_use;
  });
  for (auto it : order) {
    if (bytes_ <= budget_) break;
    bytes_ -= it->second.bytes.size();
    entries_.erase(it);
    ++evicted_;
  }
}

PageUsefulness page_usefulness(const package::PackageScene& scene, const NodeSource& nodes,
                               const Cut& current, std::span<const View> views,
                               std::span<const uint32_t> cached_nodes) {
  PageUsefulness out;
  for (const DrawnNode& d : current.drawn) out.pinned.push_back(nodes.record(d.node)->page);
  std::sort(out.pinned.begin(), out.pinned.end());
  out.pinned.erase(std::unique(out.pinned.begin(), out.pinned.end()), out.pinned.end());
  // Objects per representation, with what projecting needs, visible per view.
  struct Instance {
    uint32_t object;
    double scale;
    std::vector<uint8_t> visible;  // per view
  };
  std::vector<std::vector<Instance>> instances(scene.representations.size());
  for (uint32_t o = 0; o < scene.objects.size(); ++o) {
    Instance in{o, max_scale(scene.objects[o].transform), {}};
    for (const View& v : views) in.visible.push_back(in_frustum(object_sphere(scene, o), v));
    instances[scene.objects[o].representation].push_back(std::move(in));
  }
  for (uint32_t id : cached_nodes) {
    const package::NodeRecord& r = *nodes.record(id);
    double best = 0.0;
    if (r.kind == package::NodeKind::hlod_proxy)  // world space: no object instances it
      for (const View& v : views)
        if (in_frustum(to_world(r.sphere, glm::mat4(1.0f), 1.0), v))
          best = std::max(
              best, screen_error(double(r.parent_error), to_world(r.parent_sphere, glm::mat4(1.0f), 1.0), v));
    for (const Instance& in : instances[r.representation]) {
      const glm::mat4& t = scene.objects[in.object].transform;
      for (size_t v = 0; v < views.size(); ++v)
        if (in.visible[v])
          best = std::max(best, screen_error(double(r.parent_error) * in.scale,
                                             to_world(r.parent_sphere, t, in.scale), views[v]));
    }
    double& u = out.usefulness[r.page];
    u = std::max(u, best);
  }
  return out;
}

}  // namespace lodstream::runtime
