// `lodstream view URL_OR_FILE`: the streaming client (DESIGN.md, Client runtime; the command line's
// addresses), over a ViewClient (view_client.hpp: FILE.lods read locally, http://HOST:PORT/…/NAME.lods
// pulled, ws://HOST:PORT/NAME pushed to). In a window (GLFW) it flies with mouse and keyboard
// (fly_camera.hpp), the scheduling following the interactive camera and its measured motion; the window's
// title is the on-screen line (frame time, triangles, bytes received, pixel error). `--headless --path
// PATH.json --out DIR` follows the camera path on the wall clock at 30 frames per second, keeps the last pose
// until the cut has converged or --settle seconds have passed, and writes DESIGN's per-frame CSV to
// DIR/frames.csv. Streaming never blocks a frame: the transport and the pull scheduler run on threads of
// their own; the frame installs what has arrived, selects the cut and draws.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>

#include "command.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "cut_drawer.hpp"
#include "fly_camera.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "runtime/cut_geometry.hpp"
#include "scene_bounds.hpp"
#include "schedule/camera_path.hpp"
#include "schedule/path_gen.hpp"
#include "view_client.hpp"
#include "view_motion.hpp"

namespace lodstream::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct ViewOptions {
  std::string source;
  bool headless = false;
  std::string path, out;
  double pixel_error = 1.0;
  double settle_s = 10.0;
  double cache_mb = 1024.0;
  std::string cache_dir;  // empty: the cache lives in memory only
  uint64_t budget = 0;    // 0: none
  std::string order = "benefit";
  int window = 0;        // pull: requests outstanding at most, over as many connections (0: from the BDP)
  int frames_every = 0;  // 0: no images
  int cuts_every = 0;    // 0: no cuts.csv
  bool json = false;
  // Window mode.
  uint64_t frames = 0;  // exit after this many frames (0: when the window closes)
  std::string screenshot, up = "0,1,0", size = "1280x720";
};

constexpr double kFrameRate = 30.0;   // headless: the path's frame timeline
constexpr double kWindowRate = 60.0;  // window: frames per second at most

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size())))];
}

ViewClientOptions client_options(const ViewOptions& opt, int width, int height) {
  ViewClientOptions o;
  o.pixel_error = opt.pixel_error;
  o.cache_mb = opt.cache_mb;
  o.budget = opt.budget;
  o.order = opt.order;
  o.window = opt.window;
  o.cache_dir = opt.cache_dir;
  o.width = width;
  o.height = height;
  return o;
}

void write_file(const std::filesystem::path& file, const std::string& text) {
  write_file_atomically(file, text.data(), text.size());
}

// Summary of a run, printed as JSON (--json) or one line.
void report(const ViewOptions& opt, const char* mode, nlohmann::json j, const std::vector<double>& frame_ms) {
  j["mode"] = mode;
  j["frames"] = frame_ms.size();
  j["frame_ms_p50"] = percentile(frame_ms, 0.5);
  j["frame_ms_p99"] = percentile(frame_ms, 0.99);
  if (opt.json) {
    print_json(j);
    return;
  }
  std::printf("%s: %s, %zu frames in %.2f s, %llu bytes, benefit ratio %.4f, frame ms p50 %.1f%s\n",
              opt.source.c_str(), mode, frame_ms.size(), j["duration_s"].get<double>(),
              (unsigned long long)j["bytes"].get<uint64_t>(), j["benefit_ratio"].get<double>(),
              j["frame_ms_p50"].get<double>(),
              j.contains("converged") ? (j["converged"] == true ? ", converged" : ", not converged") : "");
}

int run_headless(const ViewOptions& opt) {
  if (opt.path.empty()) throw Error("view --headless needs --path PATH.json");
  if (opt.out.empty()) throw Error("view --headless needs --out DIR");
  const schedule::CameraPath path = schedule::load_camera_path(opt.path);
  // The clock starts before the package is opened: time to first frame includes connecting and the root
  // index, as the user waits for them (and as bench stream's simulation counts them).
  const Clock::time_point start = Clock::now();
  ViewClient client(opt.source, client_options(opt, path.width(), path.height()));

  const std::filesystem::path dir(opt.out);
  std::filesystem::create_directories(dir);
  // Images of the frames (--frames-every): the cut's geometry from the cache, drawn headless.
  std::unique_ptr<render::Context> context;
  std::unique_ptr<render::Renderer> renderer;
  std::unique_ptr<runtime::CutGeometry> geometry;
  std::unique_ptr<CutDrawer> drawer;
  if (opt.frames_every > 0) {
    context = render::create_headless_context();
    renderer = std::make_unique<render::Renderer>(*context);
    geometry = std::make_unique<runtime::CutGeometry>(client.package().reader(), client.package_dir(),
                                                      2'000'000, runtime::TextureLoading::background);
    drawer = std::make_unique<CutDrawer>(*renderer, geometry->materials());
  }
  runtime::ClientPackage& package = client.package();
  auto draw = [&](uint64_t frame, const runtime::Frame& f, const Camera& camera) {
    geometry->update(
        f.cut, runtime::pages_from_cache(package.reader(), package.cache(), runtime::CachedPages::unpacked));
    renderer->draw(camera, drawer->items(*geometry));
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
  const double first_slot = std::ceil(seconds_since(start) * kFrameRate);
  const double dt = 1.0 / kFrameRate;
  for (uint64_t i = 0;; ++i) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>((first_slot + double(i)) * dt)));
    const Clock::time_point frame_start = Clock::now();
    t = std::chrono::duration<double>(frame_start - start).count();
    const Camera pose = path.pose_at(t);
    last = client.frame(view_sample(pose, t, pose, path.pose_at(t + dt), dt));
    const bool final_pose = t >= path.end();
    const bool done = final_pose && (last.cut.converged() || t >= path.end() + opt.settle_s);
    if (geometry && (i % uint64_t(opt.frames_every) == 0 || done)) draw(i, last, pose);
    if (opt.cuts_every && ((uint64_t(first_slot) + i) % uint64_t(opt.cuts_every) == 0 || done)) {
      cuts += std::to_string(i) + ",";  // then OBJECT:NODE per drawn node, space-separated (none: empty)
      for (const schedule::DrawnNode& d : last.cut.drawn)
        cuts += (&d == last.cut.drawn.data() ? "" : " ") + std::to_string(d.object) + ":" +
                std::to_string(d.node);
      cuts += "\n";
    }
    const double ms = 1e3 * seconds_since(frame_start);
    frame_ms.push_back(ms);
    if (!first_frame_s && !last.cut.drawn.empty()) first_frame_s = t;
    if (!time_095_s && last.quality.benefit_ratio >= 0.95) time_095_s = t;
    char row[256];
    std::snprintf(row, sizeof row, "%.4f,%llu,%zu,%llu,%.6g,%.6g,%.6f,%.3f\n", t,
                  (unsigned long long)package.bytes_received(), last.cut.drawn.size(),
                  (unsigned long long)last.cut.triangles, last.quality.pixel_error_max,
                  last.quality.pixel_error_mean, last.quality.benefit_ratio, ms);
    csv += row;
    if (final_pose) converged = last.cut.converged();
    if (done) break;
  }
  write_file(dir / "frames.csv", csv);
  if (opt.cuts_every) write_file(dir / "cuts.csv", cuts);

  nlohmann::json j;
  j["duration_s"] = t;
  j["converged"] = converged;
  j["bytes"] = package.bytes_received();
  j["bytes_restored"] = package.bytes_restored();
  j["reconnects"] = client.reconnects();
  j["time_to_first_frame_s"] = first_frame_s ? nlohmann::json(*first_frame_s) : nlohmann::json(nullptr);
  j["time_to_095_s"] = time_095_s ? nlohmann::json(*time_095_s) : nlohmann::json(nullptr);
  j["benefit_ratio"] = last.quality.benefit_ratio;
  j["pixel_error_max"] = last.quality.pixel_error_max;
  j["nodes"] = last.cut.drawn.size();
  j["triangles"] = last.cut.triangles;
  j["plans"] = client.plans();
  j["csv"] = (dir / "frames.csv").string();
  report(opt, client.mode(), j, frame_ms);
  return 0;
}

// The window's on-screen line (its title).
std::string status_line(double frame_ms, const runtime::Frame& f, uint64_t bytes, float speed) {
  char line[256];
  std::snprintf(line, sizeof line,
                "lodstream view | %.1f ms | %llu triangles | %.2f MB received | pixel error %.2f px (max) | "
                "benefit %.3f | speed %.3g/s",
                frame_ms, (unsigned long long)f.cut.triangles, double(bytes) / 1e6, f.quality.pixel_error_max,
                f.quality.benefit_ratio, speed);
  return line;
}

int run_window(const ViewOptions& opt) {
  if (!opt.out.empty()) throw Error("--out is for --headless (a window writes no CSV; see --screenshot)");
  const glm::vec3 up = parse_vec3(opt.up, "--up");
  if (glm::length(up) == 0.0f) throw Error("--up must not be the zero vector");
  auto [width, height] = parse_size(opt.size, "--size");
  std::optional<schedule::CameraPath> path;
  if (!opt.path.empty()) {
    path = schedule::load_camera_path(opt.path);
    width = path->width();
    height = path->height();
  }
  ViewClient client(opt.source, client_options(opt, width, height));
  runtime::ClientPackage& package = client.package();

  // Start pose: the path's first key frame, else the generated fly-through's (3 r out, looking at the
  // scene's centre); speed: the fly-through's, about 0.3 r per second.
  const Bounds bounds = world_bounds(package.scene());
  const float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-6f);
  Camera start;
  if (path) {
    start = path->pose_at(path->start());
  } else {
    schedule::PathGenOptions gen;
    gen.up = up;
    gen.width = width;
    gen.height = height;
    start = schedule::generate_path("fly", bounds, gen).pose_at(0.0);
  }
  FlyCamera fly(start, path ? path->keyframes().front().up : up, 0.3f * radius);

  auto window = render::create_window_context(width, height, "lodstream view " + opt.source);
  render::Renderer renderer(*window);
  runtime::CutGeometry geometry(package.reader(), client.package_dir(), 2'000'000,
                                runtime::TextureLoading::background);
  CutDrawer drawer(renderer, geometry.materials());
  for (const std::string& w : drawer.warnings()) std::fprintf(stderr, "lodstream: warning: %s\n", w.c_str());

  std::vector<double> frame_ms;
  runtime::Frame last;
  const Clock::time_point start_time = Clock::now();
  Camera previous = fly.camera(width, height);
  double previous_t = 0.0, title_t = -1.0;
  for (uint64_t i = 0; opt.frames == 0 || i < opt.frames; ++i) {
    std::this_thread::sleep_until(start_time + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(double(i) / kWindowRate)));
    const Clock::time_point frame_start = Clock::now();
    const double t = seconds_since(start_time);
    if (!window->poll_events() || window->input().quit) break;
    fly.update(window->input(), t - previous_t);
    const auto [fb_width, fb_height] = window->framebuffer_size();
    if (fb_width <= 0 || fb_height <= 0) continue;  // minimised
    const Camera camera = fly.camera(fb_width, fb_height);
    // The view sample's motion: measured from the previous frame's pose.
    const double dt = std::max(t - previous_t, 1e-3);
    last = client.frame(view_sample(camera, t, i ? previous : camera, camera, dt));
    previous = camera;
    previous_t = t;
    geometry.update(last.cut, runtime::pages_from_cache(package.reader(), package.cache(),
                                                        runtime::CachedPages::unpacked));
    renderer.draw(camera, drawer.items(geometry));
    renderer.present(fb_width, fb_height);
    window->swap_buffers();
    frame_ms.push_back(1e3 * seconds_since(frame_start));
    if (t - title_t >= 0.25) {
      window->set_title(status_line(frame_ms.back(), last, package.bytes_received(), fly.speed()));
      title_t = t;
    }
  }
  if (!opt.screenshot.empty()) {
    save_png(renderer.read_pixels(), opt.screenshot);  // atomic: temporary file, then rename
  }
  nlohmann::json j;
  j["duration_s"] = seconds_since(start_time);
  j["bytes"] = package.bytes_received();
  j["benefit_ratio"] = last.quality.benefit_ratio;
  j["pixel_error_max"] = last.quality.pixel_error_max;
  j["nodes"] = last.cut.drawn.size();
  j["triangles"] = last.cut.triangles;
  j["plans"] = client.plans();
  j["renderer"] = window->renderer();
  report(opt, client.mode(), j, frame_ms);
  return 0;
}

int run_view(const ViewOptions& opt) {
  if (!(opt.pixel_error > 0.0) || !std::isfinite(opt.pixel_error))
    throw Error("--pixel-error must be a positive number of pixels");
  if (!(opt.settle_s >= 0.0) || !std::isfinite(opt.settle_s)) throw Error("--settle must be >= 0 seconds");
  if (!(opt.cache_mb > 0.0) || !std::isfinite(opt.cache_mb))
    throw Error("--cache must be a positive MB count");
  if (opt.order != "benefit" && opt.order != "sse" && opt.order != "full")
    throw Error("--order must be 'benefit', 'sse' or 'full'");
  if (opt.window < 0 || opt.window > 64) throw Error("--window must be in 0..64");
  if (opt.source.rfind("ws://", 0) == 0 && (opt.order != "benefit" || opt.window))
    throw Error("--order and --window are for pulling (http:// or a file), not ws://");
  if (opt.frames_every < 0) throw Error("--frames-every must be >= 0 (0: no images)");
  if (opt.cuts_every < 0) throw Error("--cuts-every must be >= 0 (0: none)");
  return opt.headless ? run_headless(opt) : run_window(opt);
}

const bool registered = register_command(
    {"view",
     "the streaming client: fly through a local, pulled or pushed package in a window, or follow a "
     "camera path headless",
     [](CLI::App& sub) {
       auto opt = std::make_shared<ViewOptions>();
       sub.add_option("source", opt->source,
                      "FILE.lods, http://HOST:PORT/…/NAME.lods (pull) or ws://HOST:PORT/NAME (push)")
           ->required();
       sub.add_flag("--headless", opt->headless, "no window: follow --path and write --out/frames.csv");
       sub.add_option("--path", opt->path,
                      "camera path JSON (DESIGN.md); in a window, only its first key frame (the start pose)")
           ->check(CLI::ExistingFile);
       sub.add_option("--out", opt->out, "directory for frames.csv (headless)");
       sub.add_option("--pixel-error", opt->pixel_error, "target pixel error tau")->capture_default_str();
       sub.add_option("--settle", opt->settle_s, "seconds to keep the last pose until converged (headless)")
           ->capture_default_str();
       sub.add_option("--cache", opt->cache_mb, "page cache budget, MB")->capture_default_str();
       sub.add_option(
           "--cache-dir", opt->cache_dir,
           "keep received pages in DIR/<package hash>/, start from them and read evicted pages back "
           "from there when pulling (no page sent twice)");
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
                      "headless: write DIR/frame_NNNNN.png every N frames and the final frame (0: none)");
       sub.add_flag("--json", opt->json, "print a JSON summary");
       sub.add_option("--frames", opt->frames, "window: exit after N frames (0: when the window closes)");
       sub.add_option("--screenshot", opt->screenshot, "window: write the last frame to this PNG on exit");
       sub.add_option("--up", opt->up, "window: the world's up axis X,Y,Z (navigation, start pose)")
           ->capture_default_str();
       sub.add_option("--size", opt->size, "window: size WxH (a --path gives its own)")
           ->capture_default_str();
       sub.footer(
           "Window controls: drag with the left mouse button to look around; W/S (or Up/Down) fly forward "
           "and\n"
           "back, A/D (or Left/Right) sideways, E/Q up and down along --up; hold Shift to fly 4x faster; "
           "the\n"
           "mouse wheel changes the speed (x1.25 a step; it starts at 0.3 scene radii per second); Esc "
           "quits.\n"
           "The window's title shows the frame time, triangles drawn, bytes received, the pixel error and "
           "the\n"
           "benefit ratio. The window starts at --path's first key frame, else 3 scene radii out, looking "
           "at\n"
           "the scene's centre; scheduling follows the camera and its motion measured from frame to frame.\n"
           "Headless CSV columns: t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,\n"
           "frame_ms (one row per frame at 30 frames/s; the last row is the final frame).\n"
           "Examples:\n"
           "  lodstream view out/motorBike.lods --up 0,0,1\n"
           "  lodstream view http://127.0.0.1:8080/motorBike.lods --up 0,0,1\n"
           "  lodstream view ws://127.0.0.1:8080/motorBike --headless --path path.json --out out/view");
       return [opt] { return run_view(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
