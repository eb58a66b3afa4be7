// Packages for scheduler and protocol tests: the synthetic DAG (synthetic_dag.hpp) or hand-made records
// written as a real .lods file with one node per data page and small index pages, and the NodeSource of what
// a PageScheduler says the client holds. Header-only: the including test links the package module.
#pragma once

#include <functional>
#include <random>
#include <string>

#include "package/reader.hpp"
#include "package/writer.hpp"
#include "schedule/package_records.hpp"
#include "schedule/page_scheduler.hpp"
#include "support/run.hpp"
#include "support/synthetic_dag.hpp"

namespace lodstream::test {

// Writes `records` as a package with one node per data page, node i's stored bytes `size(i)` random
// (incompressible) bytes, `root_nodes` records in the root index and 8 per index page after them.
inline package::PackageReader write_package(const std::string& name, std::vector<package::NodeRecord> records,
                                            const package::PackageScene& scene, uint32_t root_nodes,
                                            const std::function<size_t(uint32_t)>& size) {
  const auto file = test::temp_dir() / name;
  package::WriterOptions options;
  options.page_bytes = 256;  // every node closes its page
  options.nodes_per_index_page = 8;
  std::mt19937 random(7);
  package::PackageWriter writer(file, options);
  for (uint32_t i = 0; i < records.size(); ++i) {
    records[i].encoding = package::NodeEncoding::raw;
    std::vector<uint8_t> bytes(size(i));
    for (auto& b : bytes) b = uint8_t(random());
    writer.add_node(i, bytes);
    writer.end_group();
  }
  package::PackageScene s = scene;
  s.materials = {package::PackageMaterial{}};
  writer.finish(s, records, root_nodes);
  return package::PackageReader::open(file);
}

// What the client holds, as the scheduler's held set says: a node is available when its record and its data
// page are held.
struct Held : schedule::NodeSource {
  const NodeSource& all;
  const schedule::PageScheduler& scheduler;
  Held(const NodeSource& a, const schedule::PageScheduler& s) : all(a), scheduler(s) {}
  const package::NodeRecord* record(uint32_t id) const override {
    return scheduler.record_held(id) ? all.record(id) : nullptr;
  }
  bool available(uint32_t id) const override {
    const package::NodeRecord* r = record(id);
    return r && scheduler.node_held(*r);
  }
};

// The synthetic DAG as one object, written with node i's 700 random bytes (or `size(i)`) in its own page.
struct DagPackage {
  SyntheticDag dag = SyntheticDag::make();
  package::PackageReader reader;
  schedule::PackageRecords all;  // the records as written (with their pages)
  explicit DagPackage(std::function<size_t(uint32_t)> size = [](uint32_t) { return 700; })
      : reader(write_package("dag.lods", dag.records, dag.scene({glm::mat4(1.0f)}), 4, size)), all(reader) {}
  uint32_t page_of(uint32_t node) const { return all.record(node)->page; }
  const package::PackageScene& scene() const { return reader.scene(); }
};

}  // namespace lodstream::test
