// DiskFirstSource: a page the disk cache holds intact is read from disk (the inner source, a counting
// wrapper over the package file, is not asked), anything else from the inner source; a corrupt or cut-short
// page file falls back to the inner source; pages served from disk are reported once.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>

#include "runtime/disk_first_source.hpp"
#include "support/dag_package.hpp"

using namespace lodstream;
using namespace lodstream::runtime;
using schedule::PageKind;

namespace {

// The package file, counting the bytes read through it.
class CountingSource final : public package::ByteSource {
 public:
  explicit CountingSource(const std::filesystem::path& path) : file_(path) {}
  uint64_t size() const override { return file_.size(); }
  void read(uint64_t offset, std::span<uint8_t> out) const override {
    file_.read(offset, out);
    bytes_ += out.size();
  }
  const std::string& name() const override { return file_.name(); }
  uint64_t bytes() const { return bytes_; }

 private:
  package::FileSource file_;
  mutable std::atomic<uint64_t> bytes_ = 0;
};

std::vector<uint8_t> read(const package::ByteSource& source, const package::Range& r) {
  std::vector<uint8_t> bytes(r.size);
  source.read(r.offset, bytes);
  return bytes;
}

}  // namespace

TEST(DiskFirstSource, ServesIntactPagesFromDiskAndEverythingElseFromTheNetwork) {
  const test::DagPackage p;
  const package::RootIndex& root = p.reader.root();
  ASSERT_GE(root.pages.size(), 3u);
  DiskCache disk(test::temp_dir(), p.reader.header().content_hash);
  package::FileSource file(p.reader.source().name());
  for (uint32_t id : {0u, 1u, 2u}) disk.store(PageKind::data, id, read(file, root.pages[id]));
  disk.store(PageKind::index, 0, read(file, root.index_pages[0].range));
  // Page 1: one byte flipped (checksum); page 2: cut short (size).
  {
    std::fstream f(disk.file(PageKind::data, 1), std::ios::in | std::ios::out | std::ios::binary);
    const char c = char(f.get());
    f.seekp(0);
    f.put(char(c ^ 0x5a));
  }
  std::filesystem::resize_file(disk.file(PageKind::data, 2), root.pages[2].size - 1);

  auto inner = std::make_shared<CountingSource>(p.reader.source().name());
  auto pages = std::make_shared<DiskPages>(disk, root);
  const DiskFirstSource source(inner, pages);
  EXPECT_EQ(source.size(), file.size());
  EXPECT_EQ(source.name(), file.name());

  // Intact pages on disk: the same bytes as the package's, none read from the inner source.
  EXPECT_EQ(read(source, root.pages[0]), read(file, root.pages[0]));
  EXPECT_EQ(read(source, root.index_pages[0].range), read(file, root.index_pages[0].range));
  EXPECT_EQ(inner->bytes(), 0u);
  EXPECT_TRUE(pages->take_served({PageKind::data, 0}));
  EXPECT_FALSE(pages->take_served({PageKind::data, 0}));  // reported once
  EXPECT_TRUE(pages->take_served({PageKind::index, 0}));

  // A corrupt, a cut-short and an absent page file: the package's bytes, from the inner source.
  uint64_t expected = 0;
  for (uint32_t id = 1; id < root.pages.size(); ++id) {
    EXPECT_EQ(read(source, root.pages[id]), read(file, root.pages[id])) << id;
    expected += root.pages[id].size;
    EXPECT_FALSE(pages->take_served({PageKind::data, id})) << id;
  }
  EXPECT_EQ(inner->bytes(), expected);

  // A read that is not exactly a page (the root index, part of a page) goes to the inner source.
  std::vector<uint8_t> part(root.pages[0].size - 1);
  source.read(root.pages[0].offset, part);
  EXPECT_EQ(inner->bytes(), expected + part.size());
  EXPECT_FALSE(pages->take_served({PageKind::data, 0}));
}
