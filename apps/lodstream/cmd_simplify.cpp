// `lodstream simplify`: one simplified mesh (DESIGN.md, The command line): quadric edge collapse to a ratio,
// a triangle count or an error bound, with the two-sided error bound reported.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "command.hpp"
#include "core/error.hpp"
#include "io/export.hpp"
#include "io/import.hpp"
#include "simplify/scene_simplify.hpp"

namespace lodstream::cli {
namespace {

struct SimplifyArgs {
  std::string model, output;
  std::optional<double> ratio, error, error_relative;
  std::optional<size_t> triangles;
  bool json = false, positions_only = false, half_edge = false, allow_topology_change = false;
};

// A text progress bar on standard error, redrawn when the percentage changes.
class ProgressBar {
 public:
  void operator()(float f) {
    int percent = int(std::clamp(f, 0.0f, 1.0f) * 100);
    if (percent == last_) return;
    last_ = percent;
    std::fprintf(stderr, "\rsimplify [%-40s] %3d%%", std::string(size_t(percent * 40 / 100), '#').c_str(),
                 percent);
    if (percent == 100) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  int last_ = -1;
};

int run_simplify(const SimplifyArgs& args) {
  int targets = args.ratio.has_value() + args.triangles.has_value() + args.error.has_value() +
                args.error_relative.has_value();
  if (targets != 1)
    throw Error("simplify: give exactly one of --ratio, --triangles, --error, --error-relative");
  if (args.ratio && !(*args.ratio > 0 && *args.ratio <= 1)) throw Error("--ratio: must be in (0, 1]");
  if (args.error && !(*args.error >= 0)) throw Error("--error: must be >= 0");
  if (args.error_relative && !(*args.error_relative >= 0)) throw Error("--error-relative: must be >= 0");
  auto ext = std::filesystem::path(args.output).extension().string();
  if (ext != ".obj" && ext != ".ply" && ext != ".OBJ" && ext != ".PLY")
    throw Error(args.output + ": output must be .obj or .ply");

  auto start = std::chrono::steady_clock::now();
  Scene scene = import_model(args.model);
  const size_t input = scene.triangle_count();
  size_t target = 0;
  double max_error = INFINITY;
  if (args.ratio) target = size_t(std::llround(*args.ratio * double(input)));
  if (args.triangles) target = *args.triangles;
  if (args.error) max_error = *args.error;
  if (args.error_relative) max_error = *args.error_relative * scene.bounds().diagonal();

  simplify::Options options;
  if (args.positions_only) options.normal_weight = options.uv_weight = options.color_weight = 0;
  options.half_edge = args.half_edge;
  options.allow_topology_change = args.allow_topology_change;
  ProgressBar bar;
  if (input > 1000000) options.progress = [&bar](float f) { bar(f); };
  auto result = simplify::simplify_scene(scene, target, max_error, options);
  if (input > 1000000) bar(1.0f);
  export_scene(result.scene, args.output);
  double time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (!result.target_reached)
    std::fprintf(stderr, "lodstream: simplify: %s stopped at %zu triangles, short of the target %zu\n",
                 args.allow_topology_change ? "vertex clustering" : "topology-preserving collapse",
                 result.output_triangles, target);
  if (args.json) {
    print_json({{"input_triangles", input},
                {"output_triangles", result.output_triangles},
                {"time_s", time_s},
                {"error_bound", result.error_bound},
                {"target_triangles", target},
                {"target_reached", result.target_reached}});
  } else {
    std::printf("%zu -> %zu triangles in %.3f s, error bound %.6g (%.4g %% of the diagonal)%s\n", input,
                result.output_triangles, time_s, result.error_bound,
                100.0 * result.error_bound / std::max(1e-30, double(scene.bounds().diagonal())),
                result.target_reached ? "" : ", target not reached");
  }
  return 0;
}

const bool registered = register_command(
    {"simplify", "simplify a model by quadric edge collapse to a ratio, a triangle count or an error bound",
     [](CLI::App& sub) {
       auto args = std::make_shared<SimplifyArgs>();
       sub.add_option("MODEL", args->model, "input model (PLY, OBJ, OFF, or any format assimp reads)")
           ->required();
       sub.add_option("-o,--output", args->output, "output mesh, .obj or .ply")->required();
       sub.add_option("--ratio", args->ratio, "keep this fraction of the triangles, in (0, 1]");
       sub.add_option("--triangles", args->triangles, "keep this many triangles (as drawn)");
       sub.add_option("--error", args->error, "largest two-sided error bound, model units");
       sub.add_option("--error-relative", args->error_relative,
                      "largest two-sided error bound as a fraction of the bounding-box diagonal");
       sub.add_flag("--positions-only", args->positions_only, "attribute weights 0 (geometry-only metric)");
       sub.add_flag("--half-edge", args->half_edge,
                    "half-edge collapses (output vertices are input vertices)");
       sub.add_flag("--allow-topology-change", args->allow_topology_change,
                    "continue with vertex clustering where edge collapse cannot reach the triangle target");
       sub.add_flag("--json", args->json,
                    "print one JSON object: input_triangles, output_triangles, time_s, "
                    "error_bound");
       sub.footer("error_bound is a conservative bound on the symmetric Hausdorff distance to the input.");
       return [args] { return run_simplify(*args); };
     }});

}  // namespace
}  // namespace lodstream::cli
