// `lodstream view URL_OR_FILE --headless --path PATH.json --out DIR`: the streaming client (DESIGN.md, Client
// runtime; the command line's addresses). FILE.lods is read locally, http://HOST:PORT/…/NAME.lods is pulled
// (PageScheduler order over the views predicted from the path's motion, request window from the measured
// bandwidth-delay product, from lodstream serve or any static server), ws://HOST:PORT/NAME is pushed to
// (hello, a view update every frame, acknowledgements). Headless: follows the camera path on the wall clock
// at 30 frames per second, keeps the last pose until the cut has converged or --settle seconds have passed,
// and writes DESIGN's per-frame CSV to DIR/frames.csv. Streaming never blocks a frame: the transport runs on
// its own threads and the frame installs what has arrived.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>

#include "command.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "full_fetch.hpp"
#include "net/http_source.hpp"
#include "net/page_inbox.hpp"
#include "net/pull_fetcher.hpp"
#include "net/push_client.hpp"
#include "net/url.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "render/scene_upload.hpp"
#include "runtime/client_package.hpp"
#include "runtime/cut_geometry.hpp"
#include "schedule/camera_path.hpp"
#include "schedule/motion.hpp"

namespace lodstream::cli {
namespace {

using Clock = std::chrono::steady_clock;
using schedule::PageKind;

struct ViewOptions {
  std::string source;
  bool headless = false;
  std::string path, out;
  double pixel_error = 1.0;
  double settle_s = 10.0;
  double cache_mb = 1024.0;
  uint64_t budget = 0;  // 0: none
  std::string order = "benefit";
  int window = 0;        // pull: requests outstanding at most, over as many connections (0: from the BDP)
  int frames_every = 0;  // 0: no images
  int cuts_every = 0;    // 0: no cuts.csv
  bool json = false;
};

constexpr double kFrameRate = 30.0;

// The path's pose at t with its motion (for the scheduler's prediction): the eye's velocity and the angular
// velocity that turns the view direction from t to t + 1/30 s. Still after the path's end.
schedule::ViewSample sample_at(const schedule::CameraPath& path, double t) {
  const Camera c = path.pose_at(t);
  const schedule::View v = schedule::View::of(c);
  schedule::ViewSample s;
  s.time_s = t;
  s.eye = v.eye;
  s.forward = v.forward;
  s.up = v.up;
  s.fov_y_radians = glm::radians(double(c.fov_y_degrees));
  s.width = c.width;
  s.height = c.height;
  if (t < path.end()) {
    s.velocity = glm::dvec3(path.velocity_at(t).eye);
    const double dt = 1.0 / kFrameRate;
    const glm::dvec3 next = schedule::View::of(path.pose_at(t + dt)).forward;
    const glm::dvec3 axis = glm::cross(s.forward, next);
    const double sine = glm::length(axis);
    if (sine > 1e-12) s.angular_velocity = axis / sine * std::atan2(sine, glm::dot(s.forward, next)) / dt;
  }
  return s;
}

wire::ViewUpdate view_update(const schedule::ViewSample& s) {
  wire::ViewUpdate u;
  u.client_time_s = s.time_s;
  u.eye = glm::vec3(s.eye);
  u.forward = glm::vec3(s.forward);
  u.up = glm::vec3(s.up);
  u.velocity = glm::vec3(s.velocity);
  u.angular_velocity = glm::vec3(s.angular_velocity);
  u.fov_y_radians = float(s.fov_y_radians);
  u.viewport_width = uint16_t(s.width);
  u.viewport_height = uint16_t(s.height);
  return u;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size())))];
}

int run_view(const ViewOptions& opt) {
  if (!opt.headless) throw Error("view: only --headless is available in this build (no window yet)");
  if (opt.path.empty()) throw Error("view --headless needs --path PATH.json");
  if (opt.out.empty()) throw Error("view --headless needs --out DIR");
  if (!(opt.pixel_error > 0.0) || !std::isfinite(opt.pixel_error))
    throw Error("--pixel-error must be a positive number of pixels");
  if (!(opt.settle_s >= 0.0) || !std::isfinite(opt.settle_s)) throw Error("--settle must be >= 0 seconds");
  if (!(opt.cache_mb > 0.0) || !std::isfinite(opt.cache_mb))
    throw Error("--cache must be a positive MB count");
  if (opt.order != "benefit" && opt.order != "sse" && opt.order != "full")
    throw Error("--order must be 'benefit', 'sse' or 'full'");
  if (opt.window < 0 || opt.window > 64) throw Error("--window must be in 0..64");
  if (opt.frames_every < 0) throw Error("--frames-every must be >= 0 (0: no images)");
  if (opt.cuts_every < 0) throw Error("--cuts-every must be >= 0 (0: none)");
  const schedule::CameraPath path = schedule::load_camera_path(opt.path);
  // The clock starts before the package is opened: time to first frame includes connecting and the root
  // index, as the user waits for them (and as bench stream's simulation counts them).
  const Clock::time_point start = Clock::now();

  // The package's root index, and the transport.
  const bool push = opt.source.rfind("ws://", 0) == 0, pull = opt.source.rfind("http://", 0) == 0;
  if (push && (opt.order != "benefit" || opt.window))
    throw Error("--order and --window are for pulling (http:// or a file), not ws://");
  std::string http_url = opt.source;
  if (push) {
    const UrlParts u = split_url(opt.source, "ws://");
    http_url = "http://" + u.host + ":" + u.port + u.target + ".lods";  // the same server serves the file
  }
  std::shared_ptr<const package::ByteSource> root_source;
  if (push || pull)
    root_source = std::make_shared<HttpSource>(http_url);
  else
    root_source = std::make_shared<package::FileSource>(opt.source);
  runtime::ClientPackage client(package::PackageReader(root_source), uint64_t(opt.cache_mb * 1024 * 1024));
  const package::RootIndex& root = client.reader().root();

  PageInbox inbox;
  std::unique_ptr<PullFetcher> fetcher;
  std::unique_ptr<PushClient> pusher;
  if (push) {
    wire::Hello hello;
    hello.package = split_url(opt.source, "ws://").target.substr(1);
    hello.cache_budget_bytes = uint64_t(opt.cache_mb * 1024 * 1024);
    hello.triangles_per_frame =
        uint32_t(std::min<uint64_t>(opt.budget ? opt.budget : UINT32_MAX, UINT32_MAX));
    hello.viewport_width = uint16_t(path.width());
    hello.viewport_height = uint16_t(path.height());
    pusher = std::make_unique<PushClient>(opt.source, hello, inbox);
  } else if (pull) {
    PullOptions o;
    if (opt.window) o.connections = opt.window;
    fetcher = std::make_unique<PullFetcher>([url = http_url] { return std::make_shared<HttpSource>(url); },
                                            inbox, o);
  } else {
    PullOptions local;
    local.connections = 1;
    local.min_window_bytes = 8u << 20;
    fetcher = std::make_unique<PullFetcher>(
        [file = opt.source] { return std::make_shared<package::FileSource>(file); }, inbox, local);
  }

  std::unique_ptr<FullFetch> full = opt.order == "full" ? std::make_unique<FullFetch>() : nullptr;
  schedule::CutOptions cut_options;
  cut_options.tau = opt.pixel_error;
  if (opt.budget) cut_options.triangle_budget = opt.budget;
  const std::filesystem::path dir(opt.out);
  std::filesystem::create_directories(dir);
  // Images of the frames (--frames-every): the cut's geometry from the cache, drawn headless.
  std::unique_ptr<render::Context> context;
  std::unique_ptr<render::Renderer> renderer;
  std::unique_ptr<runtime::CutGeometry> geometry;
  const std::filesystem::path package_dir =
      push || pull ? std::filesystem::path() : std::filesystem::path(opt.source).parent_path();
  if (opt.frames_every > 0) {
    context = render::create_headless_context();
    renderer = std::make_unique<render::Renderer>(*context);
    geometry = std::make_unique<runtime::CutGeometry>(client.reader(), package_dir);
  }
  auto draw = [&](uint64_t frame, const runtime::Frame& f, const Camera& camera) {
    geometry->update(
        f.cut, runtime::pages_from_cache(client.reader(), client.cache(), runtime::CachedPages::unpacked));
    const render::SceneUpload upload = render::upload_scene(*renderer, geometry->scene());
    renderer->draw(camera, upload.items);
    char name[64];
    std::snprintf(name, sizeof name, "frame_%05llu.png", (unsigned long long)frame);
    save_png(renderer->read_pixels(), dir / name);
  };
  std::string csv = "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms\n";
  std::string cuts = "frame,drawn\n";  // --cuts-every: the drawn nodes of recorded frames
  std::vector<double> frame_ms;
  std::optional<double> first_frame_s, time_095_s;
  runtime::Frame last;
  bool converged = false;
  double t = 0.0;
  // Frames keep to the 1/30 s slots since the start; the first is the first slot after the set-up.
  const double first_slot =
      std::ceil(std::chrono::duration<double>(Clock::now() - start).count() * kFrameRate);
  for (uint64_t i = 0;; ++i) {
    std::this_thread::sleep_until(start +
                                  std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>((first_slot + double(i)) / kFrameRate)));
    const Clock::time_point frame_start = Clock::now();
    t = std::chrono::duration<double>(frame_start - start).count();
    if (std::string error = inbox.error(); !error.empty()) throw Error(error);
    for (ArrivedPage& a : inbox.take()) client.install(a.page.kind, a.page.id, a.bytes);

    const schedule::ViewSample now = sample_at(path, t);
    const auto predicted = schedule::predicted_views(now, 0.0);
    std::vector<schedule::View> ahead;
    for (size_t k = 1; k < predicted.size(); ++k) ahead.push_back(predicted[k].view);
    if (full) {
      full->request(client, *fetcher);
    } else if (fetcher) {
      const uint64_t in_flight = fetcher->in_flight_bytes(), window = fetcher->window_bytes();
      const size_t requests = client.in_flight(), max_requests = size_t(opt.window);
      if (opt.window ? requests < max_requests : in_flight < window) {
        const schedule::ScheduleOptions s =
            opt.window ? schedule::ScheduleOptions{opt.pixel_error, UINT64_MAX, max_requests - requests}
                       : schedule::ScheduleOptions{opt.pixel_error, window - in_flight, SIZE_MAX};
        const auto pages =
            opt.order == "sse"
                ? client.scheduler().next_sse(client.scene(), client.nodes(), predicted[0].view, s)
                : client.scheduler().next(client.scene(), client.nodes(), predicted, s);
        for (const schedule::PageRef& p : pages) {
          client.requested(p);
          fetcher->request(p, p.kind == PageKind::data ? root.pages[p.id] : root.index_pages[p.id].range);
        }
      }
    } else {
      pusher->send_view(view_update(now));
    }
    last = full ? full->frame(client, predicted[0].view, opt.pixel_error)
                : client.frame(predicted[0].view, ahead, cut_options);
    const bool final_pose = t >= path.end();
    const bool done = final_pose && (last.cut.converged() || t >= path.end() + opt.settle_s);
    if (geometry && (i % uint64_t(opt.frames_every) == 0 || done)) draw(i, last, path.pose_at(t));
    if (opt.cuts_every && ((uint64_t(first_slot) + i) % uint64_t(opt.cuts_every) == 0 || done)) {
      cuts += std::to_string(i) + ",";  // then OBJECT:NODE per drawn node, space-separated (none: empty)
      for (const schedule::DrawnNode& d : last.cut.drawn)
        cuts += (&d == last.cut.drawn.data() ? "" : " ") + std::to_string(d.object) + ":" +
                std::to_string(d.node);
      cuts += "\n";
    }
    const double ms = 1e3 * std::chrono::duration<double>(Clock::now() - frame_start).count();
    frame_ms.push_back(ms);
    if (!first_frame_s && !last.cut.drawn.empty()) first_frame_s = t;
    if (!time_095_s && last.quality.benefit_ratio >= 0.95) time_095_s = t;
    char row[256];
    std::snprintf(row, sizeof row, "%.4f,%llu,%zu,%llu,%.6g,%.6g,%.6f,%.3f\n", t,
                  (unsigned long long)client.bytes_received(), last.cut.drawn.size(),
                  (unsigned long long)last.cut.triangles, last.quality.pixel_error_max,
                  last.quality.pixel_error_mean, last.quality.benefit_ratio, ms);
    csv += row;
    if (final_pose) converged = last.cut.converged();
    if (done) break;
  }

  auto write = [&](const std::string& name, const std::string& text) {
    const auto tmp = dir / (name + ".tmp");
    {
      std::ofstream f(tmp, std::ios::binary);
      f << text;
      if (!f) throw Error((dir / name).string() + ": cannot write");
    }
    std::filesystem::rename(tmp, dir / name);
  };
  write("frames.csv", csv);
  if (opt.cuts_every) write("cuts.csv", cuts);

  nlohmann::json j;
  j["mode"] = push ? "push" : pull ? "pull" : "file";
  j["frames"] = frame_ms.size();
  j["duration_s"] = t;
  j["converged"] = converged;
  j["bytes"] = client.bytes_received();
  j["time_to_first_frame_s"] = first_frame_s ? nlohmann::json(*first_frame_s) : nlohmann::json(nullptr);
  j["time_to_095_s"] = time_095_s ? nlohmann::json(*time_095_s) : nlohmann::json(nullptr);
  j["benefit_ratio"] = last.quality.benefit_ratio;
  j["pixel_error_max"] = last.quality.pixel_error_max;
  j["nodes"] = last.cut.drawn.size();
  j["triangles"] = last.cut.triangles;
  j["frame_ms_p50"] = percentile(frame_ms, 0.5);
  j["frame_ms_p99"] = percentile(frame_ms, 0.99);
  j["csv"] = (dir / "frames.csv").string();
  if (opt.json) {
    print_json(j);
  } else {
    std::printf("%s: %s, %zu frames in %.2f s, %llu bytes, benefit ratio %.4f, %s\n", opt.source.c_str(),
                j["mode"].get<std::string>().c_str(), frame_ms.size(), t,
                (unsigned long long)client.bytes_received(), last.quality.benefit_ratio,
                converged ? "converged" : "not converged");
  }
  return 0;
}

const bool registered = register_command(
    {"view", "the streaming client: follow a camera path over a local, pulled or pushed package",
     [](CLI::App& sub) {
       auto opt = std::make_shared<ViewOptions>();
       sub.add_option("source", opt->source,
                      "FILE.lods, http://HOST:PORT/…/NAME.lods (pull) or ws://HOST:PORT/NAME (push)")
           ->required();
       sub.add_flag("--headless", opt->headless, "no window: follow --path and write --out/frames.csv");
       sub.add_option("--path", opt->path, "camera path JSON (DESIGN.md)")->check(CLI::ExistingFile);
       sub.add_option("--out", opt->out, "directory for frames.csv");
       sub.add_option("--pixel-error", opt->pixel_error, "target pixel error tau")->capture_default_str();
       sub.add_option("--settle", opt->settle_s, "seconds to keep the last pose until converged")
           ->capture_default_str();
       sub.add_option("--cache", opt->cache_mb, "page cache budget, MB")->capture_default_str();
       sub.add_option("--budget", opt->budget, "triangles drawn per frame at most (0: no limit)");
       sub.add_option("--order", opt->order,
                      "pull order: benefit (benefit per byte, predicted), sse, or full (the finest level's "
                      "pages in file order, nothing drawn until all arrived)")
           ->capture_default_str();
       sub.add_option(
              "--window", opt->window,
              "pull: at most N requests outstanding, over N connections (0: a window of bytes from the "
              "measured bandwidth-delay product)")
           ->capture_default_str();
       sub.add_option("--cuts-every", opt->cuts_every,
                      "write the drawn cut (a row per frame: its CSV row, then OBJECT:NODE per drawn node) "
                      "to DIR/cuts.csv "
                      "every N frames on the 1/30 s slots since the start, and the final frame (0: none)");
       sub.add_option("--frames-every", opt->frames_every,
                      "write DIR/frame_NNNNN.png every N frames and the final frame (0: none)");
       sub.add_flag("--json", opt->json, "print a JSON summary");
       sub.footer(
           "CSV columns: t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms\n"
           "(one row per frame at 30 frames/s; the last row is the final frame).");
       return [opt] { return run_view(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
