// `lodstream render`: a shaded image of a model or a package from an explicit camera (DESIGN.md, The command
// line), drawn headless through EGL (llvmpipe without a GPU). A package (.lods) is drawn at its cut for the
// camera and --pixel-error, with every node available (the reference a streaming client is compared with).
// With --frames N it draws N times and reports the median time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "command.hpp"
#include "core/camera.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "cut_drawer.hpp"
#include "io/import.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "render/scene_upload.hpp"
#include "runtime/cut_geometry.hpp"
#include "runtime/quality.hpp"
#include "timing.hpp"

namespace lodstream::cli {
namespace {

struct RenderOptions {
  std::string model, eye, target, up, camera_file, size, output;
  std::optional<float> fov;
  std::optional<double> pixel_error;
  int frames = 1;
  int msaa = 0;
  bool json = false;
};

Camera camera_from(const RenderOptions& opt) {
  Camera camera;
  std::string where;
  if (!opt.camera_file.empty()) {
    camera = load_camera(opt.camera_file);
    where = opt.camera_file;
  } else {
    if (opt.eye.empty() || opt.target.empty())
      throw Error("give a camera: --eye X,Y,Z --target X,Y,Z, or --camera CAM.json");
    camera.eye = parse_vec3(opt.eye, "--eye");
    camera.target = parse_vec3(opt.target, "--target");
    if (!opt.up.empty()) camera.up = parse_vec3(opt.up, "--up");
    if (opt.fov) camera.fov_y_degrees = *opt.fov;
    where = "--eye/--target/--up/--fov";
  }
  if (!opt.size.empty()) std::tie(camera.width, camera.height) = parse_size(opt.size, "--size");
  validate_camera(camera, where);
  return camera;
}

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void check_output(const std::filesystem::path& output) {
  if (lower_extension(output) != ".png") throw Error(output.string() + ": the output must be a .png file");
  const std::filesystem::path dir = output.parent_path().empty() ? "." : output.parent_path();
  if (!std::filesystem::is_directory(dir))
    throw Error(output.string() + ": folder " + dir.string() + " does not exist");
}

bool is_package(const std::filesystem::path& file) {
  return lower_extension(file) == ".lods";
}

// A package's cut for `camera` at `tau` pixels, every node available, its records decoded.
struct PackageCut {
  std::unique_ptr<package::PackageReader> reader;  // held where `geometry` points
  std::unique_ptr<runtime::CutGeometry> geometry;
  size_t nodes = 0;
  double pixel_error_max = 0.0;
};

PackageCut package_cut(const std::string& file, const Camera& camera, double tau) {
  PackageCut out;
  out.reader = std::make_unique<package::PackageReader>(package::PackageReader::open(file));
  package::PackageReader& reader = *out.reader;
  runtime::ReaderNodes nodes(reader);
  const schedule::Cut cut = schedule::select_cut(reader.scene(), nodes, schedule::View::of(camera), {tau});
  out.geometry = std::make_unique<runtime::CutGeometry>(reader, std::filesystem::path(file).parent_path());
  out.geometry->update(cut, runtime::pages_from_reader(reader));
  for (const std::string& warning : out.geometry->warnings())
    std::fprintf(stderr, "lodstream: warning: %s\n", warning.c_str());
  out.nodes = cut.drawn.size();
  out.pixel_error_max =
      runtime::frame_quality(reader.scene(), nodes, cut, schedule::View::of(camera), tau).pixel_error_max;
  return out;
}

int run_render(const RenderOptions& opt) {
  if (opt.frames < 1) throw Error("--frames must be at least 1, got " + std::to_string(opt.frames));
  if (opt.msaa < 0) throw Error("--msaa must be 0 (off) or a sample count, got " + std::to_string(opt.msaa));
  const Camera camera = camera_from(opt);
  check_output(opt.output);

  const auto load_start = std::chrono::steady_clock::now();
  const bool package = is_package(opt.model);
  if (opt.pixel_error && !package)
    throw Error("--pixel-error applies to a package (.lods), not " + opt.model);
  const double tau = opt.pixel_error.value_or(1.0);
  if (!(tau > 0.0) || !std::isfinite(tau))
    throw Error("--pixel-error must be a positive number of pixels, got " + std::to_string(tau));
  PackageCut cut;
  Scene scene;
  if (package)
    cut = package_cut(opt.model, camera, tau);
  else
    scene = import_model(opt.model);
  const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();

  auto context = render::create_headless_context();
  render::Renderer renderer(*context, {opt.msaa});
  const auto upload_start = std::chrono::steady_clock::now();
  // A package's cut as a client draws it (each decoded record uploaded once, its clusters drawn as ranges);
  // a model as one scene.
  std::optional<CutDrawer> drawer;
  render::SceneUpload upload;
  if (package) {
    drawer.emplace(renderer, cut.geometry->materials());
    upload.items = drawer->items(*cut.geometry);
    upload.triangles = cut.geometry->triangles();
    upload.warnings = drawer->warnings();
  } else {
    upload = render::upload_scene(renderer, scene);
  }
  const double upload_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - upload_start).count();
  for (const std::string& warning : upload.warnings)
    std::fprintf(stderr, "lodstream: warning: %s\n", warning.c_str());

  // Wall time per frame, and the CPU time of all the process's threads (llvmpipe's included) per frame: on a
  // shared machine the second tells what a frame costs when the first is inflated by other processes.
  std::vector<double> draw_ms, cpu_ms;
  for (int i = 0; i < opt.frames; ++i) {
    const double cpu_start = 1e3 * process_cpu_s();
    draw_ms.push_back(renderer.draw(camera, upload.items));
    cpu_ms.push_back(1e3 * process_cpu_s() - cpu_start);
  }
  save_png(renderer.read_pixels(), opt.output);

  if (opt.json) {
    nlohmann::json out = {{"triangles", upload.triangles},
                          {"width", camera.width},
                          {"height", camera.height},
                          {"frames", opt.frames},
                          {"draw_ms", median(draw_ms)},
                          {"draw_ms_min", *std::min_element(draw_ms.begin(), draw_ms.end())},
                          {"draw_cpu_ms", median(cpu_ms)},
                          {"load_s", load_s},
                          {"upload_s", upload_s},
                          {"renderer", context->renderer()},
                          {"platform", context->platform()},
                          {"msaa", opt.msaa},
                          {"output", opt.output}};
    // held_triangles: the decoded records' (every cluster of a record that the cut draws any of), decoded and
    // uploaded whole.
    if (package)
      out.update({{"nodes", cut.nodes},
                  {"pixel_error", tau},
                  {"pixel_error_max", cut.pixel_error_max},
                  {"held_triangles", cut.geometry->held_triangles()}});
    print_json(out);
  } else {
    std::printf("%s: %zu triangles, %dx%d, draw %.1f ms (median of %d), load %.2f s, %s\n",
                opt.output.c_str(), upload.triangles, camera.width, camera.height, median(draw_ms),
                opt.frames, load_s, context->renderer().c_str());
  }
  return 0;
}

const bool registered = register_command(
    {"render", "a shaded image of a model from an explicit camera (headless OpenGL)", [](CLI::App& sub) {
       auto opt = std::make_shared<RenderOptions>();
       sub.add_option("MODEL", opt->model, "model file (OBJ, PLY, OFF, glTF, ...) or package (.lods)")
           ->required();
       sub.add_option("--pixel-error", opt->pixel_error,
                      "a package's target screen-space error in pixels: the cut drawn (default 1)");
       auto* eye = sub.add_option("--eye", opt->eye, "camera position X,Y,Z");
       auto* target = sub.add_option("--target", opt->target, "point looked at X,Y,Z");
       auto* up = sub.add_option("--up", opt->up, "up direction X,Y,Z (default 0,1,0)");
       auto* fov = sub.add_option("--fov", opt->fov, "vertical field of view in degrees (default 60)");
       sub.add_option("--camera", opt->camera_file, "camera file {eye, target, up, fov, size} (DESIGN.md)")
           ->excludes(eye, target, up, fov);
       sub.add_option("--size", opt->size, "image size WxH (default 1280x720, or the camera file's size)");
       sub.add_option("--frames", opt->frames, "draw this many times and report the median draw time")
           ->capture_default_str();
       sub.add_option("--msaa", opt->msaa, "samples per pixel (0: none, deterministic and fastest)")
           ->capture_default_str();
       sub.add_option("-o,--output", opt->output, "output PNG")->required();
       sub.add_flag("--json", opt->json, "print one JSON object");
       sub.footer(
           "Example:\n  lodstream render data/motorBike.obj --eye 6,3,6 --target 0,0.5,0 --size 1280x720 -o "
           "bike.png");
       return [opt] { return run_render(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
