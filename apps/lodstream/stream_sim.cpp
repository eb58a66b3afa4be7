#include "stream_sim.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <sstream>

#include "core/error.hpp"
#include "runtime/quality.hpp"

namespace lodstream::cli {
namespace {

using package::kNone;
using schedule::Cut;
using schedule::View;

// What the client has received: node records known (root index, arrived index pages) and nodes available
// (their data page arrived).
class ArrivedNodes final : public schedule::NodeSource {
 public:
  explicit ArrivedNodes(const PackageFacts& p)
      : index_pages_(p.index_page_bytes.size(), 0), pages_(p.page_bytes.size(), 0), p_(&p) {}

  const package::NodeRecord* record(uint32_t id) const override {
    if (id >= p_->nodes.size()) return nullptr;
    return id < p_->root_nodes || index_pages_[p_->index_page_of[id]] ? &p_->nodes[id] : nullptr;
  }
  bool available(uint32_t id) const override { return record(id) && pages_[p_->nodes[id].page]; }

  std::vector<uint8_t> index_pages_, pages_;  // 1 once arrived

 private:
  const PackageFacts* p_;
};

// Every record known and every node available: for measuring a cut drawn from a complete package.
class AllNodes final : public schedule::NodeSource {
 public:
  explicit AllNodes(const PackageFacts& p) : p_(&p) {}
  const package::NodeRecord* record(uint32_t id) const override {
    return id < p_->nodes.size() ? &p_->nodes[id] : nullptr;
  }
  bool available(uint32_t id) const override { return id < p_->nodes.size(); }

 private:
  const PackageFacts* p_;
};

// The downlink's jitter differs from the uplink's.
LinkSettings reseeded(LinkSettings settings) {
  ++settings.seed;
  return settings;
}

// A transfer in flight: what it carries and when its last byte arrives.
struct Transfer {
  enum Kind : uint8_t { root, index_page, page } kind = root;
  uint32_t id = 0;
  double arrival = 0.0;
  uint64_t bytes = 0;
};

// Both directions of the simulated link and the transfers in flight (delivered in order: the downlink is
// one FIFO path).
class Link {
 public:
  explicit Link(const LinkSettings& settings) : up_(settings), down_(reseeded(settings)) {}
  // A request sent at `now` answered with `bytes` of payload.
  void request(double now, Transfer::Kind kind, uint32_t id, uint64_t payload) {
    const double at_server = up_.send(now, kRequestBytes);
    const uint64_t bytes = payload + kResponseHeaderBytes;
    in_flight_.push_back({kind, id, down_.send(at_server, bytes), bytes});
  }
  // Pops the next transfer that has arrived by `now`, if any.
  bool arrived(double now, Transfer& out) {
    if (in_flight_.empty() || in_flight_.front().arrival > now) return false;
    out = in_flight_.front();
    in_flight_.pop_front();
    return true;
  }
  size_t outstanding() const { return in_flight_.size(); }

 private:
  LinkDirection up_, down_;
  std::deque<Transfer> in_flight_;
};

size_t window_of(Policy policy) {
  return policy == Policy::sse_pull_3 ? 3 : 20;
}

}  // namespace

const char* policy_name(Policy policy) {
  switch (policy) {
    case Policy::full:
      return "full";
    case Policy::sse_pull:
      return "sse-pull";
    case Policy::sse_pull_3:
      return "sse-pull-3";
    case Policy::push:
      return "push";
    case Policy::oracle:
      return "oracle";
  }
  return "?";
}

std::vector<Policy> parse_policies(const std::string& list) {
  std::vector<Policy> out;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    bool found = false;
    for (Policy p : {Policy::full, Policy::sse_pull, Policy::sse_pull_3, Policy::push, Policy::oracle}) {
      if (name == policy_name(p)) {
        if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
        found = true;
      }
    }
    if (!found)
      throw Error("--policy: unknown policy '" + name +
                  "' (known: full, sse-pull, sse-pull-3, push, oracle)");
  }
  if (out.empty()) throw Error("--policy: give at least one policy");
  return out;
}

PackageFacts PackageFacts::of(package::PackageReader& reader) {
  PackageFacts p;
  const package::RootIndex& root = reader.root();
  p.scene = root.scene;
  p.root_nodes = uint32_t(root.root_nodes.size());
  p.nodes.reserve(root.node_count);
  p.index_page_of.assign(root.node_count, kNone);
  for (uint32_t id = 0; id < root.node_count; ++id) {
    p.nodes.push_back(reader.node(id));
    if (id >= p.root_nodes) p.index_page_of[id] = reader.index_page_of(id);
  }
  p.finest_nodes.resize(p.scene.representations.size());
  for (uint32_t id = 0; id < p.nodes.size(); ++id)
    if (p.nodes[id].children.empty()) p.finest_nodes[p.nodes[id].representation].push_back(id);
  for (const package::IndexPage& ip : root.index_pages) p.index_page_bytes.push_back(ip.range.size);
  for (const package::Range& r : root.pages) p.page_bytes.push_back(r.size);
  const uint64_t file = reader.source().size();
  p.root_fetch_bytes =
      std::min<uint64_t>(file, std::max<uint64_t>(64 * 1024, reader.header().root_size + 64));
  return p;
}

Cut finest_cut(const PackageFacts& package, const View& view) {
  Cut cut;
  const auto& objects = package.scene.objects;
  cut.objects.assign(objects.size(), schedule::ObjectState::culled);
  for (uint32_t o = 0; o < objects.size(); ++o) {
    if (!schedule::in_frustum(schedule::object_sphere(package.scene, o), view)) continue;
    cut.objects[o] = schedule::ObjectState::drawn;
    const double scale = schedule::max_scale(objects[o].transform);
    for (uint32_t id : package.finest_nodes[objects[o].representation]) {
      const package::NodeRecord& n = package.nodes[id];
      const double e = schedule::screen_error(
          double(n.error) * scale, schedule::to_world(n.sphere, objects[o].transform, scale), view);
      cut.drawn.push_back({o, id, e, n.triangles});
      cut.triangles += n.triangles;
    }
  }
  cut.ideal_triangles = cut.triangles;
  return cut;
}

SimResult simulate(const PackageFacts& package, const schedule::CameraPath& path, Policy policy,
                   const SimOptions& options) {
  if (policy == Policy::push || policy == Policy::oracle)
    throw Error(std::string("--policy ") + policy_name(policy) +
                ": needs the server-side scheduler (schedule/page_scheduler.hpp), not in this build yet");
  SimResult result;
  result.policy = policy;
  Link link(options.link);
  ArrivedNodes arrived(package);
  AllNodes all(package);
  std::vector<uint8_t> requested_pages(package.page_bytes.size(), 0),
      requested_index(package.index_page_bytes.size(), 0);
  bool root_arrived = false;
  uint64_t bytes = 0;
  link.request(0.0, Transfer::root, 0, package.root_fetch_bytes);

  // `full`: the finest level's pages, all requested in one go once the root index is there.
  std::vector<uint32_t> finest_pages;
  for (const auto& nodes : package.finest_nodes)
    for (uint32_t id : nodes) finest_pages.push_back(package.nodes[id].page);
  std::sort(finest_pages.begin(), finest_pages.end());
  finest_pages.erase(std::unique(finest_pages.begin(), finest_pages.end()), finest_pages.end());
  size_t finest_arrived = 0;

  const double fps = options.fps;
  const double duration = path.end() - path.start();
  const size_t path_frames = size_t(std::ceil(duration * fps - 1e-9));
  const size_t last_frame = size_t(std::floor((duration + options.settle_s) * fps + 1e-9));
  const size_t sample_step = options.sample_every_s > 0.0
                                 ? std::max<size_t>(1, size_t(std::lround(options.sample_every_s * fps)))
                                 : 0;
  auto sampled = [&](size_t k) {
    if (!sample_step) return false;
    if (k % sample_step == 0) return true;
    for (double s : {1.0, 2.0, 5.0})
      if (k == size_t(std::lround(s * fps))) return true;
    return false;
  };

  for (size_t k = 0; k <= last_frame; ++k) {
    const double t = double(k) / fps;
    Transfer tr;
    while (link.arrived(t, tr)) {
      bytes += tr.bytes;
      if (tr.kind == Transfer::root) {
        root_arrived = true;
        if (policy == Policy::full) {
          uint64_t all_bytes = 0;
          for (uint32_t p : finest_pages) all_bytes += package.page_bytes[p];
          link.request(t, Transfer::page, kNone, all_bytes);  // one response streams them all
        }
      } else if (tr.kind == Transfer::index_page) {
        arrived.index_pages_[tr.id] = 1;
      } else if (tr.id == kNone) {
        finest_arrived = finest_pages.size();
      } else {
        arrived.pages_[tr.id] = 1;
      }
    }
    const Camera camera = path.pose_at(path.start() + t);
    const View view = View::of(camera);
    FrameRow row;
    row.t = t;
    row.bytes = bytes;
    Cut cut;
    if (root_arrived) {
      if (policy == Policy::full) {
        if (finest_arrived == finest_pages.size()) {
          cut = finest_cut(package, view);
          row.converged = true;
        } else {
          for (uint32_t o = 0; o < package.scene.objects.size(); ++o)
            cut.objects.push_back(schedule::in_frustum(schedule::object_sphere(package.scene, o), view)
                                      ? schedule::ObjectState::incomplete
                                      : schedule::ObjectState::culled);
        }
      } else {
        cut = schedule::select_cut(package.scene, arrived, view, {options.tau});
        row.converged = cut.converged();
        // Requests, in the cut's order of missing nodes, up to the window.
        for (const schedule::MissingNode& m : cut.missing) {
          if (link.outstanding() >= window_of(policy)) break;
          if (!m.record_known) {
            const uint32_t ip = package.index_page_of[m.node];
            if (requested_index[ip]) continue;
            requested_index[ip] = 1;
            link.request(t, Transfer::index_page, ip, package.index_page_bytes[ip]);
          } else {
            const uint32_t p = package.nodes[m.node].page;
            if (requested_pages[p]) continue;
            requested_pages[p] = 1;
            link.request(t, Transfer::page, p, package.page_bytes[p]);
          }
        }
      }
      const runtime::FrameQuality q = runtime::frame_quality(package.scene, all, cut, view, options.tau);
      row.nodes = uint32_t(cut.drawn.size());
      row.triangles = cut.triangles;
      row.pixel_error_max = q.pixel_error_max;
      row.pixel_error_mean = q.pixel_error_mean;
      row.benefit_ratio = q.benefit_ratio;
    }
    row.frame_ms = options.cost.frame_ms(row.triangles);
    result.frames.push_back(row);
    const bool last = k == last_frame || (k >= path_frames && row.converged);
    if (sampled(k) || (last && sample_step)) result.samples.push_back({k, camera, cut.drawn});
    if (last) break;
  }
  return result;
}

}  // namespace lodstream::cli
