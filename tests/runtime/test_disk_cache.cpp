#include <gtest/gtest.h>

#include <fstream>

#include "runtime/disk_cache.hpp"
#include "support/dag_package.hpp"

using namespace lodstream;
using namespace lodstream::runtime;
using schedule::PageKind;

namespace {

// A client of the synthetic DAG package, opened afresh (nothing held).
ClientPackage client_of(const test::DagPackage& p, uint64_t budget = 1u << 30) {
  return ClientPackage(package::PackageReader::open(p.reader.source().name()), budget);
}

// A page's stored bytes as the package holds them (what a transport delivers).
std::vector<uint8_t> stored(const package::PackageReader& reader, PageKind kind, uint32_t id) {
  const package::Range& r =
      kind == PageKind::data ? reader.root().pages[id] : reader.root().index_pages[id].range;
  std::vector<uint8_t> bytes(r.size);
  reader.source().read(r.offset, bytes);
  return bytes;
}

// Receives every page of `p` (installing it in a client) and stores it in `disk`; returns the stored bytes.
uint64_t receive_all(const test::DagPackage& p, DiskCache& disk) {
  ClientPackage client = client_of(p);
  for (PageKind kind : {PageKind::index, PageKind::data}) {
    const size_t count =
        kind == PageKind::data ? p.reader.root().pages.size() : p.reader.root().index_pages.size();
    for (uint32_t id = 0; id < count; ++id) {
      const auto bytes = stored(p.reader, kind, id);
      client.install(kind, id, bytes);
      disk.store(kind, id, bytes);
    }
  }
  return client.bytes_received();
}

}  // namespace

TEST(DiskCache, ASecondSessionStartsFromEveryPageTheFirstReceived) {
  const test::DagPackage p;
  const auto root = test::temp_dir();
  DiskCache first(root, p.reader.header().content_hash);
  EXPECT_EQ(first.directory(), root / p.reader.header().content_hash.hex());
  const uint64_t received = receive_all(p, first);

  ClientPackage client = client_of(p);
  const RestoredPages restored = DiskCache(root, p.reader.header().content_hash).restore(client, 1u << 30);
  EXPECT_TRUE(restored.warnings.empty()) << restored.warnings.front();
  EXPECT_EQ(restored.pages, p.reader.root().pages.size() + p.reader.root().index_pages.size());
  EXPECT_EQ(restored.stored_bytes, received);
  EXPECT_EQ(client.bytes_restored(), received);
  EXPECT_EQ(client.bytes_received(), 0u);  // nothing came over a transport
  // Every page is held: the client reports them all and its scheduler would fetch nothing.
  EXPECT_EQ(client.held(PageKind::data).size(), p.reader.root().pages.size());
  EXPECT_EQ(client.held(PageKind::index).size(), p.reader.root().index_pages.size());
  for (uint32_t id = 0; id < p.reader.root().pages.size(); ++id)
    EXPECT_TRUE(client.cache().contains(p.reader.header().content_hash, id)) << id;
  for (uint32_t id = 0; id < p.reader.node_count(); ++id) EXPECT_TRUE(client.reader().has_node(id)) << id;

  // Another package (another content hash) finds nothing of this one's.
  ClientPackage other = client_of(p);
  EXPECT_EQ(DiskCache(root, package::ContentHash{1, 2}).restore(other, 1u << 30).pages, 0u);
  EXPECT_EQ(other.bytes_restored(), 0u);
}

TEST(DiskCache, CorruptAndForeignFilesAreDroppedWithAWarningNeverTrusted) {
  const test::DagPackage p;
  const auto root = test::temp_dir();
  DiskCache disk(root, p.reader.header().content_hash);
  receive_all(p, disk);
  // Page 0: one byte flipped (checksum); page 1: cut short (size); index page 0: another page's bytes;
  // d999999: a page the package does not have; notes.txt: not a page file.
  {
    std::fstream f(disk.file(PageKind::data, 0), std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(5);
    const char c = char(f.get());
    f.seekp(5);
    f.put(char(c ^ 0x40));
  }
  std::filesystem::resize_file(disk.file(PageKind::data, 1), 10);
  std::filesystem::copy_file(disk.file(PageKind::data, 2), disk.file(PageKind::index, 0),
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::copy_file(disk.file(PageKind::data, 3), disk.file(PageKind::data, 999999));
  std::ofstream(disk.directory() / "notes.txt") << "hello";

  ClientPackage client = client_of(p);
  const RestoredPages restored = disk.restore(client, 1u << 30);
  ASSERT_EQ(restored.warnings.size(), 5u);
  auto warned = [&](const std::filesystem::path& file, const std::string& why) {
    for (const auto& w : restored.warnings)
      if (w.find(file.string()) != std::string::npos && w.find(why) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(warned(disk.file(PageKind::data, 0), "checksum")) << restored.warnings[0];
  EXPECT_TRUE(warned(disk.file(PageKind::data, 1), "10 bytes"));
  EXPECT_TRUE(warned(disk.file(PageKind::index, 0), "dropped"));
  EXPECT_TRUE(warned(disk.file(PageKind::data, 999999), "no such page"));
  EXPECT_TRUE(warned(disk.directory() / "notes.txt", "ignored"));
  // The bad page files are gone; the foreign file is left alone; the good pages are held.
  EXPECT_FALSE(std::filesystem::exists(disk.file(PageKind::data, 0)));
  EXPECT_FALSE(std::filesystem::exists(disk.file(PageKind::data, 1)));
  EXPECT_FALSE(std::filesystem::exists(disk.file(PageKind::index, 0)));
  EXPECT_FALSE(std::filesystem::exists(disk.file(PageKind::data, 999999)));
  EXPECT_TRUE(std::filesystem::exists(disk.directory() / "notes.txt"));
  const auto hash = p.reader.header().content_hash;
  EXPECT_FALSE(client.cache().contains(hash, 0));
  EXPECT_FALSE(client.cache().contains(hash, 1));
  EXPECT_TRUE(client.cache().contains(hash, 2));
  EXPECT_EQ(restored.pages, p.reader.root().pages.size() - 2 + p.reader.root().index_pages.size() - 1);
  // What was dropped is simply not held: the scheduler fetches it again.
  const auto data = client.held(PageKind::data);
  EXPECT_EQ(std::count(data.begin(), data.end(), 0u), 0);
  const auto index = client.held(PageKind::index);
  EXPECT_EQ(std::count(index.begin(), index.end(), 0u), 0);
}

TEST(DiskCache, LoadsDataPagesOnlyUnderTheMemoryBudget) {
  const test::DagPackage p;
  const auto root = test::temp_dir();
  DiskCache disk(root, p.reader.header().content_hash);
  receive_all(p, disk);
  // A budget for three pages' decompressed bytes: pages 0, 1, 2 load, the rest stay on disk.
  const auto& pages = p.reader.root().pages;
  const uint64_t budget = uint64_t(pages[0].raw_size) + pages[1].raw_size + pages[2].raw_size;
  ClientPackage client = client_of(p, budget);
  const RestoredPages restored = disk.restore(client, budget);
  EXPECT_TRUE(restored.warnings.empty());
  EXPECT_EQ(client.held(PageKind::data), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_LE(client.cache().bytes(), budget);
  EXPECT_EQ(client.held(PageKind::index).size(), p.reader.root().index_pages.size());  // records always load
  EXPECT_TRUE(std::filesystem::exists(disk.file(PageKind::data, 3)));
}
