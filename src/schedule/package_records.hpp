// Every node record of a package, loaded once: what a push server's scheduler sees (it reads the whole index,
// whatever the client holds). A NodeSource whose available() is always false: what a client holds is the
// scheduler's held set (page_scheduler.hpp), not this. Immutable after construction, so sessions on several
// threads share one. Cost: one read of every index page; memory: the records.
#pragma once

#include <vector>

#include "package/reader.hpp"
#include "schedule/cut.hpp"

namespace lodstream::schedule {

class PackageRecords final : public NodeSource {
 public:
  // Loads every record through a copy of `reader` (reading the index pages it has not loaded). Throws
  // lodstream::Error when an index page cannot be read or is invalid.
  explicit PackageRecords(package::PackageReader reader);

  const package::NodeRecord* record(uint32_t id) const override {
    return id < records_.size() ? &records_[id] : nullptr;
  }
  bool available(uint32_t) const override { return false; }
  size_t size() const { return records_.size(); }

 private:
  std::vector<package::NodeRecord> records_;
};

}  // namespace lodstream::schedule
