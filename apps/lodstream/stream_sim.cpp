#include "stream_sim.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <sstream>
#include <utility>

#include "core/error.hpp"
#include "finest_cut.hpp"
#include "net/push_protocol.hpp"
#include "net/wire.hpp"
#include "runtime/quality.hpp"
#include "schedule/page_scheduler.hpp"

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
      : index_pages(p.index_page_bytes.size(), 0), pages(p.page_bytes.size(), 0), p_(&p) {}

  const package::NodeRecord* record(uint32_t id) const override {
    if (!root || id >= p_->nodes.size()) return nullptr;
    return id < p_->root_nodes || index_pages[p_->index_page_of[id]] ? &p_->nodes[id] : nullptr;
  }
  bool available(uint32_t id) const override { return record(id) && pages[p_->nodes[id].page]; }

  bool root = false;                        // the root index arrived
  std::vector<uint8_t> index_pages, pages;  // 1 once arrived

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
  enum Kind : uint8_t { root, handshake, index_page, page, all_finest } kind = root;
  uint32_t id = 0;
  double arrival = 0.0;
  uint64_t bytes = 0;
  uint32_t sequence = 0;  // of a pushed page
  double server_time = 0.0;
};

// Both directions of the simulated link: client messages in flight to the server, and transfers in flight
// to the client (each direction one FIFO path: delivered in the order sent).
class Link {
 public:
  explicit Link(const LinkSettings& settings) : up_(settings), down_(reseeded(settings)) {}
  // The client sends `bytes` at `now`; returns when they reach the server.
  double send_up(double now, size_t bytes) { return up_.send(now, bytes); }
  // The server sends `t` (its bytes, kind and id) at `now`.
  void send_down(double now, Transfer t) {
    t.arrival = down_.send(now, t.bytes);
    in_flight_.push_back(t);
  }
  // A request sent at `now` answered with `payload` bytes (plus a response header).
  void request(double now, Transfer::Kind kind, uint32_t id, uint64_t payload) {
    send_down(send_up(now, kRequestBytes), {kind, id, 0.0, payload + kResponseHeaderBytes});
  }
  // Pops the next transfer that has arrived by `now`, if any.
  bool arrived(double now, Transfer& out) {
    if (in_flight_.empty() || in_flight_.front().arrival > now) return false;
    out = in_flight_.front();
    in_flight_.pop_front();
    return true;
  }
  size_t outstanding() const { return in_flight_.size(); }
  // Bytes sent to the client that have not arrived by `now`.
  uint64_t bytes_in_flight(double now) const {
    uint64_t b = 0;
    for (const Transfer& t : in_flight_) b += t.arrival > now ? t.bytes : 0;
    return b;
  }

 private:
  LinkDirection up_, down_;
  std::deque<Transfer> in_flight_;
};

// WebSocket framing around a wire message: 4 bytes server to client (payload < 64 KiB: 2 + 2; larger: 10),
// 8 client to server (2 + 2 + the 4-byte mask).
size_t ws_frame(size_t payload, bool from_client) {
  return payload + (payload < 65536 ? 4 : 10) + (from_client ? 4 : 0);
}

// Downlink bytes of a pushed page of `stored` bytes: its wire::Page message in a WebSocket frame.
uint64_t pushed_page_bytes(uint32_t stored) {
  static const size_t header = wire::encode(wire::Page{}).size();
  return ws_frame(header + stored, false);
}

// The view message a client sends at `t`: its pose, and velocities measured over the last frame (what a
// client knows of its own motion).
wire::ViewUpdate view_update(const schedule::CameraPath& path, double t, double frame_s) {
  const Camera now = path.pose_at(path.start() + t), before = path.pose_at(path.start() + t - frame_s);
  const View v = View::of(now), b = View::of(before);
  wire::ViewUpdate u;
  u.client_time_s = t;
  u.eye = now.eye;
  u.forward = glm::vec3(v.forward);
  u.up = glm::vec3(v.up);
  if (t > 0.0) {
    u.velocity = (now.eye - before.eye) / float(frame_s);
    // Small-angle rotation taking the last frame's forward to this one's: axis * rate.
    u.angular_velocity = glm::vec3(glm::cross(b.forward, v.forward)) / float(frame_s);
  }
  u.fov_y_radians = glm::radians(now.fov_y_degrees);
  u.viewport_width = uint16_t(now.width);
  u.viewport_height = uint16_t(now.height);
  return u;
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
  p.reader = std::make_shared<const package::PackageReader>(reader);
  const package::RootIndex& root = reader.root();
  p.scene = root.scene;
  p.root_nodes = uint32_t(root.root_nodes.size());
  p.nodes.reserve(root.node_count);
  p.index_page_of.assign(root.node_count, kNone);
  for (uint32_t id = 0; id < root.node_count; ++id) {
    p.nodes.push_back(reader.node(id));
    if (id >= p.root_nodes) p.index_page_of[id] = reader.index_page_of(id);
  }
  p.finest_nodes = cli::finest_nodes(p.scene, AllNodes(p), uint32_t(p.nodes.size()));
  for (const package::IndexPage& ip : root.index_pages) p.index_page_bytes.push_back(ip.range.size);
  for (const package::Range& r : root.pages) p.page_bytes.push_back(r.size);
  const uint64_t file = reader.source().size();
  p.root_fetch_bytes =
      std::min<uint64_t>(file, std::max<uint64_t>(64 * 1024, reader.header().root_size + 64));
  return p;
}

std::vector<uint32_t> finest_pages(const PackageFacts& package) {
  return finest_pages(AllNodes(package), package.finest_nodes);
}

Cut finest_cut(const PackageFacts& package, const View& view) {
  return finest_cut(package.scene, AllNodes(package), package.finest_nodes, view);
}

namespace {

// Each policy's transfer logic; the frame loop (simulate) is shared.
class Transfers {
 public:
  virtual ~Transfers() = default;
  // Before the frame at `t`: server-side work due by t (pushes).
  virtual void serve(double /*t*/) {}
  // A transfer arrived (already applied to what the client holds).
  virtual void on_arrival(const Transfer& /*transfer*/, double /*t*/) {}
  // After the frame at `t` was selected: the client's requests or messages.
  virtual void after_frame(double t, const View& view, const Cut& cut) = 0;
};

// sse-pull and sse-pull-3: the scheduler's sse-pull ranking (PageScheduler::next_sse: the pages of the nodes
// the current view's ideal cut misses, in decreasing order of the projected error their arrival removes,
// counting what is requested as held), up to `window` requests outstanding.
class SsePull final : public Transfers {
 public:
  SsePull(const PackageFacts& p, Link& link, const ArrivedNodes& arrived, size_t window, double tau)
      : p_(&p), link_(&link), arrived_(&arrived), window_(window), tau_(tau), scheduler_(p.reader->root()) {}
  void after_frame(double t, const View& view, const Cut&) override {
    if (!arrived_->root || link_->outstanding() >= window_) return;
    const size_t room = window_ - link_->outstanding();
    for (const schedule::PageRef& page :
         scheduler_.next_sse(p_->scene, *arrived_, view, {tau_, UINT64_MAX, room})) {
      scheduler_.set_held(page.kind, page.id);
      link_->request(t, page.kind == schedule::PageKind::index ? Transfer::index_page : Transfer::page,
                     page.id, page.bytes);
    }
  }

 private:
  const PackageFacts* p_;
  Link* link_;
  const ArrivedNodes* arrived_;
  size_t window_;
  double tau_;
  schedule::PageScheduler scheduler_;
};

// push: the client sends hello, a view update every frame and an ack for what arrived; the server is the
// real sans-I/O protocol core (net/push_protocol.hpp), fed each message when it reaches the server and
// asked for pages then.
class Push final : public Transfers {
 public:
  Push(const PackageFacts& p, Link& link, const schedule::CameraPath& path, const SimOptions& options)
      : link_(&link), path_(&path), frame_s_(1.0 / options.fps) {
    PushProtocolOptions o;
    o.tau = options.tau;
    server_ = std::make_unique<PushProtocol>(std::make_shared<PushPackage>("sim", p.reader), o);
    // The WebSocket upgrade: one request and its answer, alongside the root index's request.
    link.request(0.0, Transfer::handshake, 0, 0);
  }
  void serve(double t) override {
    while (!to_server_.empty() && to_server_.front().first <= t) {
      const auto [at, message] = to_server_.front();
      to_server_.pop_front();
      if (auto answer = server_->on_message(message, at))
        link_->send_down(at, {Transfer::handshake, 1, 0.0, ws_frame(wire::encode(*answer).size(), false)});
      while (auto page = server_->next_page(at)) {
        Transfer tr{page->page.kind == schedule::PageKind::index ? Transfer::index_page : Transfer::page,
                    page->page.id, 0.0, pushed_page_bytes(page->page.bytes)};
        tr.sequence = page->sequence;
        tr.server_time = page->server_time_s;
        link_->send_down(at, tr);
      }
    }
  }
  void on_arrival(const Transfer& tr, double) override {
    if (tr.kind == Transfer::handshake && tr.id == 0) open_ = true;
    received_ += tr.bytes;
    if (tr.sequence) last_ = tr;
  }
  void after_frame(double t, const View&, const Cut&) override {
    if (!open_) return;
    if (!hello_sent_) {
      wire::Hello h;
      h.package = "sim";
      h.cache_budget_bytes = UINT64_MAX / 2;  // the simulated client evicts nothing
      h.viewport_width = uint16_t(path_->width());
      h.viewport_height = uint16_t(path_->height());
      send(t, h);
      hello_sent_ = true;
    }
    send(t, view_update(*path_, t, frame_s_));
    if (last_.sequence > acked_) {
      send(t, wire::Ack{last_.sequence, received_, t, last_.server_time});
      acked_ = last_.sequence;
    }
  }

 private:
  void send(double t, const wire::Message& m) {
    to_server_.push_back({link_->send_up(t, ws_frame(wire::encode(m).size(), true)), m});
  }

  Link* link_;
  const schedule::CameraPath* path_;
  double frame_s_;
  std::unique_ptr<PushProtocol> server_;
  std::deque<std::pair<double, wire::Message>> to_server_;  // (arrival at the server, message)
  bool open_ = false, hello_sent_ = false;
  uint64_t received_ = 0;
  uint32_t acked_ = 0;
  Transfer last_;  // the last pushed page received
};

// oracle: the push server's scheduler (PageScheduler, same horizons and weights) given the true views of
// the path instead of predicted ones, and the true link: at each frame it tops what is in flight up to
// window_bdp bandwidth-delay products (as the push server's window, from the true bandwidth and RTT).
// Nothing is sent once every view's ideal cut is sent (no idle fill: it would add bytes, not benefit).
class Oracle final : public Transfers {
 public:
  Oracle(const PackageFacts& p, Link& link, const schedule::CameraPath& path, const SimOptions& options)
      : p_(&p), link_(&link), path_(&path), options_(options), scheduler_(p.reader->root()), records_(p) {}
  void serve(double t) override {
    const PushProtocolOptions defaults;
    const LinkSettings& l = options_.link;
    const double window =
        std::max(defaults.window_bdp * l.bandwidth_bps / 8.0 * l.rtt_s, double(defaults.min_window_bytes));
    // The server starts when the client's hello would reach it: after the WebSocket upgrade and half an RTT.
    if (t < 1.5 * l.rtt_s) return;
    double in_flight = double(link_->bytes_in_flight(t));
    if (in_flight >= window) return;
    std::vector<schedule::WeightedView> views;
    for (double h : defaults.horizons.horizons_s) {
      const double at = std::min(path_->end(), path_->start() + t + 0.5 * l.rtt_s + h);
      views.push_back({View::of(path_->pose_at(at)), std::exp(-h / defaults.horizons.decay_s), h});
    }
    const auto pages =
        scheduler_.next(p_->scene, records_, views, {options_.tau, uint64_t(window - in_flight)});
    for (const schedule::PageRef& page : pages) {
      scheduler_.set_held(page.kind, page.id);
      link_->send_down(t, {page.kind == schedule::PageKind::index ? Transfer::index_page : Transfer::page,
                           page.id, 0.0, pushed_page_bytes(page.bytes)});
    }
  }
  void after_frame(double, const View&, const Cut&) override {}

 private:
  const PackageFacts* p_;
  Link* link_;
  const schedule::CameraPath* path_;
  SimOptions options_;
  schedule::PageScheduler scheduler_;
  AllNodes records_;
};

// full: after the root index, one request for every finest-level page, answered as one stream.
class Full final : public Transfers {
 public:
  Full(const PackageFacts& p, Link& link) : p_(&p), link_(&link) {}
  void on_arrival(const Transfer& tr, double t) override {
    if (tr.kind != Transfer::root) return;
    uint64_t all = 0;
    for (uint32_t page : finest_pages(*p_)) all += p_->page_bytes[page];
    link_->request(t, Transfer::all_finest, 0, all);
  }
  void after_frame(double, const View&, const Cut&) override {}

 private:
  const PackageFacts* p_;
  Link* link_;
};

}  // namespace

SimResult simulate(const PackageFacts& package, const schedule::CameraPath& path, Policy policy,
                   const SimOptions& options) {
  SimResult result;
  result.policy = policy;
  Link link(options.link);
  ArrivedNodes arrived(package);
  AllNodes all(package);
  bool finest_arrived = false;
  uint64_t bytes = 0;
  link.request(0.0, Transfer::root, 0, package.root_fetch_bytes);
  std::unique_ptr<Transfers> transfers;
  switch (policy) {
    case Policy::full:
      transfers = std::make_unique<Full>(package, link);
      break;
    case Policy::sse_pull:
      transfers = std::make_unique<SsePull>(package, link, arrived, 20, options.tau);
      break;
    case Policy::sse_pull_3:
      transfers = std::make_unique<SsePull>(package, link, arrived, 3, options.tau);
      break;
    case Policy::push:
      transfers = std::make_unique<Push>(package, link, path, options);
      break;
    case Policy::oracle:
      transfers = std::make_unique<Oracle>(package, link, path, options);
      break;
  }

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
    transfers->serve(t);
    Transfer tr;
    while (link.arrived(t, tr)) {
      bytes += tr.bytes;
      if (tr.kind == Transfer::root) arrived.root = true;
      if (tr.kind == Transfer::index_page) arrived.index_pages[tr.id] = 1;
      if (tr.kind == Transfer::page) arrived.pages[tr.id] = 1;
      if (tr.kind == Transfer::all_finest) finest_arrived = true;
      transfers->on_arrival(tr, t);
    }
    const Camera camera = path.pose_at(path.start() + t);
    const View view = View::of(camera);
    FrameRow row;
    row.t = t;
    row.bytes = bytes;
    Cut cut;
    if (arrived.root) {
      if (policy == Policy::full) {
        if (finest_arrived) {
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
      }
      const runtime::FrameQuality q = runtime::frame_quality(package.scene, all, cut, view, options.tau);
      row.nodes = uint32_t(cut.drawn.size());
      row.triangles = cut.triangles;
      row.pixel_error_max = q.pixel_error_max;
      row.pixel_error_mean = q.pixel_error_mean;
      row.benefit_ratio = q.benefit_ratio;
    }
    transfers->after_frame(t, view, cut);
    row.frame_ms = options.cost.frame_ms(row.triangles);
    result.frames.push_back(row);
    const bool last = k == last_frame || (k >= path_frames && row.converged);
    if (sampled(k) || (last && sample_step)) result.samples.push_back({k, camera, cut.drawn});
    if (last) break;
  }
  return result;
}

}  // namespace lodstream::cli
