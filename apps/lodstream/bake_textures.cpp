#include "bake_textures.hpp"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>

namespace lodstream::cli {

EmbeddedTextures embed_textures(const std::vector<Material>& materials, package::PackageWriter& writer) {
  EmbeddedTextures out;
  std::map<std::string, uint32_t> blob_of_file;
  for (const Material& m : materials) {
    package::PackageMaterial pm{m, package::kNone};
    const std::string& file = m.base_color_texture;
    if (!file.empty()) {
      auto it = blob_of_file.find(file);
      if (it == blob_of_file.end()) {
        std::ifstream in(file, std::ios::binary);
        const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), {}};
        if (!in.bad() && !bytes.empty()) {
          it = blob_of_file.emplace(file, writer.add_blob(bytes)).first;
          out.bytes += bytes.size();
        } else {
          std::fprintf(stderr, "bake: warning: material '%s': texture %s cannot be read; kept as a path\n",
                       m.name.c_str(), file.c_str());
        }
      }
      if (it != blob_of_file.end()) {
        pm.texture_blob = it->second;
        pm.material.base_color_texture = std::filesystem::path(file).filename().string();
      }
    }
    out.materials.push_back(std::move(pm));
  }
  return out;
}

}  // namespace lodstream::cli
