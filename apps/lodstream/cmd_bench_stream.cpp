// `lodstream bench stream`: every streaming policy side by side on one package, camera path and link (issue
// 6, DESIGN.md Measuring quality), in the simulator of stream_sim.hpp. A model is baked first (into --out).
// For sampled frames the drawn cut and the full-resolution scene (the package's finest cut: the source at the
// package's precision) are rendered from the same camera (headless EGL) for PSNR and SSIM. Writes, into
// --out: POLICY.csv per policy (DESIGN.md's columns, then psnr and ssim, empty where not sampled),
// summary.json (DESIGN.md's keys), summary.md (the table), benefit.png, psnr.png and bytes.png (gnuplot), and
// the sampled frames at 1, 2 and 5 s and the last one under frames/.
// --real (real_stream.hpp): every policy but oracle also runs through lodstream serve, link and a headless
// view on loopback; POLICY.csv, the table and the plots are then the real runs', image metrics at the frames
// the views wrote, and summary.json/.md set each real figure beside the simulated one (simulated/: the
// simulated CSVs; oracle is reported from the simulation only).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "bench.hpp"
#include "child_process.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "cut_drawer.hpp"
#include "measure/image_metrics.hpp"
#include "package/reader.hpp"
#include "real_stream.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "runtime/cut_geometry.hpp"
#include "scene_bounds.hpp"
#include "schedule/path_gen.hpp"
#include "stream_sim.hpp"

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

// Runs this program's `bake MODEL -o PACKAGE` (a child process: bake owns its own memory and threads; its
// report goes to standard error, standard output being --json's).
void bake(const std::string& model, const fs::path& package) {
  ChildProcess child({"bake", model, "-o", package.string()}, "-", "");
  if (child.wait() != 0) throw Error("bench stream: baking " + model + " failed (see above)");
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
        geometry_(reader, package_dir, UINT64_MAX),
        drawer_(renderer_, geometry_.materials(), 0) {}

  Image draw(const Camera& camera, const std::vector<schedule::DrawnNode>& drawn) {
    schedule::Cut cut;
    cut.drawn = drawn;
    geometry_.update(cut, runtime::pages_from_reader(*reader_));
    const std::vector<render::DrawItem>& items = drawer_.items(geometry_);
    for (const std::string& w : drawer_.warnings())
      if (warned_.insert(w).second) std::fprintf(stderr, "lodstream: warning: %s\n", w.c_str());
    renderer_.draw(camera, items);
    return renderer_.read_pixels();
  }
  // The full-resolution frame at path time `t` (`camera`: the path's pose then), drawn once per t (the
  // simulated policies share their frame times; real runs' frames each have their own).
  const Image& reference(double t, const Camera& camera) {
    auto it = references_.find(t);
    if (it == references_.end())
      it = references_.emplace(t, draw(camera, finest_cut(*facts_, schedule::View::of(camera)).drawn)).first;
    return it->second;
  }

 private:
  std::unique_ptr<render::Context> context_;
  render::Renderer renderer_;
  package::PackageReader* reader_;
  const PackageFacts* facts_;
  runtime::CutGeometry geometry_;
  CutDrawer drawer_;  // meshes a frame does not draw released after it
  std::map<double, Image> references_;
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

// PSNR at `t`. Simulated: the last sampled frame at or before t (frames are sampled at 1, 2 and 5 s
// exactly; the run stops once converged after the path: later frames repeat the last one); null when no
// frame by t was sampled. Real (`real`): a view's frame for the slot at t comes at or after t on the wall
// clock, so the first sampled frame at or after t, else the last one.
std::optional<double> psnr_at(const std::vector<FrameRow>& frames, const ImageMetrics& m, double t,
                              bool real) {
  std::optional<double> out;
  for (size_t k = 0; k < frames.size(); ++k) {
    if (std::isnan(m.psnr[k])) continue;
    if (real && frames[k].t >= t - 1e-9) return m.psnr[k];
    if (!real && frames[k].t > t + 1e-9) break;
    out = m.psnr[k];
  }
  return out;
}

PolicySummary summarize(const std::vector<FrameRow>& f, const ImageMetrics& m, double window_s,
                        const std::vector<double>& jumps, bool real) {
  PolicySummary s;
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
  s.psnr_1s = psnr_at(f, m, 1.0, real);
  s.psnr_2s = psnr_at(f, m, 2.0, real);
  s.psnr_5s = psnr_at(f, m, 5.0, real);
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

std::string csv(const std::vector<FrameRow>& frames, const ImageMetrics& m) {
  std::string out =
      "t,bytes,nodes,triangles,pixel_error_max,pixel_error_mean,benefit_ratio,frame_ms,psnr,ssim\n";
  char buf[256];
  for (size_t k = 0; k < frames.size(); ++k) {
    const FrameRow& f = frames[k];
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

// One policy's run in this benchmark: its frames (simulated or real), their image metrics and its summary.
struct Run {
  std::string name;  // the policy's name
  std::vector<FrameRow> frames;
  ImageMetrics metrics;
  PolicySummary summary;
  std::optional<double> server_cpu_s, client_cpu_s;  // --real: CPU seconds of the server and the view
};

std::string table_row(const std::string& name, const PolicySummary& p) {
  return "| " + name + " | " + fixed(p.first_frame_s, "%.2f") + " | " + fixed(p.to_095_s, "%.2f") + " | " +
         fixed(p.benefit_auc, "%.3f") + " | " + fixed(double(p.bytes) / 1e6, "%.2f") + " | " +
         fixed(p.psnr_1s, "%.1f") + " | " + fixed(p.psnr_2s, "%.1f") + " | " + fixed(p.psnr_5s, "%.1f") +
         " | " + fixed(p.frame_ms_p50, "%.1f") + " / " + fixed(p.frame_ms_p99, "%.1f") + " |\n";
}

std::string summary_table(const std::vector<Run>& runs) {
  std::string out =
      "| policy | first frame (s) | benefit 0.95 (s) | benefit AUC | MB received | PSNR 1 s | PSNR 2 s | "
      "PSNR 5 s | frame ms p50 / p99 |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Run& r : runs) out += table_row(r.name, r.summary);
  return out;
}

// How far the two modes agree: each real run's figures beside the simulated run of the same policy.
std::string agreement_table(const std::vector<Run>& real, const std::vector<Run>& simulated) {
  std::string out =
      "| policy | first frame real / sim (s) | benefit 0.95 real / sim (s) | real - sim (s) | AUC real / sim "
      "| "
      "MB real / sim |\n|---|---:|---:|---:|---:|---:|\n";
  for (const Run& r : real)
    for (const Run& sim : simulated) {
      if (sim.name != r.name) continue;
      const PolicySummary &a = r.summary, &b = sim.summary;
      const std::optional<double> difference =
          a.to_095_s && b.to_095_s ? std::optional<double>(*a.to_095_s - *b.to_095_s) : std::nullopt;
      out += "| " + r.name + " | " + fixed(a.first_frame_s, "%.2f") + " / " + fixed(b.first_frame_s, "%.2f") +
             " | " + fixed(a.to_095_s, "%.2f") + " / " + fixed(b.to_095_s, "%.2f") + " | " +
             fixed(difference, "%+.2f") + " | " + fixed(a.benefit_auc, "%.3f") + " / " +
             fixed(b.benefit_auc, "%.3f") + " | " + fixed(double(a.bytes) / 1e6, "%.2f") + " / " +
             fixed(double(b.bytes) / 1e6, "%.2f") + " |\n";
    }
  return out;
}

// benefit.png, psnr.png (when a frame was measured) and bytes.png through gnuplot (skipped with a warning
// when it is not installed), one line per run, from out/NAME.csv.
void plot(const fs::path& out, const std::vector<Run>& runs, double window_s) {
  std::string script =
      "set terminal pngcairo size 1000,560 font ',11'\nset datafile separator ','\n"
      "set key bottom right\nset grid\nset xlabel 'time (s)'\nset xrange [0:" +
      std::to_string(window_s) + "]\n";
  auto plot_one = [&](const std::string& name, const std::string& ylabel, const std::string& column,
                      const std::string& style) {
    script +=
        "set output '" + (out / ("." + name + ".png.tmp")).string() + "'\nset ylabel '" + ylabel + "'\n";
    std::string cmd = "plot ";
    for (size_t i = 0; i < runs.size(); ++i) {
      if (i) cmd += ", ";
      const std::string file = (out / (runs[i].name + ".csv")).string();
      cmd +=
          "'" + file + "' every ::1 using 1:(" + column + ") with " + style + " title '" + runs[i].name + "'";
    }
    script += cmd + "\n";
  };
  plot_one("benefit", "benefit ratio", "$7", "steps lw 2");
  bool measured = false;  // gnuplot fails on a plot without a single point
  for (const Run& r : runs)
    for (double p : r.metrics.psnr) measured = measured || !std::isnan(p);
  std::vector<std::string> plots{"benefit", "bytes"};
  if (measured) {
    plot_one("psnr", "PSNR (dB) against the full-resolution frame", "valid(9) ? $9 : NaN",
             "linespoints lw 2");
    plots.push_back("psnr");
  }
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
  for (const std::string& name : plots) fs::rename(out / ("." + name + ".png.tmp"), out / (name + ".png"));
}

// Records frame k's PSNR and SSIM against the full-resolution `reference` (PSNR of identical images capped
// at 99 for the CSV).
void measure_frame(ImageMetrics& m, size_t k, const Image& image, const Image& reference) {
  const double p = psnr(image, reference);
  m.psnr[k] = std::isinf(p) ? 99.0 : p;
  m.ssim[k] = ssim(image, reference);
}

nlohmann::json policy_json(const Run& r) {
  const PolicySummary& s = r.summary;
  nlohmann::json after = nlohmann::json::array();
  for (const auto& v : s.to_095_after_teleport_s) after.push_back(maybe(v));
  return {{"time_to_first_frame_s", maybe(s.first_frame_s)},
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
          {"frames", r.frames.size()},
          {"server_cpu_s", maybe(r.server_cpu_s)},
          {"client_cpu_s", maybe(r.client_cpu_s)}};
}

int run_bench_stream(const StreamArgs& args) {
  const LinkSettings link = parse_link(args.link);
  const std::vector<Policy> policies = parse_policies(args.policies);
  if (!(args.tau > 0.0)) throw Error("--pixel-error must be positive");
  if (!(args.settle_s >= 0.0)) throw Error("--settle must be at least 0");
  if (!(args.sample_every_s >= 0.0)) throw Error("--psnr-every must be at least 0");
  if (args.path.empty()) throw Error("--path: give a camera path file or gen:orbit|fly|drive|teleport");
  if (args.path.rfind("gen:", 0) != 0 && !fs::exists(args.path)) throw Error(args.path + ": no such file");
  if (args.real && policies.size() == 1 && policies[0] == Policy::oracle)
    throw Error("--real: oracle has no real counterpart (it needs the future path); add another policy");
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
  // --real simulates too, for the agreement figures, without image metrics (the real runs have theirs).
  options.sample_every_s = args.real ? 0.0 : args.sample_every_s;
  const double window_s = path.end() - path.start() + options.settle_s;
  write_text(out / "path.json",
             path_json(path).dump() + "\n");  // the run's path (the real clients follow it)

  std::vector<SimResult> results;
  for (Policy p : policies) {
    std::fprintf(stderr, "\rbench stream: simulating %-10s", policy_name(p));
    results.push_back(simulate(facts, path, p, options));
  }
  std::fprintf(stderr, "\n");
  std::vector<Run> simulated;
  for (const SimResult& r : results) {
    Run run{policy_name(r.policy), r.frames, {}, {}, {}, {}};
    run.metrics.psnr.assign(r.frames.size(), NAN);
    run.metrics.ssim.assign(r.frames.size(), NAN);
    simulated.push_back(std::move(run));
  }

  std::unique_ptr<FrameRenderer> renderer;
  auto frame_renderer = [&]() -> FrameRenderer& {
    if (!renderer) renderer = std::make_unique<FrameRenderer>(reader, facts, file.parent_path());
    return *renderer;
  };
  // Simulated mode: image metrics at the sampled frames; frames at 1, 2 and 5 s and the last one saved.
  size_t total = 0, done = 0;
  for (const SimResult& r : results) total += r.samples.size();
  if (total > 0) fs::create_directories(out / "frames");
  for (size_t i = 0; i < results.size(); ++i) {
    const SimResult& r = results[i];
    for (const FrameSample& s : r.samples) {
      std::fprintf(stderr, "\rbench stream: image metrics %zu/%zu", ++done, total);
      const double t = r.frames[s.frame].t;
      const Image& reference = frame_renderer().reference(t, s.camera);
      const Image image = frame_renderer().draw(s.camera, s.drawn);
      measure_frame(simulated[i].metrics, s.frame, image, reference);
      const bool saved = s.frame + 1 == r.frames.size() || s.frame == size_t(std::lround(options.fps)) ||
                         s.frame == size_t(std::lround(2 * options.fps)) ||
                         s.frame == size_t(std::lround(5 * options.fps));
      if (saved) {
        char name[64];
        std::snprintf(name, sizeof name, "_%06.2fs.png", t);
        save_png(image, out / "frames" / (policy_name(r.policy) + std::string(name)));
        save_png(reference, out / "frames" / ("reference" + std::string(name)));
      }
    }
  }
  if (total > 0) std::fprintf(stderr, "\n");
  for (Run& r : simulated) r.summary = summarize(r.frames, r.metrics, window_s, jumps, false);

  // --real: each policy but oracle through serve, link and view; image metrics at the frames each view drew.
  std::vector<Run> real;
  if (args.real) {
    RealOptions o;
    o.package = fs::absolute(file);
    o.path_file = fs::absolute(out / "path.json");
    o.out = out / "real";
    o.link = link;
    o.tau = args.tau;
    o.settle_s = args.settle_s;
    o.path_duration_s = path.end() - path.start();
    // Cuts recorded every second; those at 1, 2 and 5 s, every --psnr-every and the last are measured.
    o.cuts_every = args.sample_every_s > 0.0 ? int(std::lround(options.fps)) : 0;
    const long every_s = std::max(1L, std::lround(args.sample_every_s));
    RealStream stream(o);
    size_t count = 0;
    for (Policy p : policies)
      if (p != Policy::oracle) ++count;
    for (Policy p : policies) {
      if (p == Policy::oracle) continue;
      const std::string label = "(" + std::to_string(real.size() + 1) + "/" + std::to_string(count) + ")";
      RealRun r = stream.run(p, label);
      auto known = [](double v) { return std::isfinite(v) ? std::optional<double>(v) : std::nullopt; };
      Run run{policy_name(p), r.frames, {}, {}, known(r.server_cpu_s), known(r.client_cpu_s)};
      run.metrics.psnr.assign(r.frames.size(), NAN);
      run.metrics.ssim.assign(r.frames.size(), NAN);
      for (const auto& [k, drawn] : r.cuts) {
        const long second = std::lround(r.frames[k].t);
        if (k + 1 != r.frames.size() && second != 1 && second != 2 && second != 5 && second % every_s != 0)
          continue;
        // The view drew frame k at path time t (its clock since it started).
        const Camera camera = path.pose_at(r.frames[k].t);
        measure_frame(run.metrics, k, frame_renderer().draw(camera, drawn),
                      frame_renderer().reference(r.frames[k].t, camera));
      }
      run.summary = summarize(run.frames, run.metrics, window_s, jumps, true);
      real.push_back(std::move(run));
    }
    std::fprintf(stderr, "\n");
  }

  const std::vector<Run>& shown = args.real ? real : simulated;
  nlohmann::json json_policies = nlohmann::json::object();
  for (const Run& r : shown) {
    write_text(out / (r.name + ".csv"), csv(r.frames, r.metrics));
    json_policies[r.name] = policy_json(r);
  }
  if (args.real) {
    fs::create_directories(out / "simulated");
    for (const Run& sim : simulated) {
      write_text(out / "simulated" / (sim.name + ".csv"), csv(sim.frames, sim.metrics));
      if (json_policies.contains(sim.name)) {
        json_policies[sim.name]["mode"] = "real";
        json_policies[sim.name]["simulated"] = policy_json(sim);
      } else {
        json_policies[sim.name] = policy_json(sim);  // oracle: no real counterpart
        json_policies[sim.name]["mode"] = "simulated only";
      }
    }
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
      {"mode", args.real ? "real" : "simulated"}};
  write_text(out / "summary.json", summary.dump(2) + "\n");
  char head[512];
  std::snprintf(head, sizeof head,
                "# bench stream%s: %s, path %s (%.1f s + %.1f s settle), link %.3g Mbit/s, RTT %.0f ms%s\n\n",
                args.real ? " --real" : "", file.filename().c_str(), args.path.c_str(),
                path.end() - path.start(), options.settle_s, link.bandwidth_bps / 1e6, link.rtt_s * 1e3,
                link.jitter_s > 0 ? (", jitter " + std::to_string(link.jitter_s * 1e3) + " ms").c_str() : "");
  std::string md = std::string(head) + summary_table(shown);
  if (args.real) {
    for (const Run& sim : simulated)
      if (!json_policies[sim.name].contains("simulated"))
        md += table_row(sim.name + " (simulated only)", sim.summary);
    md +=
        "\nReal mode: lodstream serve, a fresh lodstream link per policy and one headless lodstream view per "
        "policy (fresh cache) on loopback, on the wall clock; frame ms = the client's measured frame (cut "
        "selection), not the cost model; PSNR at t: the first frame at or after t whose cut the view "
        "recorded, "
        "drawn afterwards, against the package's finest cut from the same camera. MB: page bytes the "
        "client installed (the simulation also counts HTTP and WebSocket headers). Logs and CSVs under "
        "real/; "
        "the simulated runs under simulated/.\n\nCPU seconds (user + system) during each run: ";
    for (const Run& r : real)
      md += r.name + " server " + fixed(r.server_cpu_s, "%.2f") + ", client " +
            fixed(r.client_cpu_s, "%.2f") + (&r == &real.back() ? ".\n" : "; ");
    md += "\n## How far the two modes agree\n\n" + agreement_table(real, simulated);
  } else {
    md +=
        "\nBenefit AUC: mean benefit ratio over the window (path + settle). PSNR against the package's "
        "finest "
        "cut from the same camera (99.0: identical; '-': nothing sampled yet); a policy's PSNR at t is its "
        "last "
        "sampled frame at or before t. Simulated mode; frame times from the cost model.\n";
  }
  write_text(out / "summary.md", md);
  plot(out, shown, window_s);
  if (args.json)
    print_json(summary);
  else
    std::printf(
        "%s\nwritten to %s: summary.md, summary.json, POLICY.csv, benefit.png, psnr.png, bytes.png, "
        "path.json, %s\n",
        md.c_str(), out.c_str(), args.real ? "real/, simulated/" : "frames/");
  return 0;
}

const bool registered = register_bench(
    {"stream", "streaming policies side by side on a simulated link (or --real): CSV, summary, plots",
     [](CLI::App& sub) {
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
                    "also run each policy but oracle through lodstream serve, link and a headless view on "
                    "loopback (wall clock), reporting them beside the simulation");
       sub.add_flag("--json", args->json, "print summary.json's object");
       sub.footer(
           "Example:\n  lodstream bench stream out/motorBike.lods --path gen:fly --up 0,0,1 --link "
           "bandwidth=10mbit,rtt=80ms --out out/stream");
       return [args] { return run_bench_stream(*args); };
     }});

}  // namespace
}  // namespace lodstream::cli
