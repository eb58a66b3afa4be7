// account_index (package/index_account.hpp): it accounts every record once, its field streams are exactly the
// stored index pages' records (the sizes' varints aside), and the stored bytes it reports are the file's.
#include <gtest/gtest.h>

#include <numeric>

#include "package/bytes.hpp"
#include "package/index_account.hpp"
#include "package/reader.hpp"
#include "package_fixture.hpp"
#include "support/run.hpp"

namespace lodstream::test {
namespace {

using namespace package;

TEST(IndexAccount, FieldsAddUpToTheStoredRecords) {
  const auto file = temp_dir() / "index_account.lods";
  write_test_package(file);
  PackageReader reader = PackageReader::open(file);
  const IndexAccount a = account_index(reader);
  EXPECT_EQ(a.records, reader.node_count());
  EXPECT_EQ(a.root_stored, reader.header().root_size);

  // Each index page's records, re-serialized, are its raw bytes; the fields are those bytes but their sizes.
  const RootIndex& root = reader.root();
  ASSERT_GT(root.index_pages.size(), 1u);
  std::array<uint64_t, kIndexFields> raw{};
  uint64_t pages_stored = 0;
  auto add = [&](std::span<const NodeRecord> records, uint32_t first_id) {
    const auto fields = serialize_node_fields(records, first_id);
    ByteWriter sizes;
    for (size_t f = 0; f < kIndexFields; ++f) raw[f] += fields[f].size(), sizes.varint(fields[f].size());
    return sizes.bytes.size();
  };
  add(root.root_nodes, 0);
  for (const IndexPage& page : root.index_pages) {
    std::vector<NodeRecord> records;
    for (uint32_t id = page.first_node; id < page.first_node + page.node_count; ++id)
      records.push_back(reader.node(id));
    const uint64_t before = std::accumulate(raw.begin(), raw.end(), uint64_t(0));
    const size_t sizes = add(records, page.first_node);
    const uint64_t fields = std::accumulate(raw.begin(), raw.end(), uint64_t(0)) - before;
    EXPECT_EQ(fields + sizes, page.range.raw_size) << "index page of node " << page.first_node;
    EXPECT_EQ(serialize_nodes(records, page.first_node).size(), page.range.raw_size);
    pages_stored += page.range.size;
  }
  EXPECT_EQ(a.pages_stored, pages_stored);
  for (size_t f = 0; f < kIndexFields; ++f) {
    EXPECT_EQ(a.raw[f], raw[f]) << kIndexFieldNames[f];
    EXPECT_EQ(a.raw[f] == 0, a.compressed[f] == 0) << kIndexFieldNames[f];
  }
  // One head byte per record (kIndexFieldNames[0]), and at least one varint byte of triangle count ([4]).
  EXPECT_EQ(a.raw[0], a.records);
  EXPECT_GE(a.raw[4], a.records);
}

}  // namespace
}  // namespace lodstream::test
