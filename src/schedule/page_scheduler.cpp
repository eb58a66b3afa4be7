#include "schedule/page_scheduler.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <unordered_set>

#include "core/error.hpp"
#include "schedule/screen_area.hpp"

namespace lodstream::schedule {

namespace {

// Availability as the scheduler plans it: a node is available when its data page is held or chosen.
class Planned final : public NodeSource {
 public:
  Planned(const NodeSource& records, const std::vector<bool>& data) : records_(records), data_(data) {}
  const package::NodeRecord* record(uint32_t id) const override { return records_.record(id); }
  bool available(uint32_t id) const override {
    const package::NodeRecord* r = records_.record(id);
    return r && data_[r->page];
  }

 private:
  const NodeSource& records_;
  const std::vector<bool>& data_;
};

// An exchange's gain per unit of screen area (header, formula of the benefit): the error it removes on a log
// scale (member_gain); an object's roots (nothing drawn yet) count kRootGain.
constexpr double kRootGain = 10.0;

// A group exchange of some view's ideal cut: P (empty for an object's roots) is replaced by G.
struct Exchange {
  uint32_t object = 0;
  std::vector<uint32_t> p, g;
  double benefit = 0.0;    // summed over the weighted views
  double secondary = 0.0;  // the largest weighted e_P: the order among exchanges of no benefit
  bool done = false;
  // The data pages that must be held or chosen, besides P's, for P to be drawn (drawable_gates), and
  // whether they all are (once true, it stays true within a call).
  std::vector<uint32_t> gate;
  bool gate_open = false;
};

// The pages chosen so far (held ones included) and the order they were chosen in.
struct Plan {
  const PageScheduler& scheduler;
  const NodeSource& records;
  std::vector<bool> data, index;
  std::vector<PageRef> order;
  uint64_t bytes = 0;
  const ScheduleOptions& options;

  bool full() const {
    return !order.empty() && (bytes >= options.max_bytes || order.size() >= options.max_pages);
  }
  void add(PageKind kind, uint32_t id) {
    std::vector<bool>& set = kind == PageKind::data ? data : index;
    if (set[id] || full()) return;
    set[id] = true;
    order.push_back(scheduler.page(kind, id));
    bytes += order.back().bytes;
  }
  void add_record(uint32_t node) {
    const uint32_t page = scheduler.index_page_of(node);
    if (page != package::kNone) add(PageKind::index, page);
  }
  // Bytes the exchange still needs: index pages of P's and G's records, data pages of G.
  uint64_t cost(const Exchange& e) const {
    std::vector<PageRef> pages;
    auto need = [&](PageKind kind, uint32_t id) {
      const std::vector<bool>& set = kind == PageKind::data ? data : index;
      if (!set[id] && std::find(pages.begin(), pages.end(), PageRef{kind, id, 0}) == pages.end())
        pages.push_back({kind, id, 0});
    };
    for (const auto* ids : {&e.p, &e.g})
      for (uint32_t n : *ids)
        if (uint32_t page = scheduler.index_page_of(n); page != package::kNone) need(PageKind::index, page);
    for (uint32_t n : e.g) need(PageKind::data, records.record(n)->page);
    uint64_t sum = 0;
    for (const PageRef& p : pages) sum += scheduler.page(p.kind, p.id).bytes;
    return sum;
  }
  bool eligible(Exchange& e) const {
    if (!e.gate_open)
      e.gate_open = std::all_of(e.gate.begin(), e.gate.end(), [&](uint32_t page) { return data[page]; });
    return e.gate_open &&
           std::all_of(e.p.begin(), e.p.end(), [&](uint32_t n) { return data[records.record(n)->page]; });
  }
};

// Sets each exchange's gate (Exchange::gate): the pages of the nodes that must be available, besides P, for
// P to be drawn at all (cut.hpp). An object's nodes are drawn only when all its roots are; an object covered
// by HLOD only when its leaf proxy L is drawn and refined: L's HLOD root, the children of each of L's
// ancestors (an exchange replaces a proxy by all its children), L, and the G of L's exchange (the roots of
// its objects in the views). A proxy's exchange is gated by the same chain above it. Without the gate an
// object's refinements were eligible as soon as their own P was chosen, and planned while the object was not
// drawable (motorBike with HLOD: push sent 1 MB of objects' finer levels while every leaf waited for a few
// of its objects' root pages, benefit 0.01 until 1.5 s). Unknown records gate nothing (their index pages
// come first). Cost: O(HLOD nodes + exchanges x gate size).
void drawable_gates(const package::PackageScene& scene, const NodeSource& records,
                    std::map<uint64_t, Exchange>& exchanges) {
  std::vector<uint32_t> hlod_roots, leaf_of(scene.objects.size(), package::kNone);
  for (const package::Representation& rep : scene.representations)
    if (rep.kind == package::RepresentationKind::hlod)
      hlod_roots.insert(hlod_roots.end(), rep.roots.begin(), rep.roots.end());
  std::vector<uint32_t> stack = hlod_roots;
  while (!stack.empty()) {
    const uint32_t id = stack.back();
    stack.pop_back();
    const package::NodeRecord* r = records.record(id);
    if (!r) continue;
    stack.insert(stack.end(), r->children.begin(), r->children.end());
    if (r->children.empty())
      for (uint32_t o : r->objects)
        if (o < leaf_of.size()) leaf_of[o] = id;
  }
  auto add = [&](std::vector<uint32_t>& pages, uint32_t node) {
    if (const package::NodeRecord* r = records.record(node))
      if (std::find(pages.begin(), pages.end(), r->page) == pages.end()) pages.push_back(r->page);
  };
  // The pages for proxy `p` to be drawn: its HLOD root (the cut asks only for roots in view; every root
  // when the chain up from p is not known yet) and the children of each of its ancestors.
  auto proxy_chain = [&](uint32_t p, std::vector<uint32_t>& pages) {
    uint32_t top = p;
    const package::NodeRecord* r = records.record(p);
    while (r && !r->parents.empty()) {
      top = r->parents[0];
      if ((r = records.record(top)))
        for (uint32_t c : r->children) add(pages, c);
    }
    if (r)
      add(pages, top);
    else
      for (uint32_t root : hlod_roots) add(pages, root);
  };
  for (auto& [key, e] : exchanges) {
    const uint32_t low = uint32_t(key);
    if (e.object == package::kNone) {
      if (low != package::kNone) proxy_chain(low, e.gate);
      continue;
    }
    if (e.p.empty()) continue;  // an object's roots
    const uint32_t leaf = leaf_of[e.object];
    if (leaf == package::kNone) {
      for (uint32_t root : scene.representations[scene.objects[e.object].representation].roots)
        add(e.gate, root);
      continue;
    }
    proxy_chain(leaf, e.gate);
    add(e.gate, leaf);
    if (auto it = exchanges.find(uint64_t(package::kNone) << 32 | leaf); it != exchanges.end())
      for (uint32_t n : it->second.g) add(e.gate, n);
  }
}

double view_area(const package::PackageScene& scene, const Cut& cut, const View& view) {
  double total = 0.0;
  for (uint32_t o = 0; o < scene.objects.size(); ++o)
    if (cut.objects[o] != ObjectState::culled) total += projected_area(object_sphere(scene, o), view);
  return total > 0.0 ? total : 1.0;
}

// Adds view `v`'s benefit of the HLOD exchange below proxy `p` (cut.hpp; package::kNone: the HLOD's roots,
// where nothing is drawn) to `exchanges`. Every object a proxy draws is drawn by it whole, so the benefit
// sums, over the objects of the exchange's members in the frustum, A_i x the log gain from e_P (`p_error_px`)
// to the member's error: members are p's child proxies, or for a leaf the roots of its objects (one
// exchange: the cut refines a leaf only when all of them are available); members already held count too
// (their objects gain as much when P is replaced). Skipped while a member's record is unknown.
void add_hlod_exchange(const package::PackageScene& scene, const NodeSource& records, const Cut& cut,
                       const WeightedView& v, double tau, uint32_t p, double p_error_px,
                       const std::vector<double>& object_area, double total,
                       std::map<uint64_t, Exchange>& exchanges) {
  auto gain = [&](double e_px) {
    return std::isinf(p_error_px) ? kRootGain : std::log(std::max(p_error_px, tau) / std::max(e_px, tau));
  };
  const package::NodeRecord* proxy = p == package::kNone ? nullptr : records.record(p);
  std::vector<uint32_t> g;
  double benefit = 0.0;
  if (!proxy || !proxy->children.empty()) {
    std::vector<uint32_t> members;
    for (const package::Representation& rep : scene.representations)
      if (rep.kind == package::RepresentationKind::hlod && !proxy) members = rep.roots;
    if (proxy) members = proxy->children;
    for (uint32_t c : members) {
      const package::NodeRecord* r = records.record(c);
      if (!r) return;
      g.push_back(c);
      double area = 0.0;
      for (uint32_t o : r->objects)
        if (o < object_area.size()) area += object_area[o];
      if (area > 0.0) benefit += area * gain(projected_error(scene, package::kNone, *r, v.view));
    }
  } else {
    for (uint32_t o : proxy->objects) {
      if (o >= cut.objects.size() || cut.objects[o] == ObjectState::culled) continue;
      double e_px = 0.0;
      for (uint32_t root : scene.representations[scene.objects[o].representation].roots) {
        const package::NodeRecord* r = records.record(root);
        if (!r) return;
        g.push_back(root);
        e_px = std::max(e_px, projected_error(scene, o, *r, v.view));
      }
      benefit += object_area[o] * gain(e_px);
    }
  }
  Exchange& e = exchanges[uint64_t(package::kNone) << 32 | p];
  e.object = package::kNone;
  if (proxy) e.p = {p};
  for (uint32_t n : g)
    if (std::find(e.g.begin(), e.g.end(), n) == e.g.end()) e.g.push_back(n);
  e.benefit += v.weight * benefit / total;
  e.secondary = std::max(e.secondary, v.weight * std::min(p_error_px, 1e300));
}

// How many levels member_gain looks below a member that keeps its parents' error, and what "keeps" means:
// within 1 % (the carried error comes back a few ulps to 0.002 % apart through the levels' max of radii).
constexpr int kLookahead = 12;
constexpr double kKeeps = 0.99;

// The projected error a member r of G leaves once refined as far as it must be to lower its error: r's own,
// or, when r keeps its parents' error (error_g = max of its inputs' carries a fallback's error up unchanged),
// the largest of its children's, and so on for up to kLookahead levels while the records are known. Such a
// member removes nothing by itself and the exchange below it cannot be ranked until it is held, so by its own
// gain a chain of them ranked last by benefit per byte and stalled. City (bench stream gen:fly, 10 Mbit/s 80
// ms): push / oracle to benefit 0.95 0.93 / 0.90 -> 0.83 / 0.80 s; motorBike and elephant_1m unchanged. At
// group ratio 0.4 a strict "keeps" (error >= parent_error) stopped the lookahead at 22.4272 under 22.4277
// and left a 30 px node unrefined from 0.77 to 1.25 s: push / oracle 1.30 / 1.27 -> 0.80 / 0.73 s with
// kKeeps.
double refined_error_px(const package::PackageScene& scene, const NodeSource& records, uint32_t object,
                        const package::NodeRecord& r, const View& view) {
  const package::NodeRecord* at = &r;
  for (int depth = 0; depth < kLookahead && at->error >= kKeeps * at->parent_error && !at->children.empty();
       ++depth) {
    const package::NodeRecord* worst = nullptr;
    for (uint32_t c : at->children) {
      const package::NodeRecord* child = records.record(c);
      if (!child) return projected_error(scene, object, *at, view);
      if (!worst || child->error > worst->error) worst = child;
    }
    at = worst;
  }
  return projected_error(scene, object, *at, view);
}

// The log gain of replacing P (projected error `p_error_px`) by the members `g` of `object`: the mean over
// the members, weighted by the screen area of each member's sphere (unweighted when none has any), of
// ln(max(e_P, tau) / max(e_g, tau)), e_g as refined_error_px. G's members come from different groups, so
// their errors differ: a member that is refined further (e_g close to e_P) gains nearly nothing, its siblings
// may gain much. The gain of one member chosen by id order made an exchange worth nothing when its first
// member was the nearly-useless one (city, mixed-precision records: a chain of five such exchanges under 20
// px held the oracle at benefit 0.92 for 0.7 s). Cost: O(|G|).
double member_gain(const package::PackageScene& scene, const NodeSource& records, uint32_t object,
                   const std::vector<uint32_t>& g, const View& view, double p_error_px, double tau) {
  if (g.empty()) return 0.0;
  const glm::mat4& transform = scene.objects[object].transform;
  const double scale = max_scale(transform);
  double weighted = 0.0, weight = 0.0, plain = 0.0;
  for (uint32_t n : g) {
    const package::NodeRecord& r = *records.record(n);
    const double gain = std::log(std::max(p_error_px, tau) /
                                 std::max(refined_error_px(scene, records, object, r, view), tau));
    const double a = projected_area(to_world(r.sphere, transform, scale), view);
    weighted += a * gain, weight += a, plain += gain;
  }
  return weight > 0.0 ? weighted / weight : plain / double(g.size());
}

// Adds view `v`'s exchanges (from its cut's missing nodes) to `exchanges`; unknown records go to
// `unknown` (node -> the largest weighted error their arrival may remove).
void collect(const package::PackageScene& scene, const NodeSource& records, const Cut& cut,
             const WeightedView& v, double tau, std::map<uint64_t, Exchange>& exchanges,
             std::map<uint32_t, double>& unknown) {
  const double total = view_area(scene, cut, v.view);
  // A_i per object in the frustum (0 when culled), and W_i: the screen area of the nodes drawn now for
  // object i (the weights of alpha_i's mean).
  std::vector<double> object_area(scene.objects.size(), 0.0), drawn_area(scene.objects.size(), 0.0);
  for (uint32_t o = 0; o < scene.objects.size(); ++o)
    if (cut.objects[o] != ObjectState::culled)
      object_area[o] = projected_area(object_sphere(scene, o), v.view);
  for (const DrawnNode& d : cut.drawn) {
    if (d.object == package::kNone) continue;  // an HLOD proxy: its exchanges weigh its objects' A_i
    if (d.refined) continue;                   // a progressive prefix weighs its object's sphere once
    const package::ObjectRecord& o = scene.objects[d.object];
    drawn_area[d.object] +=
        projected_area(to_world(records.record(d.node)->sphere, o.transform, max_scale(o.transform)), v.view);
  }
  auto known = [&](const std::vector<uint32_t>& ids) {
    return std::all_of(ids.begin(), ids.end(), [&](uint32_t n) { return records.record(n) != nullptr; });
  };
  std::unordered_set<uint64_t> seen;  // exchanges of this view (a linear search was quadratic in the cut)
  for (const MissingNode& m : cut.missing) {
    if (!m.record_known) {
      double& priority = unknown[m.node];
      priority = std::max(priority, v.weight * std::min(m.parent_error_px, 1e300));
      continue;
    }
    const package::NodeRecord& r = *records.record(m.node);
    const bool proxy = m.object == package::kNone;
    const bool root = r.parents.empty();
    if (proxy || m.proxy != package::kNone) {
      const uint32_t p = proxy ? (root ? package::kNone : r.parents[0]) : m.proxy;
      const uint64_t key = uint64_t(package::kNone) << 32 | p;
      if (!seen.insert(key).second) continue;
      add_hlod_exchange(scene, records, cut, v, tau, p, m.parent_error_px, object_area, total, exchanges);
      continue;
    }
    const glm::mat4& transform = scene.objects[m.object].transform;
    const uint64_t key = uint64_t(m.object) << 32 |
                         (root ? package::kNone : *std::min_element(r.parents.begin(), r.parents.end()));
    if (!seen.insert(key).second) continue;
    Exchange e;
    e.object = m.object;
    if (root) {
      e.g = scene.representations[scene.objects[m.object].representation].roots;
    } else {
      e.p = r.parents;
      std::sort(e.p.begin(), e.p.end());
      e.g = records.record(e.p[0])->children;
    }
    if (!known(e.g)) continue;  // its unknown records are in `unknown`
    // Roots where nothing is drawn count kRootGain; a P replaced by G the log of the error it removes.
    const double gain =
        root ? kRootGain : member_gain(scene, records, m.object, e.g, v.view, m.parent_error_px, tau);
    // The object's share that changes: all of A_i for its roots; for P, its nodes' weight in alpha_i's mean
    // (|P| spheres of area a(P) out of W_i), at most all of it.
    double area = object_area[m.object];
    if (!root) {
      const double a_p = double(e.p.size()) *
                         projected_area(to_world(r.parent_sphere, transform, max_scale(transform)), v.view);
      area = drawn_area[m.object] > 0.0 ? area * std::min(1.0, a_p / drawn_area[m.object]) : a_p;
    }
    auto [it, inserted] = exchanges.try_emplace(key, std::move(e));
    it->second.benefit += v.weight * area * gain / total;
    it->second.secondary = std::max(it->second.secondary, v.weight * std::min(m.parent_error_px, 1e300));
  }
}

}  // namespace

PageScheduler::PageScheduler(const package::RootIndex& root)
    : root_(&root),
      index_map_(root),
      data_held_(root.pages.size(), false),
      index_held_(root.index_pages.size(), false) {
  for (const package::Range& page : root.pages) data_cost_.push_back(page.size);
}

void PageScheduler::set_cost(uint32_t id, uint32_t bytes) {
  if (id >= data_cost_.size())
    throw Error("data page " + std::to_string(id) + " does not exist (" + std::to_string(data_cost_.size()) +
                " pages)");
  data_cost_[id] = bytes;
}

void PageScheduler::set_held(PageKind kind, uint32_t id, bool held) {
  std::vector<bool>& set = kind == PageKind::data ? data_held_ : index_held_;
  if (id >= set.size())
    throw Error(std::string(kind == PageKind::data ? "data" : "index") + " page " + std::to_string(id) +
                " does not exist (" + std::to_string(set.size()) + " pages)");
  set[id] = held;
}

bool PageScheduler::held(PageKind kind, uint32_t id) const {
  const std::vector<bool>& set = kind == PageKind::data ? data_held_ : index_held_;
  return id < set.size() && set[id];
}

bool PageScheduler::record_held(uint32_t id) const {
  const uint32_t page = index_page_of(id);
  return page == package::kNone || index_held_[page];
}

PageRef PageScheduler::page(PageKind kind, uint32_t id) const {
  return {kind, id, kind == PageKind::data ? data_cost_[id] : root_->index_pages[id].range.size};
}

uint32_t PageScheduler::index_page_of(uint32_t id) const {
  if (id >= root_->node_count)
    throw Error("node " + std::to_string(id) + " does not exist (" + std::to_string(root_->node_count) +
                " nodes)");
  return index_map_.page_of(id);
}

std::vector<PageRef> PageScheduler::next(const package::PackageScene& scene, const NodeSource& records,
                                         std::span<const WeightedView> views,
                                         const ScheduleOptions& options) const {
  Plan plan{*this, records, data_held_, index_held_, {}, 0, options};
  const Planned planned(records, data_held_);
  std::map<uint64_t, Exchange> exchanges;
  std::map<uint32_t, double> unknown;
  for (const WeightedView& v : views)
    collect(scene, records, select_cut(scene, planned, v.view, {options.tau, options.triangle_budget}), v,
            options.tau, exchanges, unknown);
  drawable_gates(scene, records, exchanges);

  // Records first: nothing below an unknown record can be ranked.
  std::vector<std::pair<double, uint32_t>> by_priority;
  for (auto [node, priority] : unknown) by_priority.push_back({-priority, node});
  std::sort(by_priority.begin(), by_priority.end());
  for (auto [priority, node] : by_priority) plan.add_record(node);

  // Greedy by benefit per byte among the eligible exchanges. Ratios are taken once, with the costs as of the
  // call (pages chosen during the call make shared pages cheaper; that is not re-ranked), so each pick is a
  // scan for the first eligible exchange in ratio order: O(E) cheap checks, not E cost evaluations.
  struct Ranked {
    double ratio, secondary;
    Exchange* e;
  };
  std::vector<Ranked> ranked;
  for (auto& [key, e] : exchanges)
    if (const uint64_t cost = plan.cost(e); cost > 0)
      ranked.push_back({e.benefit / double(cost), e.secondary / double(cost), &e});
  std::stable_sort(ranked.begin(), ranked.end(), [](const Ranked& a, const Ranked& b) {
    return std::tie(a.ratio, a.secondary) > std::tie(b.ratio, b.secondary);
  });
  size_t first = 0;  // ranked[0, first) are all done
  while (!plan.full()) {
    while (first < ranked.size() && ranked[first].e->done) ++first;
    Exchange* best = nullptr;
    for (size_t i = first; i < ranked.size(); ++i) {
      const Ranked& r = ranked[i];
      if (r.e->done || !plan.eligible(*r.e)) continue;
      if (plan.cost(*r.e) == 0) {
        r.e->done = true;
        continue;
      }
      best = r.e;
      break;
    }
    if (!best) break;
    for (const auto* ids : {&best->p, &best->g})
      for (uint32_t n : *ids) plan.add_record(n);
    for (uint32_t n : best->g) plan.add(PageKind::data, records.record(n)->page);
  }
  return plan.order;
}

std::vector<PageRef> PageScheduler::next_sse(const package::PackageScene& scene, const NodeSource& records,
                                             const View& view, const ScheduleOptions& options) const {
  Plan plan{*this, records, data_held_, index_held_, {}, 0, options};
  const Planned planned(records, data_held_);
  const Cut cut = select_cut(scene, planned, view, {options.tau, options.triangle_budget});
  for (const MissingNode& m : cut.missing) {
    plan.add_record(m.node);
    if (m.record_known) plan.add(PageKind::data, records.record(m.node)->page);
    if (plan.full()) break;
  }
  return plan.order;
}

}  // namespace lodstream::schedule
