// The streaming simulator of `lodstream bench stream` (issue 6, DESIGN.md Measuring quality): a deterministic
// discrete-event simulation of one client following a camera path at a fixed frame rate over a simulated
// link (net's LinkDirection each way: token bucket + delay line, on a virtual clock), selecting each frame's
// cut (schedule::select_cut) from what has arrived, and measuring it (runtime::frame_quality). No wall clock,
// no sockets, no GL: the same input gives the same frames, bit for bit.
//
// Transfers (every policy pays the same): the client first fetches the file's last max(64 KiB, root index +
// 64 B) bytes (one suffix request, as PackageReader::open does), then index pages and data pages, one page
// per request. A request costs kRequestBytes on the uplink when the client sends it; the server answers when
// it arrives, with the page's stored bytes plus kResponseHeaderBytes on the downlink; the page is usable from
// the first frame at or after its last byte arrives. The client's cache has no budget here (nothing evicted).
//
// Policies (DESIGN.md):
//   full        after the root index, one request for every data page holding a finest-level node (a node
//   with
//               no children), in file order, answered as one stream; nothing is drawn until all have arrived,
//               then the finest cut (every finest node of every object in the frustum);
//   sse-pull    each frame, the scheduler's sse-pull ranking (schedule::PageScheduler::next_sse: the pages of
//               the nodes the view's ideal cut misses, counting requested pages as held, in decreasing order
//               of the projected error their arrival removes; an unknown record asks for its index page
//               first) gives the pages to request, up to 20 requests outstanding (cesium-native's default);
//   sse-pull-3  the same with 3 (Nexus's default);
//   push        a WebSocket (its upgrade costs one request and answer, alongside the root index's request),
//               then hello, a view update every frame (pose, and velocities measured over the last frame) and
//               an ack per frame for the pages that arrived; the server is the real sans-I/O protocol core
//               (net/push_protocol.hpp: PageScheduler over predicted views, window from its link estimator,
//               file-order fill when idle), fed each message at the time it reaches the server;
//   oracle      the same PageScheduler with the same horizons and weights, given the path's true future views
//               (from half an RTT ahead) and the true link: each frame it tops the bytes in flight up to the
//               push server's window (window_bdp bandwidth-delay products); it starts when a push hello would
//               reach the server (1.5 RTT) and sends nothing once the views' ideal cuts are sent (no fill).
// Pushed pages cost their wire::Page message in a WebSocket frame; client messages their encoded size in a
// masked frame.
//
// Frame time is the cost model's prediction (CostModel), so runs are reproducible; frames stay on the fixed
// 1/fps timeline whatever that prediction is. After the path's last key frame the client keeps the last pose
// until it has converged (nothing left to fetch for that view) or `settle_s` has passed; the last frame is
// that one.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "net/link_model.hpp"
#include "package/reader.hpp"
#include "schedule/camera_path.hpp"
#include "schedule/cut.hpp"

namespace lodstream::cli {

enum class Policy { full, sse_pull, sse_pull_3, push, oracle };

const char* policy_name(Policy policy);
// Parses a comma-separated list of policy names; throws lodstream::Error naming the unknown one.
std::vector<Policy> parse_policies(const std::string& list);

inline constexpr size_t kRequestBytes = 250;         // an HTTP/1.1 Range request with its headers
inline constexpr size_t kResponseHeaderBytes = 300;  // a 206 response's status line and headers

// Predicted frame time of drawing `triangles` (Gobbetti & Bouvier's linear cost model, seed 002: a fixed cost
// plus a cost per triangle), calibrated once on this machine's Mesa llvmpipe at 1280x720: 125 ms per million
// triangles (BENCHMARKS.md, Rendering: 145-154 ms per 1.2 M on an idle machine) and 8 ms per frame (clear,
// fragment shading of a full frame, read back).
struct CostModel {
  double fixed_ms = 8.0;
  double ms_per_million_triangles = 125.0;
  double frame_ms(uint64_t triangles) const {
    return fixed_ms + ms_per_million_triangles * 1e-6 * double(triangles);
  }
};

// What the simulator needs of a package: its whole index (read once from the local file) and the stored size
// of every part.
struct PackageFacts {
  package::PackageScene scene;
  std::vector<package::NodeRecord> nodes;  // every record, by id
  uint32_t root_nodes = 0;                 // ids below are in the root index
  std::vector<uint32_t> index_page_of;     // per node id >= root_nodes: its index page (else kNone)
  std::vector<uint32_t> index_page_bytes;  // stored size of each index page
  std::vector<uint32_t> page_bytes;        // stored size of each data page
  uint64_t root_fetch_bytes = 0;           // the first suffix request's answer
  std::vector<std::vector<uint32_t>>
      finest_nodes;  // per representation: its nodes with no children, no proxy
  std::shared_ptr<const package::PackageReader> reader;  // every index page loaded (the push server's)

  // Reads every index page of `reader` (one read each) and keeps a copy of it.
  static PackageFacts of(package::PackageReader& reader);
};

struct SimOptions {
  LinkSettings link;
  double tau = 1.0;  // target pixel error
  double fps = 30.0;
  double settle_s = 10.0;
  CostModel cost;
  // Frames whose cut is kept for image metrics: every `sample_every_s`, plus those at 1, 2 and 5 s and the
  // last one; none when 0.
  double sample_every_s = 1.0;
};

// One row of the per-frame CSV (DESIGN.md's columns).
struct FrameRow {
  double t = 0.0;      // seconds since the start
  uint64_t bytes = 0;  // received so far (answers whose last byte has arrived)
  uint32_t nodes = 0;  // drawn (an instanced node counted once per object)
  uint64_t triangles = 0;
  double pixel_error_max = 0.0, pixel_error_mean = 0.0, benefit_ratio = 0.0, frame_ms = 0.0;
  bool converged = false;  // nothing left to fetch for this view
};

// A frame kept for image metrics: its camera and what it drew.
struct FrameSample {
  size_t frame = 0;  // index into SimResult::frames
  Camera camera;
  std::vector<schedule::DrawnNode> drawn;
};

struct SimResult {
  Policy policy = Policy::full;
  std::vector<FrameRow> frames;
  std::vector<FrameSample> samples;
};

// Runs one policy.
SimResult simulate(const PackageFacts& package, const schedule::CameraPath& path, Policy policy,
                   const SimOptions& options);

// finest_cut.hpp's finest_pages and finest_cut over the whole package: what `full` fetches and draws, and
// what image metrics compare against.
std::vector<uint32_t> finest_pages(const PackageFacts& package);
schedule::Cut finest_cut(const PackageFacts& package, const schedule::View& view);

}  // namespace lodstream::cli
