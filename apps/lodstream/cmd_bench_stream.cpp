// `lodstream bench stream`: every streaming policy side by side on one package, camera path and link (issue
// 6, DESIGN.md Measuring quality), in the simulator of stream_sim.hpp. A model is baked first (into --out).
// For sampled frames the drawn cut and the full-resolution scene (the package's finest cut: the source at the
// package's precision) are rendered from the same camera (headless EGL) for PSNR and SSIM. Writes, into
// --out: POLICY.csv per policy (DESIGN.md's columns, then psnr and ssim, empty where not sampled),
// summary.json (DESIGN.md's keys), summary.md (the table), benefit.png, psnr.png and bytes.png (gnuplot), and
// the sampled frames at 1, 2 and 5 s and the last one under frames/.
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "bench.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "measure/image_metrics.hpp"
#include "package/reader.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "render/scene_upload.hpp"
#include "runtime/cut_geometry.hpp"
#include "scene_bounds.hpp"
#include "schedule/path_gen.hpp"
#include "stream_sim.hpp"

extern char** environ;

namespace lodstream::cli {
namespace {

namespace fs = std::filesystem;

struct StreamArgs {
  std::string input, path, link = "bandwidth=10mbit,rtt=80ms",
                           policies = "full,sse-pull,sse-pull-3,push,oracle", out;
  std::string up = "0,1,0", size = "1280x720";
  double tau = 1.0, settle_s = 10.0, sample_every_s = 1.0;
  bool real = false, json = false;
};

// "bandwidth=10mbit,rtt=80ms[,jitter=5ms]".
LinkSettings parse_link(const std::string& text) {
  LinkSettings link;
  bool bandwidth = false, rtt = false;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "bandwidth")
      link.bandwidth_bps = parse_bandwidth(value, "--link bandwidth"), bandwidth = true;
    else if (key == "rtt")
      link.rtt_s = parse_duration(value, "--link rtt"), rtt = true;
    else if (key == "jitter")
      link.jitter_s = parse_duration(value, "--link jitter");
    else
      throw Error("--link: unknown key '" + key + "' in '" + text + "' (give bandwidth=…,rtt=…[,jitter=…])");
  }
  if (!bandwidth || !rtt) throw Error("--link: give bandwidth=… and rtt=… (e.g. bandwidth=10mbit,rtt=80ms)");
  if (!(link.bandwidth_bps > 0.0)) throw Error("--link: bandwidth must be positive");
  return link;
}

// Runs this program's `bake MODEL -o PACKAGE` (a child process: bake owns its own memory and threads).
void bake(const std::string& model, const fs::path& package) {
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args{self, "bake", model, "-o", package.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, self.c_str(), nullptr, nullptr, argv.data(), environ) != 0)
    throw Error("bench stream: cannot run " + self + " bake");
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error("bench stream: baking " + model + " failed (see above)");
}

fs::path package_of(const StreamArgs& args) {
  if (!fs::exists(args.input)) throw Error(args.input + ": no such file");
  if (fs::path(args.input).extension() == ".lods") return args.input;
  const fs::path package = fs::path(args.out) / (fs::path(args.input).stem().string() + ".lods");
  if (fs::exists(package) && fs::last_write_time(package) >= fs::last_write_time(args.input)) {
    std::fprintf(stderr, "bench stream: using %s (newer than %s)\n", package.c_str(), args.input.c_str());
  } else {
    std::fprintf(stderr, "bench stream: baking %s into %s\n", args.input.c_str(), package.c_str());
    bake(args.input, package);
  }
  return package;
}

schedule::CameraPath camera_path(const StreamArgs& args, const package::PackageScene& scene) {
  if (args.path.rfind("gen:", 0) != 0) return schedule::load_camera_path(args.path);
  schedule::PathGenOptions options;
  options.up = parse_vec3(args.up, "--up");
  std::tie(options.width, options.height) = parse_size(args.size, "--size");
  return schedule::generate_path(args.path.substr(4), world_bounds(scene), options);
}

// DESIGN.md's camera path JSON of `path` (what load_camera_path reads back): the run's path, recorded.
nlohmann::json path_json(const schedule::CameraPath& path) {
  auto vec = [](glm::vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json keyframes = nlohmann::json::array();
  for (const schedule::Keyframe& k : path.keyframes())
    keyframes.push_back({{"t", k.t}, {"eye", vec(k.eye)}, {"target", vec(k.target)}, {"up", vec(k.up)}});
  return {{"fov", path.fov_y_degrees()}, {"size", {path.width(), path.height()}}, {"keyframes", keyframes}};
}

// Image metrics of the sampled frames: PSNR and SSIM of each policy's frame against the full-resolution
// frame from the same camera.
class FrameRenderer {
 public:
  FrameRenderer(package::PackageReader& reader, const PackageFacts& facts, const fs::path& package_dir)
      : context_(render::create_headless_context()),
        renderer_(*context_),
        reader_(&reader),
        facts_(&facts),
        geometry_(reader, package_dir, UINT64_MAX) {}

  Image draw(const Camera& camera, const std::vector<schedule::DrawnNode>& drawn) {
    schedule::Cut cut;
    cut.drawn = drawn;
    geometry_.update(cut, runtime::pages_from_reader(*reader_));
    const render::SceneUpload upload = render::upload_scene(renderer_, geometry_.scene());
    for (const std::string& w : upload.warnings)
      if (warned_.insert(w).second) std::fprintf(stderr, "lodstream: warning: %s\n", w.c_str());
    renderer_.draw(camera, upload.items);
    Image image = renderer_.read_pixels();
    render::release_scene(renderer_, upload);
    return image;
  }
  // The full-resolution frame for sampled frame `frame` (same camera for every policy), drawn once.
  const Image& reference(size_t frame, const Camera& camera) {
    auto it = references_.find(frame);
    if (it == references_.end())
      it = references_.emplace(frame, draw(camera, finest_cut(*facts_, schedule::View::of(camera)).drawn))
               .first;
    return it->second;
  }

 private:
  std::unique_ptr<render::Context> context_;
  render::Renderer renderer_;
  package::PackageReader* reader_;
  const PackageFacts* facts_;
  runtime::CutGeometry geometry_;
  std::map<size_t, Image> references_;
  std::set<std::string> warned_;
};

// Per-frame image metrics of one policy (NaN where the frame was not sampled).
struct ImageMetrics {
  std::vector<double> psnr, ssim;
};

// What summary.json reports per policy (DESIGN.md's keys; null where a figure does not exist).
struct PolicySummary {
  std::optional<double> first_frame_s, to_095_s, psnr_1s, psnr_2s, psnr_5s;
  std::vector<std::optional<double>> to_095_after_teleport_s;
  double benefit_auc = 0.0, frame_ms_p50 = 0.0, frame_ms_p99 = 0.0;
  uint64_t bytes = 0;
  std::optional<double> converged_s;
};

// Nearest-rank percentile p (0..100) of `values` (not empty).
double percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  const size_t rank = size_t(std::ceil(p / 100.0 * double(values.size())));
  return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

// First frame at or after `from` whose benefit ratio reaches 0.95, as seconds since `from`.
std::optional<double> time_to_095(const std::vector<FrameRow>& frames, double from) {
  for (const FrameRow& f : frames)
    if (f.t >= from - 1e-9 && f.benefit_ratio >= 0.95) return f.t - from;
  return std::nullopt;
}

// PSNR of the last sampled frame at or before `t` (the run stops once converged after the path: later frames
// repeat the last one); null when no frame at or before t was sampled.
std::optional<double> psnr_at(const std::vector<FrameRow>& frames, const ImageMetrics& m, double t) {
  std::optional<double> out;
  for (size_t k = 0; k < frames.size() && frames[k].t <= t + 1e-9; ++k)
    if (!std::isnan(m.psnr[k])) out = m.psnr[k];
  return out;
}

PolicySummary summarize(const SimResult& r, const ImageMetrics& m, double window_s,
                        const std::vector<double>& jumps) {
  PolicySummary s;
  const auto& f = r.frames;
  for (const FrameRow& row : f)
    if (row.nodes > 0 && !s.first_frame_s) s.first_frame_s = row.t;
  s.to_095_s = time_to_095(f, 0.0);
  for (double jump : jumps) s.to_095_after_teleport_s.push_back(time_to_095(f, jump));
  // Area under the benefit curve over [0, window], each frame's value held until the next one (the last
  // frame's until the window's end), divided by the window: the mean benefit ratio.
  for (size_t k = 0; k < f.size(); ++k) {
    const double t1 = std::min(window_s, k + 1 < f.size() ? f[k + 1].t : window_s);
    s.benefit_auc += f[k].benefit_ratio * std::max(0.0, t1 - f[k].t);
  }
  s.benefit_auc /= window_s;
  s.bytes = f.back().bytes;
  if (f.back().converged) s.converged_s = f.back().t;
  std::vector<double> ms;
  for (const FrameRow& row : f) ms.push_back(row.frame_ms);
  s.frame_ms_p50 = percentile(ms, 50.0);
  s.frame_ms_p99 = percentile(ms, 99.0);
  s.psnr_1s = psnr_at(f, m, 1.0);
  s.psnr_2s = psnr_at(f, m, 2.0);
  s.psnr_5s = psnr_at(f, m, 5.0);
  return s;
}

nlohmann::json maybe(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json();
}

std::string fixed(const std::optional<double>& v, const char* format) {
  if (!v) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, *v);
  return buf;
}

std::string csv(const SimResult& r, const ImageMetrics& m) {
  std::string out =
      "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms,psnr,ssim\n";
  char buf[256];
  for (size_t k = 0; k < r.frames.size(); ++k) {
    const FrameRow& f = r.frames[k];
    std::snprintf(buf, sizeof buf, "%.4f,%llu,%u,%llu,%.6g,%.6g,%.6f,%.3f,", f.t, (unsigned long long)f.bytes,
                  f.nodes, (unsigned long long)f.triangles, f.pixel_error_max, f.pixel_error_mean,
                  f.benefit_ratio, f.frame_ms);
    out += buf;
    if (!std::isnan(m.psnr[k])) {
      std::snprintf(buf, sizeof buf, "%.4f,%.6f", m.psnr[k], m.ssim[k]);
      out += buf;
    } else {
      out += ",";
    }
    out += "\n";
  }
  return out;
}

void write_text(const fs::path& file, const std::string& text) {
  write_file_atomically(file, text.data(), text.size());
}

std::string summary_table(const std::vector<Policy>& policies, const std::vector<PolicySummary>& s) {
  std::string out =
      "| policy | first frame (s) | benefit 0.95 (s) | benefit AUC | MB received | PSNR 1 s | PSNR 2 s | "
      "PSNR 5 s | frame ms p50 / p99 |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (size_t i = 0; i < policies.size(); ++i) {
    const PolicySummary& p = s[i];
    out += "| " + std::string(policy_name(policies[i])) + " | " + fixed(p.first_frame_s, "%.2f") + " | " +
           fixed(p.to_095_s, "%.2f") + " | " + fixed(p.benefit_auc, "%.3f") + " | " +
           fixed(double(p.bytes) / 1e6, "%.2f") + " | " + fixed(p.psnr_1s, "%.1f") + " | " +
           fixed(p.psnr_2s, "%.1f") + " | " + fixed(p.psnr_5s, "%.1f") + " | " +
           fixed(p.frame_ms_p50, "%.1f") + " / " + fixed(p.frame_ms_p99, "%.1f") + " |\n";
  }
  return out;
}

// benefit.png, psnr.png and bytes.png through gnuplot (skipped with a warning when it is not installed).
void plot(const fs::path& out, const std::vector<Policy>& policies, double window_s) {
  std::string script =
      "set terminal pngcairo size 1000,560 font ',11'\nset datafile separator ','\n"
      "set key bottom right\nset grid\nset xlabel 'time (s)'\nset xrange [0:" +
      std::to_string(window_s) + "]\n";
  auto plot_one = [&](const std::string& name, const std::string& ylabel, const std::string& column,
                      const std::string& style) {
    script +=
        "set output '" + (out / ("." + name + ".png.tmp")).string() + "'\nset ylabel '" + ylabel + "'\n";
    std::string cmd = "plot ";
    for (size_t i = 0; i < policies.size(); ++i) {
      if (i) cmd += ", ";
      const std::string file = (out / (std::string(policy_name(policies[i])) + ".csv")).string();
      cmd += "'" + file + "' every ::1 using 1:(" + column + ") with " + style + " title '" +
             policy_name(policies[i]) + "'";
    }
    script += cmd + "\n";
  };
  plot_one("benefit", "benefit ratio", "$7", "steps lw 2");
  plot_one("psnr", "PSNR (dB) against the full-resolution frame", "valid(9) ? $9 : NaN", "linespoints lw 2");
  plot_one("bytes", "MB received", "$2/1e6", "steps lw 2");
  const fs::path gp = out / ".plots.gp";
  write_text(gp, script);
  const std::string cmd = "gnuplot '" + gp.string() + "' 1>&2";  // stdout is --json's
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(
        stderr, "lodstream: warning: gnuplot failed or is missing (apt-get install gnuplot-nox): no plots\n");
    fs::remove(gp);
    return;
  }
  fs::remove(gp);
  for (const char* name : {"benefit", "psnr", "bytes"})
    fs::rename(out / ("." + std::string(name) + ".png.tmp"), out / (std::string(name) + ".png"));
}

int run_bench_stream(const StreamArgs& args) {
  if (args.real) throw Error("--real is not implemented yet: run the simulated mode (without --real)");
  const LinkSettings link = parse_link(args.link);
  const std::vector<Policy> policies = parse_policies(args.policies);
  if (!(args.tau > 0.0)) throw Error("--pixel-error must be positive");
  if (!(args.settle_s >= 0.0)) throw Error("--settle must be at least 0");
  if (!(args.sample_every_s >= 0.0)) throw Error("--psnr-every must be at least 0");
  if (args.path.empty()) throw Error("--path: give a camera path file or gen:orbit|fly|drive|teleport");
  if (args.path.rfind("gen:", 0) != 0 && !fs::exists(args.path)) throw Error(args.path + ": no such file");
  fs::create_directories(args.out);
  const fs::path out(args.out);

  const fs::path file = package_of(args);
  package::PackageReader reader = package::PackageReader::open(file);
  const PackageFacts facts = PackageFacts::of(reader);
  const schedule::CameraPath path = camera_path(args, facts.scene);
  const std::vector<double> jumps = schedule::teleports(path);
  SimOptions options;
  options.link = link;
  options.tau = args.tau;
  options.settle_s = args.settle_s;
  options.sample_every_s = args.sample_every_s;
  const double window_s = path.end() - path.start() + options.settle_s;

  std::vector<SimResult> results;
  for (Policy p : policies) {
    std::fprintf(stderr, "\rbench stream: simulating %-10s", policy_name(p));
    results.push_back(simulate(facts, path, p, options));
  }
  std::fprintf(stderr, "\n");

  // Image metrics at the sampled frames.
  std::vector<ImageMetrics> metrics(results.size());
  size_t total = 0, done = 0;
  for (const SimResult& r : results) total += r.samples.size();
  std::unique_ptr<FrameRenderer> renderer;
  if (total > 0) {
    renderer = std::make_unique<FrameRenderer>(reader, facts, file.parent_path());
    fs::create_directories(out / "frames");
  }
  for (size_t i = 0; i < results.size(); ++i) {
    const SimResult& r = results[i];
    metrics[i].psnr.assign(r.frames.size(), NAN);
    metrics[i].ssim.assign(r.frames.size(), NAN);
    for (const FrameSample& s : r.samples) {
      std::fprintf(stderr, "\rbench stream: image metrics %zu/%zu", ++done, total);
      const Image& reference = renderer->reference(s.frame, s.camera);
      const Image image = renderer->draw(s.camera, s.drawn);
      const double p = psnr(image, reference);
      metrics[i].psnr[s.frame] = std::isinf(p) ? 99.0 : p;  // identical images: capped for the CSV
      metrics[i].ssim[s.frame] = ssim(image, reference);
      const bool saved = s.frame + 1 == r.frames.size() || s.frame == size_t(std::lround(options.fps)) ||
                         s.frame == size_t(std::lround(2 * options.fps)) ||
                         s.frame == size_t(std::lround(5 * options.fps));
      if (saved) {
        char name[64];
        std::snprintf(name, sizeof name, "_%06.2fs.png", r.frames[s.frame].t);
        save_png(image, out / "frames" / (policy_name(r.policy) + std::string(name)));
        save_png(reference, out / "frames" / ("reference" + std::string(name)));
      }
    }
  }
  if (total > 0) std::fprintf(stderr, "\n");

  std::vector<PolicySummary> summaries;
  nlohmann::json json_policies = nlohmann::json::object();
  for (size_t i = 0; i < results.size(); ++i) {
    write_text(out / (std::string(policy_name(results[i].policy)) + ".csv"), csv(results[i], metrics[i]));
    const PolicySummary s = summarize(results[i], metrics[i], window_s, jumps);
    nlohmann::json after = nlohmann::json::array();
    for (const auto& v : s.to_095_after_teleport_s) after.push_back(maybe(v));
    json_policies[policy_name(results[i].policy)] = {{"time_to_first_frame_s", maybe(s.first_frame_s)},
                                                     {"time_to_095_s", maybe(s.to_095_s)},
                                                     {"benefit_auc", s.benefit_auc},
                                                     {"bytes", s.bytes},
                                                     {"psnr_at_1s", maybe(s.psnr_1s)},
                                                     {"psnr_at_2s", maybe(s.psnr_2s)},
                                                     {"psnr_at_5s", maybe(s.psnr_5s)},
                                                     {"frame_ms_p50", s.frame_ms_p50},
                                                     {"frame_ms_p99", s.frame_ms_p99},
                                                     {"time_to_095_after_teleport_s", after},
                                                     {"converged_s", maybe(s.converged_s)},
                                                     {"frames", results[i].frames.size()}};
    summaries.push_back(s);
  }
  const nlohmann::json summary = {
      {"policies", json_policies},
      {"package", file.string()},
      {"path", args.path},
      {"path_duration_s", path.end() - path.start()},
      {"window_s", window_s},
      {"teleports_s", jumps},
      {"link", {{"bandwidth_bps", link.bandwidth_bps}, {"rtt_s", link.rtt_s}, {"jitter_s", link.jitter_s}}},
      {"pixel_error", args.tau},
      {"mode", "simulated"}};
  write_text(out / "summary.json", summary.dump(2) + "\n");
  write_text(out / "path.json", path_json(path).dump() + "\n");
  char head[512];
  std::snprintf(head, sizeof head,
                "# bench stream: %s, path %s (%.1f s + %.1f s settle), link %.3g Mbit/s, RTT %.0f ms%s\n\n",
                file.filename().c_str(), args.path.c_str(), path.end() - path.start(), options.settle_s,
                link.bandwidth_bps / 1e6, link.rtt_s * 1e3,
                link.jitter_s > 0 ? (", jitter " + std::to_string(link.jitter_s * 1e3) + " ms").c_str() : "");
  const std::string md =
      std::string(head) + summary_table(policies, summaries) +
      "\nBenefit AUC: mean benefit ratio over the window (path + settle). PSNR against the "
      "package's finest cut from the same camera (99.0: identical; '-': nothing sampled yet); a "
      "policy's PSNR at t is its last sampled frame at or before t. Simulated mode; frame times from the "
      "cost "
      "model.\n";
  write_text(out / "summary.md", md);
  plot(out, policies, window_s);
  if (args.json)
    print_json(summary);
  else
    std::printf(
        "%s\nwritten to %s: summary.md, summary.json, POLICY.csv, benefit.png, psnr.png, bytes.png, "
        "path.json, frames/\n",
        md.c_str(), out.c_str());
  return 0;
}

const bool registered = register_bench(
    {"stream", "streaming policies side by side on a simulated link: CSV, summary, plots", [](CLI::App& sub) {
       auto args = std::make_shared<StreamArgs>();
       sub.add_option("SCENE", args->input, "a package (.lods), or a model to bake into --out first")
           ->required();
       sub.add_option("--path", args->path, "camera path JSON (DESIGN.md), or gen:orbit|fly|drive|teleport")
           ->required();
       sub.add_option("--link", args->link, "bandwidth=…,rtt=…[,jitter=…] of the simulated link")
           ->capture_default_str();
       sub.add_option("--policy", args->policies, "comma-separated: full, sse-pull, sse-pull-3, push, oracle")
           ->capture_default_str();
       sub.add_option("--out", args->out, "output folder")->required();
       sub.add_option("--pixel-error", args->tau, "target screen-space error tau in pixels")
           ->capture_default_str();
       sub.add_option("--settle", args->settle_s, "seconds the last pose is held after the path")
           ->capture_default_str();
       sub.add_option(
              "--psnr-every", args->sample_every_s,
              "seconds between frames rendered for PSNR/SSIM (also at 1, 2, 5 s and the last; 0: none)")
           ->capture_default_str();
       sub.add_option("--up", args->up, "up axis X,Y,Z of a generated path")->capture_default_str();
       sub.add_option("--size", args->size, "image size WxH of a generated path")->capture_default_str();
       sub.add_flag("--real", args->real,
                    "through lodstream serve and link on loopback (not implemented yet)");
       sub.add_flag("--json", args->json, "print summary.json's object");
       sub.footer(
           "Example:\n  lodstream bench stream out/motorBike.lods --path gen:fly --up 0,0,1 --link "
           "bandwidth=10mbit,rtt=80ms --out out/stream");
       return [args] { return run_bench_stream(*args); };
     }});

}  // namespace
}  // namespace lodstream::cli
