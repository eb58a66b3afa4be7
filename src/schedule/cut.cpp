#include "schedule/cut.hpp"

#include <algorithm>
#include <cmath>
#include <queue>
#include <tuple>

#include <absl/container/flat_hash_set.h>

#include "core/error.hpp"

namespace lodstream::schedule {

namespace {

struct ObjectView {
  glm::mat4 transform;
  double scale = 1.0;
};

// One refinement candidate: the exchange below drawn node `node` of `object`, keyed by `error_px`, the
// projected error of its P (= node's own).
struct Candidate {
  double error_px;
  uint32_t object, node;
  bool operator<(const Candidate& o) const {  // max-heap on error; ties: smaller (object, node) first
    return std::tie(error_px, o.object, o.node) < std::tie(o.error_px, object, node);
  }
};

uint64_t key(uint32_t object, uint32_t node) {
  return uint64_t(object) << 32 | node;
}

// Whether two id lists hold the same ids in any order. The bake lists a group's ids in one order in all of
// its records, so the sorting into `scratch` happens only where they differ. Cost: O(n) for equal lists.
bool same_ids(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b,
              std::vector<uint32_t> (&scratch)[2]) {
  if (a.size() != b.size()) return false;
  size_t i = 0;
  while (i < a.size() && a[i] == b[i]) ++i;  // a few ids: a loop, not a call to memcmp
  if (i == a.size()) return true;
  scratch[0] = a, scratch[1] = b;
  std::sort(scratch[0].begin(), scratch[0].end());
  std::sort(scratch[1].begin(), scratch[1].end());
  return scratch[0] == scratch[1];
}

// The scene's HLOD (cut.hpp): its roots (those whose records are known) and the objects they cover.
struct HlodCover {
  std::vector<uint32_t> roots;
  std::vector<uint8_t> covered;  // per object
};

HlodCover hlod_cover(const package::PackageScene& scene, const NodeSource& nodes) {
  HlodCover h;
  h.covered.assign(scene.objects.size(), 0);
  for (const package::Representation& rep : scene.representations) {
    if (rep.kind != package::RepresentationKind::hlod) continue;
    for (uint32_t root : rep.roots) {
      const package::NodeRecord* r = nodes.record(root);
      if (!r) continue;
      h.roots.push_back(root);
      for (uint32_t o : r->objects)
        if (o < h.covered.size()) h.covered[o] = 1;
    }
  }
  return h;
}

WorldSphere proxy_sphere(const package::NodeRecord& r) {
  return {glm::dvec3(r.sphere.center), double(r.sphere.radius)};
}

// Node `r`'s projected error under `transform` (largest axis scale `scale`), or world space (a proxy) when
// `transform` is null.
double project_node(const package::NodeRecord& r, const glm::mat4* transform, double scale,
                    const View& view) {
  if (!transform) return screen_error(double(r.error), proxy_sphere(r), view);
  return screen_error(double(r.error) * scale, to_world(r.sphere, *transform, scale), view);
}

class Traversal {
 public:
  Traversal(const package::PackageScene& scene, const NodeSource& nodes, const View& view,
            const CutOptions& options, bool ideal)
      : scene_(scene), nodes_(nodes), view_(view), options_(options), ideal_(ideal) {}

  // Runs the greedy refinement over the objects in state `drawn`: those not covered by `hlod` from their
  // roots, the covered ones from the HLOD's roots in the frustum.
  void run(const std::vector<ObjectState>& states, const std::vector<ObjectView>& objects,
           const HlodCover& hlod) {
    objects_ = &objects;
    states_ = &states;
    tau_ = options_.tau;
    for (uint32_t o = 0; o < states.size(); ++o) {
      if (states[o] != ObjectState::drawn || hlod.covered[o]) continue;
      for (uint32_t root : scene_.representations[scene_.objects[o].representation].roots) draw(o, root);
    }
    for (uint32_t root : hlod.roots)
      if (in_frustum(proxy_sphere(*nodes_.record(root)), view_)) draw(package::kNone, root);
    while (!heap_.empty()) {
      const Candidate c = heap_.top();
      heap_.pop();
      if (!(c.error_px > options_.tau)) break;
      if (!drawn_.contains(key(c.object, c.node))) continue;  // refined already through another P member
      const package::NodeRecord& p = *nodes_.record(c.node);
      if (c.object == package::kNone) {
        if (!refine_proxy(c, p)) break;
        continue;
      }
      if (p.kind == package::NodeKind::progressive_step) {
        if (!refine_step(c, p)) break;
        continue;
      }
      // G and P of the exchange, checked to be one.
      std::vector<const package::NodeRecord*>& g = members_;
      g.resize(p.children.size());
      bool known = true;
      for (size_t i = 0; i < g.size(); ++i) {
        g[i] = nodes_.record(p.children[i]);
        if (!g[i]) {
          known = false;
          if (ideal_) missing_.push_back({c.object, p.children[i], 0.0, c.error_px, false});
        }
      }
      if (!known) continue;
      const std::vector<uint32_t>& parents = g[0]->parents;
      bool all_drawn = true;
      for (uint32_t q : parents) all_drawn = all_drawn && drawn_.contains(key(c.object, q));
      if (!all_drawn) continue;  // queued again when the last member of P is drawn
      check_exchange(c.node, p, g, parents);
      uint64_t removed = 0, added = 0;
      bool available = true;
      for (uint32_t q : parents) removed += nodes_.record(q)->triangles;
      for (size_t i = 0; i < g.size(); ++i) {
        added += g[i]->triangles;
        available = available && nodes_.available(p.children[i]);
      }
      if (!available && !ideal_) continue;  // the best available ancestor level (P) stays drawn
      if (triangles_ - removed + added > options_.triangle_budget) {
        budget_limited_ = true;
        tau_ = c.error_px;
        break;
      }
      for (uint32_t q : parents) drawn_.erase(key(c.object, q));
      triangles_ -= removed;
      for (size_t i = 0; i < g.size(); ++i) {
        if (ideal_ && !nodes_.available(p.children[i]))
          missing_.push_back({c.object, p.children[i], project(c.object, *g[i]), c.error_px, true});
        draw(c.object, p.children[i]);
      }
    }
  }

  // The exchange below drawn proxy `p` (cut.hpp, HLOD): its child proxies in the frustum, or for a leaf the
  // roots of its objects in the frustum. Returns false when the budget stops the refinement.
  bool refine_proxy(const Candidate& c, const package::NodeRecord& p) {
    struct Member {
      uint32_t object, node;
      const package::NodeRecord* record;
    };
    std::vector<Member> g;
    bool known = true;
    auto add = [&](uint32_t object, uint32_t id) {
      const package::NodeRecord* r = nodes_.record(id);
      if (!r) {
        known = false;
        if (ideal_)
          missing_.push_back(
              {object, id, 0.0, c.error_px, false, object == package::kNone ? package::kNone : c.node});
      } else if (object != package::kNone || in_frustum(proxy_sphere(*r), view_)) {
        g.push_back({object, id, r});
      }
    };
    if (!p.children.empty()) {
      for (uint32_t child : p.children) add(package::kNone, child);
    } else {
      for (uint32_t o : p.objects)
        if (o < states_->size() && (*states_)[o] != ObjectState::culled)
          for (uint32_t root : scene_.representations[scene_.objects[o].representation].roots) add(o, root);
    }
    if (!known) return true;
    uint64_t added = 0;
    bool available = true;
    for (const Member& m : g) {
      added += m.record->triangles;
      available = available && nodes_.available(m.node);
    }
    if (!available && !ideal_) return true;  // the proxy stays drawn
    if (triangles_ - p.triangles + added > options_.triangle_budget) {
      budget_limited_ = true;
      tau_ = c.error_px;
      return false;
    }
    drawn_.erase(key(c.object, c.node));
    triangles_ -= p.triangles;
    for (const Member& m : g) {
      if (ideal_ && !nodes_.available(m.node))
        missing_.push_back({m.object, m.node, project(m.object, *m.record), c.error_px, true,
                            m.object == package::kNone ? package::kNone : c.node});
      draw(m.object, m.node);
    }
    return true;
  }

  // The step after drawn progressive step `p` (cut.hpp, progressive meshes), drawn in addition to it.
  // Returns false when the budget stops the refinement.
  bool refine_step(const Candidate& c, const package::NodeRecord& p) {
    const uint32_t next = p.children[0];
    const package::NodeRecord* r = nodes_.record(next);
    if (!r) {
      if (ideal_) missing_.push_back({c.object, next, 0.0, c.error_px, false});
      return true;
    }
    if (p.children.size() != 1 || r->kind != package::NodeKind::progressive_step ||
        r->parents != std::vector<uint32_t>{c.node})
      throw Error("node " + std::to_string(c.node) + ": its next step is not one progressive step after it");
    const bool available = nodes_.available(next);
    if (!available && !ideal_) return true;  // the prefix ends at p
    if (triangles_ + r->triangles > options_.triangle_budget) {
      budget_limited_ = true;
      tau_ = c.error_px;
      return false;
    }
    if (ideal_ && !available) missing_.push_back({c.object, next, project(c.object, *r), c.error_px, true});
    draw(c.object, next);
    return true;
  }

  // Marks node `id` of `object` drawn (its record must be known) and queues the exchange below it.
  void draw(uint32_t object, uint32_t id) {
    const package::NodeRecord& r = *nodes_.record(id);
    drawn_.insert(key(object, id));
    triangles_ += r.triangles;
    if (!r.children.empty() || r.kind == package::NodeKind::hlod_proxy)
      heap_.push({project(object, r), object, id});
  }

  double project(uint32_t object, const package::NodeRecord& r) const {
    if (object == package::kNone) return project_node(r, nullptr, 1.0, view_);
    const ObjectView& o = (*objects_)[object];
    return project_node(r, &o.transform, o.scale, view_);
  }

  void check_exchange(uint32_t id, const package::NodeRecord& p,
                      const std::vector<const package::NodeRecord*>& g,
                      const std::vector<uint32_t>& parents) {
    for (const package::NodeRecord* member : g)
      if (!same_ids(member->parents, parents, scratch_))
        throw Error("node " + std::to_string(id) +
                    ": its children do not share one set of parents (not a group exchange)");
    for (uint32_t q : parents) {
      const package::NodeRecord* r = nodes_.record(q);
      if (!r || !same_ids(r->children, p.children, scratch_))
        throw Error("node " + std::to_string(q) + ": its children differ from node " + std::to_string(id) +
                    "'s (not a group exchange)");
    }
  }

  const package::PackageScene& scene_;
  const NodeSource& nodes_;
  const View& view_;
  const CutOptions& options_;
  const bool ideal_;
  const std::vector<ObjectView>* objects_ = nullptr;
  const std::vector<ObjectState>* states_ = nullptr;
  std::priority_queue<Candidate> heap_;
  // (object, node) keys of the drawn nodes: abseil's open-addressing set, as insert / erase / lookup per
  // visited node with std::unordered_set's node allocations were a third of the push server's planning.
  absl::flat_hash_set<uint64_t> drawn_;
  std::vector<const package::NodeRecord*> members_;  // run()'s G records, reused
  std::vector<uint32_t> scratch_[2];                 // same_ids' sorting of unsorted lists
  uint64_t triangles_ = 0;
  double tau_ = 0.0;
  bool budget_limited_ = false;
  std::vector<MissingNode> missing_;
};

}  // namespace

WorldSphere object_sphere(const package::PackageScene& scene, uint32_t object) {
  const package::ObjectRecord& o = scene.objects[object];
  const Bounds& b = scene.representations[o.representation].bounds;
  return to_world(Sphere{b.center(), 0.5f * b.diagonal()}, o.transform, max_scale(o.transform));
}

double projected_error(const package::PackageScene& scene, uint32_t object, const package::NodeRecord& r,
                       const View& view) {
  if (object == package::kNone) return project_node(r, nullptr, 1.0, view);
  const glm::mat4& transform = scene.objects[object].transform;
  return project_node(r, &transform, max_scale(transform), view);
}

Cut select_cut(const package::PackageScene& scene, const NodeSource& nodes, const View& view,
               const CutOptions& options) {
  Cut cut;
  std::vector<ObjectView> objects(scene.objects.size());
  cut.objects.assign(scene.objects.size(), ObjectState::drawn);
  std::vector<ObjectState> ideal_states = cut.objects;
  std::vector<MissingNode> missing_roots;
  const HlodCover hlod = hlod_cover(scene, nodes);
  bool hlod_available = true;
  for (uint32_t root : hlod.roots) {
    const package::NodeRecord& r = *nodes.record(root);
    // A root out of view covers only objects out of view (its sphere contains theirs): it neither blocks
    // the others nor is asked for.
    if (nodes.available(root) || !in_frustum(proxy_sphere(r), view)) continue;
    hlod_available = false;
    missing_roots.push_back(
        {package::kNone, root, screen_error(double(r.error), proxy_sphere(r), view), INFINITY, true});
  }
  for (uint32_t o = 0; o < scene.objects.size(); ++o) {
    const package::ObjectRecord& object = scene.objects[o];
    const package::Representation& rep = scene.representations[object.representation];
    objects[o] = {object.transform, max_scale(object.transform)};
    if (rep.bounds.empty() || !in_frustum(object_sphere(scene, o), view)) {
      cut.objects[o] = ideal_states[o] = ObjectState::culled;
      continue;
    }
    if (hlod.covered[o]) {  // its roots are reached through the HLOD's leaves
      if (!hlod_available) cut.objects[o] = ObjectState::incomplete;
      continue;
    }
    for (uint32_t root : rep.roots) {
      const package::NodeRecord* r = nodes.record(root);
      if (!r) {
        missing_roots.push_back({o, root, 0.0, INFINITY, false});
        cut.objects[o] = ideal_states[o] = ObjectState::incomplete;
      } else if (!nodes.available(root)) {
        const double e = screen_error(double(r->error) * objects[o].scale,
                                      to_world(r->sphere, object.transform, objects[o].scale), view);
        missing_roots.push_back({o, root, e, INFINITY, true});
        cut.objects[o] = ObjectState::incomplete;
      }
    }
  }

  Traversal available(scene, nodes, view, options, false);
  available.run(cut.objects, objects, hlod_available ? hlod : HlodCover{{}, hlod.covered});
  Traversal ideal(scene, nodes, view, options, true);
  ideal.run(ideal_states, objects, hlod);

  for (uint64_t k : available.drawn_) {
    const uint32_t o = uint32_t(k >> 32), id = uint32_t(k);
    const package::NodeRecord& r = *nodes.record(id);
    const bool refined = r.kind == package::NodeKind::progressive_step && !r.children.empty() &&
                         available.drawn_.contains(key(o, r.children[0]));
    cut.drawn.push_back({o, id, available.project(o, r), r.triangles, refined});
  }
  std::sort(cut.drawn.begin(), cut.drawn.end(), [](const DrawnNode& a, const DrawnNode& b) {
    return std::tie(a.object, a.node) < std::tie(b.object, b.node);
  });
  cut.triangles = available.triangles_;
  cut.ideal_triangles = ideal.triangles_;
  cut.tau = available.tau_;
  cut.budget_limited = available.budget_limited_;
  cut.missing = std::move(missing_roots);
  cut.missing.insert(cut.missing.end(), ideal.missing_.begin(), ideal.missing_.end());
  // Each member of P reports G's unknown records: keep one entry per (object, node).
  std::sort(cut.missing.begin(), cut.missing.end(), [](const MissingNode& a, const MissingNode& b) {
    return std::tie(a.object, a.node) < std::tie(b.object, b.node);
  });
  cut.missing.erase(std::unique(cut.missing.begin(), cut.missing.end(),
                                [](const MissingNode& a, const MissingNode& b) {
                                  return a.object == b.object && a.node == b.node;
                                }),
                    cut.missing.end());
  std::stable_sort(cut.missing.begin(), cut.missing.end(), [](const MissingNode& a, const MissingNode& b) {
    return a.parent_error_px > b.parent_error_px;
  });
  return cut;
}

}  // namespace lodstream::schedule
