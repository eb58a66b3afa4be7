#include "raw_package.hpp"

#include <vector>

namespace lodstream::test {

package::WrittenPackage write_raw_package(const std::filesystem::path& file, uint32_t nodes, uint8_t salt) {
  package::WriterOptions options;
  options.page_bytes = 4096;
  options.nodes_per_index_page = 16;
  package::PackageWriter writer(file, options);
  std::vector<package::NodeRecord> records(nodes);
  for (uint32_t i = 0; i < nodes; ++i) {
    std::vector<uint8_t> bytes(1000 + i * 13);
    for (size_t k = 0; k < bytes.size(); ++k) bytes[k] = uint8_t(k * 31 + i * 7 + salt);
    writer.add_node(i, bytes);
    writer.end_group();
    records[i].encoding = package::NodeEncoding::raw;
  }
  package::PackageScene scene;
  package::Representation rep;
  rep.bounds.add(glm::vec3(0.0f));
  rep.bounds.add(glm::vec3(1.0f));
  rep.roots = {0};
  scene.materials = {package::PackageMaterial{}};
  scene.representations = {rep};
  scene.objects = {{"o", glm::mat4(1.0f), 0}};
  return writer.finish(scene, records, 4);
}

}  // namespace lodstream::test
