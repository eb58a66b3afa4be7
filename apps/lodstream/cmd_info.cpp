// `lodstream info MODEL [--json]`: what a model file holds (objects, vertices, triangles, bounds, attributes,
// materials) and how long it took to load.
#include <chrono>
#include <cstdio>
#include <memory>

#include "command.hpp"
#include "io/import.hpp"

namespace lodstream::cli {
namespace {

struct InfoOptions {
  std::string model;
  bool json = false;
  float crease = 60.0f;
};

int run_info(const InfoOptions& opt) {
  auto start = std::chrono::steady_clock::now();
  ImportOptions import_options;
  import_options.crease_angle_degrees = opt.crease;
  Scene scene = import_model(opt.model, import_options);
  double time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  bool normals = false, uvs = false, colors = false;
  for (const auto& m : scene.meshes) normals |= m.has_normals(), uvs |= m.has_uvs(), colors |= m.has_colors();
  nlohmann::json materials = nlohmann::json::array();
  for (const auto& m : scene.materials)
    materials.push_back({{"name", m.name},
                         {"base_color", {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a}},
                         {"texture", m.base_color_texture.empty() ? nlohmann::json(nullptr)
                                                                  : nlohmann::json(m.base_color_texture)}});
  const Bounds bounds = scene.bounds();
  if (opt.json) {
    print_json({{"file", opt.model},
                {"objects", scene.objects.size()},
                {"meshes", scene.meshes.size()},
                {"vertices", scene.vertex_count()},
                {"triangles", scene.triangle_count()},
                {"unique_triangles", scene.unique_triangle_count()},
                {"bounds", bounds_json(bounds)},
                {"diagonal", bounds.diagonal()},
                {"attributes", {{"normals", normals}, {"uvs", uvs}, {"colors", colors}}},
                {"materials", materials},
                {"time_s", time_s}});
    return 0;
  }
  std::printf("%s\n", opt.model.c_str());
  std::printf("  objects    %zu (%zu distinct meshes)\n", scene.objects.size(), scene.meshes.size());
  std::printf("  vertices   %zu\n", scene.vertex_count());
  std::printf("  triangles  %zu (%zu unique)\n", scene.triangle_count(), scene.unique_triangle_count());
  std::printf("  bounds     [%g, %g, %g] .. [%g, %g, %g] (diagonal %g)\n", bounds.min.x, bounds.min.y,
              bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z, bounds.diagonal());
  std::printf("  attributes positions%s%s%s\n", normals ? ", normals" : "", uvs ? ", uvs" : "",
              colors ? ", colors" : "");
  std::printf("  materials  %zu\n", scene.materials.size());
  for (const auto& m : scene.materials)
    std::printf("    %-24s base colour (%.3g, %.3g, %.3g, %.3g)%s%s\n", m.name.c_str(), m.base_color.r,
                m.base_color.g, m.base_color.b, m.base_color.a,
                m.base_color_texture.empty() ? "" : ", texture ", m.base_color_texture.c_str());
  std::printf("  load time  %.3f s\n", time_s);
  return 0;
}

const bool registered = register_command(
    {"info", "what a model holds: objects, vertices, triangles, bounds, attributes, materials",
     [](CLI::App& sub) {
       auto opt = std::make_shared<InfoOptions>();
       sub.add_option("MODEL", opt->model, "model file (OBJ, PLY, OFF, STL, glTF/GLB, 3DS, DAE, FBX, ...)")
           ->required();
       sub.add_flag("--json", opt->json, "print one JSON object");
       sub.add_option("--crease-angle", opt->crease,
                      "degrees; sharper normal creases stay seams when welding")
           ->capture_default_str()
           ->check(CLI::Range(0.0f, 180.0f));
       sub.footer(
           "JSON keys: objects, meshes, vertices and triangles (as drawn: instances count each time), "
           "unique_triangles,\nbounds {min, max}, diagonal, attributes {normals, uvs, colors}, materials "
           "[{name, "
           "base_color, texture}], time_s.");
       return [opt] { return run_info(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
