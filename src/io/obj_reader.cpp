#include "io/obj_reader.hpp"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cstdio>
#include <map>

#include "core/error.hpp"

namespace lodstream {

namespace {

// First line of a (possibly multi-line) tinyobjloader message.
std::string first_line(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

std::filesystem::path texture_path(const std::filesystem::path& dir, std::string name) {
  if (name.empty()) return {};
  std::replace(name.begin(), name.end(), '\\', '/');
  std::filesystem::path p(name);
  if (p.is_relative()) p = dir / p;
  return std::filesystem::absolute(p).lexically_normal();
}

}  // namespace

Scene read_obj(const std::filesystem::path& path) {
  const std::string file = path.string();
  if (!std::filesystem::is_regular_file(path)) throw Error(file + ": cannot open: no such file");
  const std::filesystem::path dir =
      path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = true;
  config.mtl_search_path = dir.string() + "/";
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(file, config))
    throw Error(file + ": " +
                (reader.Error().empty() ? std::string("cannot parse OBJ") : first_line(reader.Error())));
  if (!reader.Warning().empty())
    std::fprintf(stderr, "lodstream: warning: %s: %s\n", file.c_str(), first_line(reader.Warning()).c_str());

  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  const size_t nv = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3,
               nt = attrib.texcoords.size() / 2;
  // tinyobjloader fills absent vertex colours with white: colours count as present only when one is not
  // white.
  const bool colors =
      attrib.colors.size() == attrib.vertices.size() &&
      std::any_of(attrib.colors.begin(), attrib.colors.end(), [](float c) { return c != 1.0f; });

  Scene scene;
  const auto& materials = reader.GetMaterials();
  for (const auto& m : materials) {
    Material mat;
    mat.name = m.name;
    mat.base_color = glm::vec4(m.diffuse[0], m.diffuse[1], m.diffuse[2], m.dissolve);
    mat.base_color_texture = texture_path(dir, m.diffuse_texname).string();
    scene.materials.push_back(std::move(mat));
  }
  const uint32_t default_material = static_cast<uint32_t>(scene.materials.size());
  bool default_used = false;

  for (const auto& shape : reader.GetShapes()) {
    const auto& m = shape.mesh;
    // One mesh per material used by the shape, in order of first use.
    std::map<int, Mesh> by_material;
    std::vector<int> order;
    size_t corner = 0;
    for (size_t f = 0; f < m.num_face_vertices.size(); ++f) {
      const size_t n = m.num_face_vertices[f];
      int mat = f < m.material_ids.size() ? m.material_ids[f] : -1;
      if (mat < 0 || static_cast<size_t>(mat) >= materials.size()) mat = -1;
      auto [it, inserted] = by_material.try_emplace(mat);
      if (inserted) order.push_back(mat);
      Mesh& mesh = it->second;
      if (corner + n > m.indices.size())
        throw Error(file + ": inconsistent face data in group '" + shape.name + "'");
      if (n != 3) {  // tinyobjloader leaves polygons it could not triangulate; skip them
        corner += n;
        continue;
      }
      for (size_t k = 0; k < 3; ++k, ++corner) {
        const tinyobj::index_t& ix = m.indices[corner];
        if (ix.vertex_index < 0 || static_cast<size_t>(ix.vertex_index) >= nv)
          throw Error(file + ": face in group '" + shape.name + "' references vertex " +
                      std::to_string(ix.vertex_index + 1) + ", but there are only " + std::to_string(nv));
        if (ix.normal_index >= 0 && static_cast<size_t>(ix.normal_index) >= nn)
          throw Error(file + ": face in group '" + shape.name + "' references normal " +
                      std::to_string(ix.normal_index + 1) + ", but there are only " + std::to_string(nn));
        if (ix.texcoord_index >= 0 && static_cast<size_t>(ix.texcoord_index) >= nt)
          throw Error(file + ": face in group '" + shape.name + "' references texture coordinate " +
                      std::to_string(ix.texcoord_index + 1) + ", but there are only " + std::to_string(nt));
        const float* p = &attrib.vertices[3 * ix.vertex_index];
        mesh.positions.emplace_back(p[0], p[1], p[2]);
        // A normal or UV is kept per corner; a mesh where some corners lack one loses that attribute below.
        mesh.normals.push_back(ix.normal_index >= 0 ? glm::vec3(attrib.normals[3 * ix.normal_index],
                                                                attrib.normals[3 * ix.normal_index + 1],
                                                                attrib.normals[3 * ix.normal_index + 2])
                                                    : glm::vec3(NAN));
        mesh.uvs.push_back(ix.texcoord_index >= 0 ? glm::vec2(attrib.texcoords[2 * ix.texcoord_index],
                                                              attrib.texcoords[2 * ix.texcoord_index + 1])
                                                  : glm::vec2(NAN));
        if (colors) {
          const float* c = &attrib.colors[3 * ix.vertex_index];
          mesh.colors.emplace_back(c[0], c[1], c[2], 1.0f);
        }
        mesh.indices.push_back(static_cast<uint32_t>(mesh.indices.size()));
      }
    }
    for (int mat : order) {
      Mesh& mesh = by_material[mat];
      if (mesh.indices.empty()) continue;
      if (std::any_of(mesh.normals.begin(), mesh.normals.end(),
                      [](const glm::vec3& n) { return n.x != n.x; }))
        mesh.normals.clear();
      if (std::any_of(mesh.uvs.begin(), mesh.uvs.end(), [](const glm::vec2& t) { return t.x != t.x; }))
        mesh.uvs.clear();
      mesh.material = mat < 0 ? default_material : static_cast<uint32_t>(mat);
      default_used |= mat < 0;
      std::string name = shape.name.empty() ? path.stem().string() : shape.name;
      if (order.size() > 1) name += "/" + (mat < 0 ? std::string("default") : materials[mat].name);
      scene.objects.push_back(
          Object{std::move(name), glm::mat4(1.0f), static_cast<uint32_t>(scene.meshes.size())});
      scene.meshes.push_back(std::move(mesh));
    }
  }
  if (default_used) scene.materials.emplace_back().name = "default";  // base colour 0.8 grey
  return scene;
}

}  // namespace lodstream
