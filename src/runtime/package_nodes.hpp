// PackageNodes: the NodeSource that cut selection reads in a client: node records from a PackageReader (only
// those whose index page has arrived: no read is ever made from here, so a frame never waits on the
// network) and availability from a PageCache (a node is available when its data page is cached).
// Same thread-safety as PackageReader::node(): synchronise with whatever installs index pages.
#pragma once

#include "package/reader.hpp"
#include "runtime/cache.hpp"
#include "schedule/cut.hpp"

namespace lodstream::runtime {

class PackageNodes final : public NodeSource {
 public:
  PackageNodes(package::PackageReader& reader, const PageCache& cache)
      : reader_(&reader), cache_(&cache), package_(reader.header().content_hash) {}

  const package::NodeRecord* record(uint32_t id) const override { return reader_->held_node(id); }
  bool available(uint32_t id) const override {
    const package::NodeRecord* r = record(id);
    return r && cache_->contains(package_, r->page);
  }

 private:
  package::PackageReader* reader_;
  const PageCache* cache_;
  package::ContentHash package_;
};

}  // namespace lodstream::runtime
