// `lodstream bench simplify`: meshoptimizer 0.18's meshopt_simplify (the anchor, DESIGN.md Targets) first,
// then lodstream at exactly the triangle count meshoptimizer reached, with default attribute weights and
// positions only; for each: time, triangles, symmetric Hausdorff and mean distance to the input (relative to
// its bounding-box diagonal) and the mean PSNR of renders from three fixed cameras against the input.
#include <meshoptimizer.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "bench.hpp"
#include "core/error.hpp"
#include "io/import.hpp"
#include "measure/image_metrics.hpp"
#include "measure/surface_distance.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "render/scene_upload.hpp"
#include "simplify/scene_simplify.hpp"
#include "timing.hpp"

namespace lodstream::cli {
namespace {

struct BenchArgs {
  std::string model;
  double ratio = 0.1;
  bool json = false;
  int runs = 1;
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// meshopt_simplify on every mesh (target: ratio of its indices, no error limit); returns the time.
void run_meshoptimizer(double ratio, Scene& out) {
  for (Mesh& m : out.meshes) {
    std::vector<uint32_t> dst(m.indices.size());
    size_t target = size_t(double(m.indices.size() / 3) * ratio) * 3;
    size_t n = meshopt_simplify(dst.data(), m.indices.data(), m.indices.size(), &m.positions[0].x,
                                m.positions.size(), sizeof(glm::vec3), target, FLT_MAX, 0, nullptr);
    dst.resize(n);
    m.indices = std::move(dst);
  }
}

// Three fixed views of the input's bounding sphere (front, side, above at an angle), 640 x 480.
std::vector<Camera> bench_cameras(const Scene& scene) {
  Bounds b = scene.bounds();
  glm::vec3 c = b.center();
  float d = 1.2f * b.diagonal();
  std::vector<Camera> cams;
  for (glm::vec3 dir : {glm::vec3(0, 0, 1), glm::vec3(1, 0.2f, 0), glm::vec3(-0.5f, 0.8f, -0.6f)}) {
    Camera cam;
    cam.eye = c + glm::normalize(dir) * d;
    cam.target = c;
    cam.fov_y_degrees = 45;
    cam.width = 640, cam.height = 480;
    cams.push_back(cam);
  }
  return cams;
}

class Renders {
 public:
  explicit Renders(const Scene& reference) : cameras_(bench_cameras(reference)) {
    try {
      context_ = render::create_headless_context();
      renderer_ = std::make_unique<render::Renderer>(*context_);
      reference_ = draw(reference);
    } catch (const Error& e) {
      std::fprintf(stderr, "bench simplify: no renders (%s); psnr is null\n", e.what());
      renderer_.reset();
    }
  }
  // Mean PSNR over the cameras against the reference renders; NaN without a renderer.
  double psnr(const Scene& scene) {
    if (!renderer_) return NAN;
    auto images = draw(scene);
    double sum = 0;
    for (size_t i = 0; i < images.size(); ++i) {
      double p = lodstream::psnr(images[i], reference_[i]);
      sum += std::isfinite(p) ? p : 99.0;
    }
    return sum / double(images.size());
  }

 private:
  std::vector<Image> draw(const Scene& scene) {
    auto upload = render::upload_scene(*renderer_, scene);
    std::vector<Image> images;
    for (const Camera& cam : cameras_) {
      renderer_->draw(cam, upload.items);
      images.push_back(renderer_->read_pixels());
    }
    render::release_scene(*renderer_, upload);
    return images;
  }
  std::vector<Camera> cameras_;
  std::unique_ptr<render::Context> context_;
  std::unique_ptr<render::Renderer> renderer_;
  std::vector<Image> reference_;
};

// One side's figures: wall and process CPU seconds of its simplification, and how close `out` is to `in`.
nlohmann::json row(const Scene& in, const Scene& out, double time_s, double cpu_s, Renders& renders) {
  auto d = measure_surface_distance(in, out);
  double diag = in.bounds().diagonal();
  double psnr = renders.psnr(out);
  return {{"time_s", time_s},
          {"cpu_s", cpu_s},
          {"triangles", out.triangle_count()},
          {"hausdorff_relative", d.hausdorff / diag},
          {"mean_relative", d.mean / diag},
          {"psnr", std::isfinite(psnr) ? nlohmann::json(psnr) : nlohmann::json(nullptr)}};
}

int run_bench(const BenchArgs& args) {
  if (!(args.ratio > 0 && args.ratio <= 1)) throw Error("--ratio: must be in (0, 1]");
  Scene in = import_model(args.model);
  Renders renders(in);
  nlohmann::json result;
  result["model"] = args.model;
  result["input_triangles"] = in.triangle_count();
  result["ratio"] = args.ratio;

  // The sides take turns, --runs times (a slow spell of the machine then hits all three); each reports the
  // median wall and CPU time of its runs and the quality of its last output (the same every run).
  struct Side {
    const char* key;
    Scene out;
    std::vector<double> wall, cpu;
  };
  Side sides[] = {
      {"meshoptimizer", {}, {}, {}}, {"lodstream", {}, {}, {}}, {"lodstream_positions_only", {}, {}, {}}};
  for (int run = 0; run < args.runs; ++run) {
    for (size_t s = 0; s < 3; ++s) {
      Side& side = sides[s];
      side.out = in;
      simplify::Options options;
      if (s == 2) options.normal_weight = options.uv_weight = options.color_weight = 0;
      const auto start = Clock::now();
      const double cpu = process_cpu_s();
      if (s == 0) {
        run_meshoptimizer(args.ratio, side.out);
      } else {
        // Each mesh to exactly the count meshoptimizer reached for it.
        for (size_t i = 0; i < in.meshes.size(); ++i) {
          options.target_triangles = sides[0].out.meshes[i].triangle_count();
          side.out.meshes[i] = simplify::simplify_mesh(in.meshes[i], options).mesh;
        }
      }
      side.wall.push_back(seconds_since(start));
      side.cpu.push_back(process_cpu_s() - cpu);
    }
  }
  for (const Side& side : sides)
    result[side.key] = row(in, side.out, median(side.wall), median(side.cpu), renders);
  result["runs"] = args.runs;
  if (args.json) {
    print_json(result);
  } else {
    std::printf("%s: %zu triangles, ratio %g\n", args.model.c_str(), in.triangle_count(), args.ratio);
    std::printf("%-26s %9s %9s %10s %12s %12s %8s\n", "", "time_s", "cpu_s", "triangles", "hausdorff_rel",
                "mean_rel", "psnr");
    for (const char* key : {"meshoptimizer", "lodstream", "lodstream_positions_only"}) {
      const auto& r = result[key];
      std::printf("%-26s %9.3f %9.3f %10zu %12.3e %12.3e %8.2f\n", key, r["time_s"].get<double>(),
                  r["cpu_s"].get<double>(), r["triangles"].get<size_t>(),
                  r["hausdorff_relative"].get<double>(), r["mean_relative"].get<double>(),
                  r["psnr"].is_null() ? NAN : r["psnr"].get<double>());
    }
  }
  return 0;
}

const bool registered = register_bench(
    {"simplify", "lodstream's simplifier against meshoptimizer 0.18 at the same triangle count",
     [](CLI::App& sub) {
       auto args = std::make_shared<BenchArgs>();
       sub.add_option("MODEL", args->model, "input model")->required();
       sub.add_option("--ratio", args->ratio, "fraction of the triangles meshoptimizer is asked to keep")
           ->capture_default_str();
       sub.add_option("--runs", args->runs,
                      "times each side runs, taking turns; the medians are reported (1..20)")
           ->capture_default_str()
           ->check(CLI::Range(1, 20));
       sub.add_flag("--json", args->json, "print one JSON object");
       return [args] { return run_bench(*args); };
     }});

}  // namespace
}  // namespace lodstream::cli
