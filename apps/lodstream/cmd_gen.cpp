// `lodstream gen`: deterministic large test inputs derived from real meshes (DESIGN.md, Test data).
//   gen subdivide MODEL --levels N -o OUT.ply   Loop subdivision (refined_elephant: 2 levels → 1.4M, 3
//   → 5.7M) gen layout MODEL... --copies N,... -o OUT   many copies of real models on a grid, one object per
//   part
#include <chrono>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <memory>
#include <unordered_map>

#include "command.hpp"
#include "core/error.hpp"
#include "io/export.hpp"
#include "io/import.hpp"
#include "loop_subdivision.hpp"

namespace lodstream::cli {
namespace {

struct GenOptions {
  std::vector<std::string> models;
  std::string output;
  int levels = 1;
  std::vector<int> copies;
  float spacing = 1.2f;
};

// Every object of `scene` with its transform applied, as one surface welded by position (attribute seams
// would otherwise open cracks under Loop subdivision).
Mesh flatten(const Scene& scene) {
  Mesh out;
  struct Hash {
    size_t operator()(const glm::vec3& p) const {
      return std::hash<float>()(p.x) ^ (std::hash<float>()(p.y) * 31) ^ (std::hash<float>()(p.z) * 131);
    }
  };
  std::unordered_map<glm::vec3, uint32_t, Hash> index;
  for (const auto& o : scene.objects) {
    const Mesh& m = scene.meshes[o.mesh];
    for (uint32_t i : m.indices) {
      glm::vec3 p = glm::vec3(o.transform * glm::vec4(m.positions[i], 1.0f));
      auto [it, inserted] = index.try_emplace(p, uint32_t(out.positions.size()));
      if (inserted) out.positions.push_back(p);
      out.indices.push_back(it->second);
    }
  }
  return out;
}

int run_subdivide(const GenOptions& opt) {
  if (opt.levels < 1 || opt.levels > 5) throw Error("--levels must be between 1 and 5");
  auto start = std::chrono::steady_clock::now();
  Scene in = import_model(opt.models.at(0));
  Mesh mesh = loop_subdivide(flatten(in), opt.levels);
  std::fprintf(stderr, "gen: %s: %zu triangles -> %zu after %d levels of Loop subdivision\n",
               opt.models[0].c_str(), in.triangle_count(), mesh.triangle_count(), opt.levels);
  size_t triangles = mesh.triangle_count();
  export_scene(make_scene(std::move(mesh), "subdivided"), opt.output);
  print_json({{"output", opt.output},
              {"triangles", triangles},
              {"time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}});
  return 0;
}

// Model i gets copies[i] instances in a square grid whose cell is `spacing` times the model's footprint
// (x, y: the Debian models are z-up); the grids of successive models are laid out one after another along -y.
// Meshes are stored once; objects reference them (instances).
int run_layout(const GenOptions& opt) {
  if (opt.copies.size() != opt.models.size())
    throw Error("--copies needs one count per model (" + std::to_string(opt.models.size()) + " models)");
  if (!(opt.spacing >= 1.0f && opt.spacing <= 100.0f)) throw Error("--spacing must be between 1 and 100");
  Scene layout;
  float y0 = 0.0f;
  for (size_t i = 0; i < opt.models.size(); ++i) {
    if (opt.copies[i] < 1 || opt.copies[i] > 10000) throw Error("--copies: each count must be in 1..10000");
    Scene model = import_model(opt.models[i]);
    Bounds b = model.bounds();
    glm::vec3 cell = b.extent() * opt.spacing;
    int columns = int(std::ceil(std::sqrt(double(opt.copies[i]))));
    uint32_t material_base = uint32_t(layout.materials.size()), mesh_base = uint32_t(layout.meshes.size());
    layout.materials.insert(layout.materials.end(), model.materials.begin(), model.materials.end());
    for (auto& m : model.meshes) {
      m.material += material_base;
      layout.meshes.push_back(std::move(m));
    }
    for (int c = 0; c < opt.copies[i]; ++c) {
      glm::vec3 offset{float(c % columns) * cell.x - b.min.x, y0 - float(c / columns + 1) * cell.y - b.min.y,
                       -b.min.z};
      glm::mat4 place = glm::translate(glm::mat4(1.0f), offset);
      for (const auto& o : model.objects)
        layout.objects.push_back(
            Object{o.name + "#" + std::to_string(c), place * o.transform, o.mesh + mesh_base});
    }
    y0 -= float((opt.copies[i] + columns - 1) / columns) * cell.y;
  }
  std::fprintf(stderr, "gen: layout of %zu objects, %zu triangles\n", layout.objects.size(),
               layout.triangle_count());
  export_scene(layout, opt.output);
  print_json(
      {{"output", opt.output}, {"objects", layout.objects.size()}, {"triangles", layout.triangle_count()}});
  return 0;
}

const bool registered = register_command(
    {"gen", "derive large test inputs from real meshes (Loop subdivision, layouts of many copies)",
     [](CLI::App& sub) {
       auto opt = std::make_shared<GenOptions>();
       sub.require_subcommand(1);
       auto* subdivide =
           sub.add_subcommand("subdivide", "Loop-subdivide MODEL (each level: 4x the triangles)");
       subdivide->add_option("model", opt->models, "input model")->required()->expected(1);
       subdivide->add_option("--levels", opt->levels, "levels of subdivision (1..5)")->required();
       subdivide->add_option("-o,--output", opt->output, "output .ply or .obj")->required();
       auto* layout = sub.add_subcommand("layout", "lay out copies of MODELs on a grid, one object per part");
       layout->add_option("models", opt->models, "input models")->required();
       layout->add_option("--copies", opt->copies, "copies of each model, comma-separated")
           ->required()
           ->delimiter(',');
       layout->add_option("--spacing", opt->spacing, "grid cell as a multiple of a model's footprint")
           ->capture_default_str();
       layout->add_option("-o,--output", opt->output, "output .obj (one group per object)")->required();
       return [opt, subdivide]() { return subdivide->parsed() ? run_subdivide(*opt) : run_layout(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
