// `lodstream measure A B [--samples N] [--json]`: Metro-style distance between two models' surfaces.
// `lodstream measure --images A.png B.png [--json]`: PSNR and SSIM between two images.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "io/import.hpp"
#include "measure/image_metrics.hpp"
#include "measure/surface_distance.hpp"
#include "measure/world_surface.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct MeasureOptions {
  std::vector<std::string> files;
  bool images = false;
  bool json = false;
  size_t samples = 0;
};

// The world-space surface of a model file; errors name the file.
lodstream::Mesh load_surface(const std::string& file) {
  lodstream::Scene scene = lodstream::import_model(file);
  try {
    lodstream::Mesh surface = lodstream::world_surface(scene);
    if (surface.triangle_count() == 0) throw lodstream::Error("no triangles to measure");
    return surface;
  } catch (const lodstream::Error& e) {
    throw lodstream::Error(file + ": " + e.what());
  }
}

// A ratio, or null when the denominator is 0 (a surface collapsed to a point has no diagonal).
nlohmann::json relative(double value, double diagonal) {
  return diagonal > 0 ? nlohmann::json(value / diagonal) : nlohmann::json(nullptr);
}

int measure_models(const MeasureOptions& o) {
  const Clock::time_point load_start = Clock::now();
  const lodstream::Mesh a = load_surface(o.files[0]);
  const lodstream::Mesh b = load_surface(o.files[1]);
  const double load_s = seconds_since(load_start);

  const Clock::time_point start = Clock::now();
  const lodstream::SurfaceDistance d = lodstream::measure_surface_distance(a, b, {o.samples, 1});
  const double time_s = seconds_since(start);
  const double diagonal = b.bounds().diagonal();

  if (o.json) {
    lodstream::cli::print_json({{"hausdorff", d.hausdorff},
                                {"mean", d.mean},
                                {"rms", d.rms},
                                {"a_to_b_max", d.a_to_b.max},
                                {"b_to_a_max", d.b_to_a.max},
                                {"a_to_b_mean", d.a_to_b.mean},
                                {"b_to_a_mean", d.b_to_a.mean},
                                {"diagonal", diagonal},
                                {"hausdorff_relative", relative(d.hausdorff, diagonal)},
                                {"mean_relative", relative(d.mean, diagonal)},
                                {"rms_relative", relative(d.rms, diagonal)},
                                {"samples", d.samples},
                                {"time_s", time_s},
                                {"load_time_s", load_s}});
    return 0;
  }
  auto percent = [&](double v) { return diagonal > 0 ? 100.0 * v / diagonal : 0.0; };
  std::printf("A: %s (%zu triangles)\nB: %s (%zu triangles), bounding-box diagonal %g\n", o.files[0].c_str(),
              a.triangle_count(), o.files[1].c_str(), b.triangle_count(), diagonal);
  std::printf("hausdorff  %-12g (%.6f%% of the diagonal)\n", d.hausdorff, percent(d.hausdorff));
  std::printf("  A to B max %-12g mean %g\n", d.a_to_b.max, d.a_to_b.mean);
  std::printf("  B to A max %-12g mean %g\n", d.b_to_a.max, d.b_to_a.mean);
  std::printf("mean       %-12g (%.6f%%)\n", d.mean, percent(d.mean));
  std::printf("rms        %-12g (%.6f%%)\n", d.rms, percent(d.rms));
  std::printf("%zu samples in %.3f s (loading took %.3f s)\n", d.samples, time_s, load_s);
  return 0;
}

int measure_images(const MeasureOptions& o) {
  const lodstream::Image a = lodstream::load_image(o.files[0]);
  const lodstream::Image b = lodstream::load_image(o.files[1]);
  double psnr = 0, ssim = 0;
  try {
    psnr = lodstream::psnr(a, b);
    ssim = lodstream::ssim(a, b);
  } catch (const lodstream::Error& e) {
    throw lodstream::Error(o.files[0] + " and " + o.files[1] + ": " + e.what());
  }
  if (o.json) {
    lodstream::cli::print_json(
        {{"psnr", std::isinf(psnr) ? nlohmann::json(nullptr) : nlohmann::json(psnr)}, {"ssim", ssim}});
    return 0;
  }
  if (std::isinf(psnr))
    std::printf("psnr inf (identical)\n");
  else
    std::printf("psnr %.4f dB\n", psnr);
  std::printf("ssim %.6f\n", ssim);
  return 0;
}

const bool registered = lodstream::cli::register_command(
    {"measure",
     "distance between two models' surfaces (Hausdorff, mean, RMS), or PSNR and SSIM of two images",
     [](CLI::App& sub) {
       auto o = std::make_shared<MeasureOptions>();
       sub.add_option("files", o->files, "A B: two models (or two images with --images)")
           ->required()
           ->expected(2);
       sub.add_flag("--images", o->images, "compare two images: PSNR over RGB and SSIM on luminance");
       sub.add_option(
              "--samples", o->samples,
              "area samples per surface (default: 2 per triangle, at least 100000); every vertex and at "
              "least one point per triangle are sampled as well")
           ->check(CLI::PositiveNumber);
       sub.add_flag("--json", o->json, "print one JSON object");
       return [o]() -> int {
         if (o->images && o->samples) throw lodstream::Error("--samples applies to models, not to --images");
         return o->images ? measure_images(*o) : measure_models(*o);
       };
     }});

}  // namespace
