#include "io/import.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <exception>

#include "core/error.hpp"
#include "io/import_worker.hpp"
#include "io/obj_reader.hpp"
#include "io/off_reader.hpp"
#include "io/ply_reader.hpp"
#include "io/validate.hpp"
#include "io/weld.hpp"

namespace lodstream {

namespace {

// Validates and welds every mesh, drops objects whose mesh has no triangles left, and meshes and materials no
// object uses; prints one warning line per kind of repair.
void prepare_scene(Scene& scene, const ImportOptions& options, const std::string& file) {
  // Meshes are independent: validated and welded in parallel; the first error in mesh order is reported.
  std::vector<std::string> what(scene.meshes.size(), file);
  if (scene.meshes.size() > 1)
    for (size_t o = scene.objects.size(); o-- > 0;)
      if (scene.objects[o].mesh < what.size())
        what[scene.objects[o].mesh] = file + " (object '" + scene.objects[o].name + "')";
  std::vector<ValidationCounts> counts(scene.meshes.size());
  std::vector<std::exception_ptr> errors(scene.meshes.size());
  tbb::parallel_for(size_t(0), scene.meshes.size(), [&](size_t m) {
    try {
      Mesh& mesh = scene.meshes[m];
      if (mesh.material >= scene.materials.size())
        throw Error(what[m] + ": material index " + std::to_string(mesh.material) + " out of range");
      counts[m] = validate_mesh(mesh, what[m]);
      if (!mesh.indices.empty()) weld(mesh, options.crease_angle_degrees);
    } catch (...) {
      errors[m] = std::current_exception();
    }
  });
  size_t degenerate = 0, dropped_normals = 0;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (errors[m]) std::rethrow_exception(errors[m]);
    degenerate += counts[m].degenerate_triangles;
    dropped_normals += counts[m].dropped_normals;
  }
  if (degenerate > 0)
    std::fprintf(stderr, "lodstream: warning: %s: dropped %zu degenerate (zero-area) triangles\n",
                 file.c_str(), degenerate);
  if (dropped_normals > 0)
    std::fprintf(stderr, "lodstream: warning: %s: %zu meshes had invalid normals; recomputed them\n",
                 file.c_str(), dropped_normals);

  // Drop empty objects, then renumber the meshes and materials that are still used.
  for (const auto& o : scene.objects) {
    if (o.mesh >= scene.meshes.size())
      throw Error(file + ": object '" + o.name + "' references a missing mesh");
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(o.transform[c][r]))
          throw Error(file + ": object '" + o.name + "' has a non-finite transform");
  }
  std::erase_if(scene.objects, [&](const Object& o) { return scene.meshes[o.mesh].indices.empty(); });
  if (scene.objects.empty()) throw Error(file + ": no triangles (the model is empty)");
  std::vector<uint32_t> mesh_index(scene.meshes.size(), UINT32_MAX),
      material_index(scene.materials.size(), UINT32_MAX);
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  for (auto& o : scene.objects) {
    if (mesh_index[o.mesh] == UINT32_MAX) {
      mesh_index[o.mesh] = static_cast<uint32_t>(meshes.size());
      Mesh& mesh = scene.meshes[o.mesh];
      if (material_index[mesh.material] == UINT32_MAX) {
        material_index[mesh.material] = static_cast<uint32_t>(materials.size());
        materials.push_back(std::move(scene.materials[mesh.material]));
      }
      mesh.material = material_index[mesh.material];
      meshes.push_back(std::move(mesh));
    }
    o.mesh = mesh_index[o.mesh];
  }
  scene.meshes = std::move(meshes);
  scene.materials = std::move(materials);
}

}  // namespace

Scene import_model(const std::filesystem::path& file, const ImportOptions& options) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw Error(file.string() + ": cannot open: " +
                (std::filesystem::exists(file, ec) ? "not a regular file" : "no such file"));
  Scene scene;
  if (ext == ".ply")
    scene = read_ply(file);
  else if (ext == ".off")
    scene = read_off(file);
  else if (ext == ".obj")
    scene = read_obj(file);
  else
    scene = import_in_worker(file, options);
  prepare_scene(scene, options, file.string());
  return scene;
}

}  // namespace lodstream
