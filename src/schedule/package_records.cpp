#include "schedule/package_records.hpp"

namespace lodstream::schedule {

PackageRecords::PackageRecords(package::PackageReader reader) {
  records_.reserve(reader.node_count());
  for (uint32_t id = 0; id < reader.node_count(); ++id) records_.push_back(reader.node(id));
}

}  // namespace lodstream::schedule
