#include "io/export.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <map>

#include "core/error.hpp"
#include "core/image.hpp"

namespace lodstream {

namespace {

// One object's vertices in world space, with every attribute the file will hold.
struct WorldMesh {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::vec4> colors;
  const std::vector<uint32_t>* indices = nullptr;
  uint32_t material = 0;
};

struct Flat {
  std::vector<WorldMesh> meshes;
  bool normals = false, uvs = false, colors = false;
};

// Applies each object's transform: p' = M p, n' = normalize((M^-1)^T n).
Flat flatten(const Scene& scene) {
  Flat flat;
  for (const auto& o : scene.objects) {
    const Mesh& m = scene.meshes.at(o.mesh);
    flat.normals |= m.has_normals();
    flat.uvs |= m.has_uvs();
    flat.colors |= m.has_colors();
  }
  for (const auto& o : scene.objects) {
    const Mesh& m = scene.meshes[o.mesh];
    WorldMesh w;
    w.indices = &m.indices;
    w.material = m.material;
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(o.transform)));
    w.positions.resize(m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i)
      w.positions[i] = glm::vec3(o.transform * glm::vec4(m.positions[i], 1));
    if (flat.normals) {
      Mesh smooth;
      const std::vector<glm::vec3>* normals = &m.normals;
      if (!m.has_normals()) {
        smooth.positions = m.positions;
        smooth.indices = m.indices;
        compute_smooth_normals(smooth);
        normals = &smooth.normals;
      }
      w.normals.resize(m.positions.size());
      for (size_t i = 0; i < m.positions.size(); ++i) {
        glm::vec3 n = normal_matrix * (*normals)[i];
        float len = glm::length(n);
        w.normals[i] = len > 0 ? n / len : glm::vec3(0, 0, 1);
      }
    }
    if (flat.uvs) w.uvs = m.has_uvs() ? m.uvs : std::vector<glm::vec2>(m.positions.size(), glm::vec2(0.0f));
    if (flat.colors) {
      glm::vec4 base =
          m.material < scene.materials.size() ? scene.materials[m.material].base_color : glm::vec4(1.0f);
      w.colors = m.has_colors() ? m.colors : std::vector<glm::vec4>(m.positions.size(), base);
    }
    flat.meshes.push_back(std::move(w));
  }
  return flat;
}

template <class T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

uint8_t to_byte(float c) {
  return static_cast<uint8_t>(std::clamp(c, 0.0f, 1.0f) * 255.0f + 0.5f);
}

std::string ply_bytes(const Scene& scene) {
  Flat flat = flatten(scene);
  size_t nv = 0, nt = 0;
  for (const auto& w : flat.meshes) nv += w.positions.size(), nt += w.indices->size() / 3;
  if (nv > UINT32_MAX / 2) throw Error("too many vertices for PLY (" + std::to_string(nv) + ")");
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by lodstream\nelement vertex " +
                    std::to_string(nv) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (flat.normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (flat.uvs) out += "property float s\nproperty float t\n";
  if (flat.colors)
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  out += "element face " + std::to_string(nt) + "\nproperty list uchar int vertex_indices\nend_header\n";
  const size_t stride = 12 + (flat.normals ? 12 : 0) + (flat.uvs ? 8 : 0) + (flat.colors ? 4 : 0);
  out.reserve(out.size() + nv * stride + nt * 13);
  for (const auto& w : flat.meshes)
    for (size_t i = 0; i < w.positions.size(); ++i) {
      put(out, w.positions[i]);
      if (flat.normals) put(out, w.normals[i]);
      if (flat.uvs) put(out, w.uvs[i]);
      if (flat.colors)
        for (int k = 0; k < 4; ++k) put(out, to_byte(w.colors[i][k]));
    }
  int32_t base = 0;
  for (const auto& w : flat.meshes) {
    const auto& idx = *w.indices;
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
      put(out, uint8_t{3});
      for (int k = 0; k < 3; ++k) put(out, static_cast<int32_t>(base + static_cast<int32_t>(idx[t + k])));
    }
    base += static_cast<int32_t>(w.positions.size());
  }
  return out;
}

// Shortest text that reads back as the same float.
void number(std::string& out, float v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, end);
}

// A name usable after `o`, `usemtl` and `newmtl` (no blanks).
std::string token(std::string name, const std::string& fallback) {
  for (char& c : name)
    if (std::isspace(static_cast<unsigned char>(c))) c = '_';
  return name.empty() ? fallback : name;
}

std::string obj_bytes(const Scene& scene, const std::string& mtl_name, std::string& mtl) {
  Flat flat = flatten(scene);
  // Unique material names.
  std::vector<std::string> names;
  std::map<std::string, int> seen;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    std::string n = token(scene.materials[i].name, "material" + std::to_string(i));
    if (seen[n]++ > 0) n += "_" + std::to_string(i);
    names.push_back(n);
    const Material& m = scene.materials[i];
    mtl += "newmtl " + n + "\nKd ";
    for (int k = 0; k < 3; ++k) number(mtl, m.base_color[k]), mtl += k < 2 ? " " : "\n";
    mtl += "d ";
    number(mtl, m.base_color.a);
    mtl += "\n";
    if (!m.base_color_texture.empty()) mtl += "map_Kd " + m.base_color_texture + "\n";
    mtl += "\n";
  }
  std::string out = "# written by lodstream\n";
  if (!scene.materials.empty()) out += "mtllib " + mtl_name + "\n";
  size_t base = 1;
  for (size_t m = 0; m < flat.meshes.size(); ++m) {
    const WorldMesh& w = flat.meshes[m];
    out += "o " + token(scene.objects[m].name, "object" + std::to_string(m)) + "\n";
    if (w.material < names.size()) out += "usemtl " + names[w.material] + "\n";
    for (size_t i = 0; i < w.positions.size(); ++i) {
      out += "v ";
      for (int k = 0; k < 3; ++k) number(out, w.positions[i][k]), out += ' ';
      if (flat.colors)
        for (int k = 0; k < 3; ++k) number(out, w.colors[i][k]), out += ' ';
      out.back() = '\n';
    }
    for (size_t i = 0; i < w.uvs.size(); ++i) {
      out += "vt ";
      number(out, w.uvs[i].x);
      out += ' ';
      number(out, w.uvs[i].y);
      out += '\n';
    }
    for (size_t i = 0; i < w.normals.size(); ++i) {
      out += "vn ";
      for (int k = 0; k < 3; ++k) number(out, w.normals[i][k]), out += k < 2 ? ' ' : '\n';
    }
    const auto& idx = *w.indices;
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
      out += 'f';
      for (int k = 0; k < 3; ++k) {
        std::string i = std::to_string(base + idx[t + k]);
        out += ' ';
        out += i;
        if (flat.uvs || flat.normals) out += '/' + (flat.uvs ? i : std::string());
        if (flat.normals) out += '/' + i;
      }
      out += '\n';
    }
    base += w.positions.size();
  }
  return out;
}

}  // namespace

void export_scene(const Scene& scene, const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const auto& o : scene.objects)
    if (o.mesh >= scene.meshes.size()) throw Error(file.string() + ": object '" + o.name + "' has no mesh");
  if (ext == ".ply") {
    std::string bytes = ply_bytes(scene);
    write_file_atomically(file, bytes.data(), bytes.size());
  } else if (ext == ".obj") {
    std::filesystem::path mtl_file = file;
    mtl_file.replace_extension(".mtl");
    std::string mtl;
    std::string bytes = obj_bytes(scene, mtl_file.filename().string(), mtl);
    if (!scene.materials.empty()) write_file_atomically(mtl_file, mtl.data(), mtl.size());
    write_file_atomically(file, bytes.data(), bytes.size());
  } else {
    throw Error(file.string() + ": cannot export: unknown extension '" + ext + "' (use .ply or .obj)");
  }
}

}  // namespace lodstream
