// Corrupted and hostile packages: truncation at every length, flipped bytes at every position, and crafted
// headers / indices with valid checksums (huge counts, offsets past the end, overlapping pages, out-of-range
// ids, NaNs). Every case must end in a one-line lodstream::Error naming the file, or read back exactly the
// original content; never a crash (this test also runs under AddressSanitizer, see the package report).
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <fstream>
#include <functional>

#include "core/error.hpp"
#include "package/bytes.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/quantized_node.hpp"
#include "package/reader.hpp"
#include "package/traversal_codec.hpp"
#include "package_fixture.hpp"
#include "support/run.hpp"

namespace lodstream::test {
namespace {

using namespace package;

class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::vector<uint8_t> bytes) : bytes_(std::move(bytes)) {}
  uint64_t size() const override { return bytes_.size(); }
  void read(uint64_t offset, std::span<uint8_t> out) const override {
    if (offset > bytes_.size() || out.size() > bytes_.size() - offset)
      throw Error(name_ + ": read past the end");
    std::copy_n(bytes_.begin() + std::ptrdiff_t(offset), out.size(), out.begin());
  }
  const std::string& name() const override { return name_; }

 private:
  std::vector<uint8_t> bytes_;
  std::string name_ = "hostile.lods";
};

struct Content {
  std::vector<NodeRecord> records;
  std::vector<DecodedNode> nodes;
  std::vector<std::vector<uint8_t>> blobs;
};

// Reads everything a client could ask for.
Content read_all(PackageReader& reader) {
  Content c;
  for (uint32_t id = 0; id < reader.node_count(); ++id) c.records.push_back(reader.node(id));
  for (uint32_t id = 0; id < reader.node_count(); ++id) c.nodes.push_back(reader.load_node(id));
  for (uint32_t b = 0; b < reader.root().blobs.size(); ++b) c.blobs.push_back(reader.read_blob(b));
  return c;
}

bool same(const Content& a, const Content& b) {
  if (a.records.size() != b.records.size() || a.nodes.size() != b.nodes.size() || a.blobs != b.blobs)
    return false;
  for (size_t i = 0; i < a.records.size(); ++i) {
    const NodeRecord &x = a.records[i], &y = b.records[i];
    if (x.page != y.page || x.offset != y.offset || x.size != y.size || x.cluster != y.cluster ||
        x.children != y.children || x.parents != y.parents || x.objects != y.objects ||
        x.triangles != y.triangles || x.error != y.error) {
      return false;
    }
  }
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const Mesh &x = a.nodes[i].mesh, &y = b.nodes[i].mesh;
    if (x.indices != y.indices || x.positions != y.positions || x.normals != y.normals || x.uvs != y.uvs ||
        x.colors != y.colors) {
      return false;
    }
  }
  return true;
}

class Corruption : public ::testing::TestWithParam<uint32_t> {
 protected:
  void SetUp() override {
    std::filesystem::path file = temp_dir() / "small.lods";
    write_test_package(file, GetParam());
    std::ifstream in(file, std::ios::binary);
    original = {std::istreambuf_iterator<char>(in), {}};
    PackageReader reader(std::make_shared<MemorySource>(original));
    reference = read_all(reader);
    header = reader.header();
    root = reader.root();
  }

  enum class Outcome { error, intact };
  // Opens and reads everything; an Error must be one line naming the source, anything else must be intact.
  Outcome outcome(std::vector<uint8_t> bytes, std::string* message = nullptr) {
    try {
      PackageReader reader(std::make_shared<MemorySource>(std::move(bytes)));
      Content c = read_all(reader);
      EXPECT_TRUE(same(c, reference)) << "corruption went undetected and changed the content";
      return Outcome::intact;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.rfind("hostile.lods", 0), 0u) << what;
      if (message) *message = what;
      return Outcome::error;
    }
  }

  // The package with its root index replaced by `raw_root` and valid checksums, sizes and content hash.
  std::vector<uint8_t> with_raw_root(std::span<const uint8_t> raw_root) {
    std::vector<uint8_t> out(original.begin(), original.begin() + std::ptrdiff_t(header.root_offset));
    std::vector<uint8_t> stored = zstd_compress(raw_root, 3);
    Header h = header;
    h.root_size = uint32_t(stored.size());
    h.root_raw_size = uint32_t(raw_root.size());
    h.root_checksum = checksum64(stored);
    out.insert(out.end(), stored.begin(), stored.end());
    h.file_size = out.size() + kHeaderSize;
    ContentHasher hasher;
    hasher.update(std::span(out).subspan(kHeaderSize));
    h.content_hash = hasher.digest();
    auto bytes = encode_header(h);
    std::copy(bytes.begin(), bytes.end(), out.begin());
    out.insert(out.end(), bytes.begin(), bytes.end());
    return out;
  }
  std::vector<uint8_t> with_root(const std::function<void(RootIndex&)>& mutate) {
    RootIndex r = root;
    mutate(r);
    return with_raw_root(serialize_root(r));
  }
  // The package with both header copies rewritten by `mutate` (no other change).
  std::vector<uint8_t> with_header(const std::function<void(Header&)>& mutate) {
    Header h = header;
    mutate(h);
    auto bytes = encode_header(h);
    std::vector<uint8_t> out = original;
    std::copy(bytes.begin(), bytes.end(), out.begin());
    std::copy(bytes.begin(), bytes.end(), out.end() - kHeaderSize);
    return out;
  }

  std::vector<uint8_t> original;
  Content reference;
  Header header;
  RootIndex root;
};

INSTANTIATE_TEST_SUITE_P(Codecs, Corruption,
                         ::testing::Values(MeshoptCodec::kId, PredictiveCodec::kId, TraversalCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(Corruption, TheRebuildHelperItselfGivesAValidPackage) {
  EXPECT_EQ(outcome(with_root([](RootIndex&) {})), Outcome::intact);
}

TEST_P(Corruption, EveryTruncationIsAnError) {
  for (size_t n = 0; n < original.size(); ++n) {
    ASSERT_EQ(outcome(std::vector<uint8_t>(original.begin(), original.begin() + std::ptrdiff_t(n))),
              Outcome::error)
        << "truncated to " << n;
  }
}

TEST_P(Corruption, FlippedBytesAreErrorsOrHarmlessAndVerifyCatchesAll) {
  size_t errors = 0;
  for (size_t at = 0; at < original.size(); ++at) {
    for (uint8_t mask : {uint8_t(0xff), uint8_t(0x01)}) {
      if (mask == 0x01 && at % 3 != 0) continue;  // single-bit flips at every third byte keep the test fast
      std::vector<uint8_t> bad = original;
      bad[at] ^= mask;
      errors += outcome(bad) == Outcome::error;
      // Whatever a lazy read saw, the content hash check sees every flip.
      try {
        PackageReader reader(std::make_shared<MemorySource>(bad));
        EXPECT_THROW(reader.verify(), Error) << "flip at " << at << " not caught by verify";
      } catch (const Error&) {
      }
    }
  }
  // Only flips inside the unused parts of the header copies (the header at offset 0, the content hash in
  // the trailer) can leave the content readable.
  EXPECT_GE(errors, (original.size() - 2 * kHeaderSize) * 4 / 3);
}

TEST_P(Corruption, HostileHeadersAreErrors) {
  std::vector<std::function<void(Header&)>> cases = {
      [](Header& h) { h.version = 99; },
      [](Header& h) { h.file_size = uint64_t(1) << 60; },
      [](Header& h) { h.root_offset = h.file_size; },
      [](Header& h) { h.root_offset = 3; },
      [](Header& h) { h.root_size = UINT32_MAX; },
      [](Header& h) { h.root_raw_size = UINT32_MAX; },
      [](Header& h) { h.root_raw_size += 1; },
      [](Header& h) { h.root_checksum ^= 1; },
  };
  for (size_t i = 0; i < cases.size(); ++i)
    EXPECT_EQ(outcome(with_header(cases[i])), Outcome::error) << "case " << i;
  std::vector<uint8_t> bad_magic = original;
  bad_magic[bad_magic.size() - kHeaderSize + 1] = 'X';
  std::string message;
  EXPECT_EQ(outcome(bad_magic, &message), Outcome::error);
  EXPECT_NE(message.find("magic"), std::string::npos) << message;
}

TEST_P(Corruption, HostileRootIndicesAreErrors) {
  const uint64_t end = original.size();
  std::vector<std::pair<const char*, std::function<void(RootIndex&)>>> cases = {
      {"2^32-1 nodes", [](RootIndex& r) { r.node_count = UINT32_MAX; }},
      {"index page claims 2^31 nodes", [](RootIndex& r) { r.index_pages[0].node_count = 1u << 31; }},
      {"index page range gap", [](RootIndex& r) { r.index_pages[1].first_node += 1; }},
      {"index pages shifted",
       [](RootIndex& r) {
         r.index_pages[0].node_count += 1;
         r.index_pages[1].first_node += 1;
         r.index_pages[1].node_count -= 1;
       }},
      {"page past the end", [&](RootIndex& r) { r.pages[1].offset = end + 100; }},
      {"page of 4 GiB", [](RootIndex& r) { r.pages[1].size = UINT32_MAX; }},
      {"page offset 2^63", [](RootIndex& r) { r.pages[0].offset = uint64_t(1) << 63; }},
      {"overlapping pages", [](RootIndex& r) { r.pages[1].offset = r.pages[0].offset; }},
      {"page overlaps the header", [](RootIndex& r) { r.pages[0].offset = 10; }},
      {"page raw size over the limit", [](RootIndex& r) { r.pages[0].raw_size = kMaxPageRawBytes + 1; }},
      {"page raw size lies", [](RootIndex& r) { r.pages[0].raw_size -= 1; }},
      {"page checksum", [](RootIndex& r) { r.pages.back().checksum ^= 4; }},
      {"blob past the end", [&](RootIndex& r) { r.blobs[0].offset = end; }},
      {"node outside its page",
       [](RootIndex& r) { r.root_nodes[0].offset = r.pages[r.root_nodes[0].page].raw_size; }},
      {"node size past its page", [](RootIndex& r) { r.root_nodes[1].size = UINT32_MAX; }},
      {"node in a page that does not exist", [](RootIndex& r) { r.root_nodes[0].page = 1000; }},
      {"child id out of range", [](RootIndex& r) { r.root_nodes[1].children.push_back(r.node_count); }},
      {"parent id negative", [](RootIndex& r) { r.root_nodes[2].parents = {UINT32_MAX}; }},
      {"object id out of range", [](RootIndex& r) { r.root_nodes[0].objects = {99}; }},
      {"representation out of range", [](RootIndex& r) { r.root_nodes[0].representation = 7; }},
      {"material out of range", [](RootIndex& r) { r.root_nodes[0].material = 7; }},
      {"NaN error", [](RootIndex& r) { r.root_nodes[0].error = std::nanf(""); }},
      {"negative error", [](RootIndex& r) { r.root_nodes[0].error = -1.0f; }},
      {"NaN parents' error", [](RootIndex& r) { r.root_nodes[1].parent_error = std::nanf(""); }},
      {"NaN radius", [](RootIndex& r) { r.root_nodes[1].sphere.radius = std::nanf(""); }},
      {"infinite parents' radius", [](RootIndex& r) { r.root_nodes[0].parent_sphere.radius = INFINITY; }},
      {"negative radius", [](RootIndex& r) { r.root_nodes[0].sphere.radius = -1.0f; }},
      {"infinite centre", [](RootIndex& r) { r.root_nodes[0].sphere.center.x = INFINITY; }},
      {"wrong triangle count", [](RootIndex& r) { r.root_nodes[0].triangles += 1; }},
      {"cluster past its record's", [](RootIndex& r) { r.root_nodes[0].cluster = kMaxRecordClusters - 1; }},
      {"NaN transform", [](RootIndex& r) { r.scene.objects[0].transform[1][1] = std::nanf(""); }},
      {"object representation", [](RootIndex& r) { r.scene.objects[0].representation = 2; }},
      {"zero grid step", [](RootIndex& r) { r.scene.representations[0].grid.step = 0.0f; }},
      {"root node id", [](RootIndex& r) { r.scene.representations[0].roots = {1u << 30}; }},
      {"texture blob", [](RootIndex& r) { r.scene.materials[1].texture_blob = 5; }},
      {"unknown codec", [](RootIndex& r) { r.codec = 7; }},
  };
  for (const auto& [name, mutate] : cases) {
    std::string message;
    EXPECT_EQ(outcome(with_root(mutate), &message), Outcome::error) << name;
    EXPECT_FALSE(message.empty()) << name;
  }
}

TEST_P(Corruption, HugeCountsInHandWrittenRootsAreErrors) {
  // Root index prefix: codec, node count, input triangles, metadata; then a count that would need exabytes.
  auto prefix = [&]() {
    ByteWriter w;
    w.u32(root.codec);
    w.u32(root.node_count);
    w.u64(0);
    w.string("");
    return w;
  };
  for (int table = 0; table < 6; ++table) {
    ByteWriter w = prefix();
    for (int empty = 0; empty < table; ++empty) w.varint(0);  // earlier tables empty
    w.varint(uint64_t(1) << 60);
    std::string message;
    EXPECT_EQ(outcome(with_raw_root(w.bytes), &message), Outcome::error) << "table " << table;
    EXPECT_NE(message.find("impossible"), std::string::npos) << message;
  }
  ByteWriter w = prefix();
  w.u8(0xff);  // an unterminated varint running to the end
  EXPECT_EQ(outcome(with_raw_root(w.bytes)), Outcome::error);
  ByteWriter long_string = prefix();
  long_string.bytes.resize(long_string.bytes.size() - 1);
  long_string.varint(UINT32_MAX);  // metadata of 4 GiB
  EXPECT_EQ(outcome(with_raw_root(long_string.bytes)), Outcome::error);
}

TEST_P(Corruption, ARangeStoredAfterTheLastTakesElevenBytes) {
  // Offset 0 bytes past the previous range's end (1 byte), size and raw size below 128 (1 byte each), u64
  // checksum.
  RootIndex r = root;
  const size_t before = serialize_root(r).size();
  const Range& last = r.pages.back();
  r.pages.push_back(Range{last.offset + last.size, 100, 120, 0x0123456789abcdefull});
  EXPECT_EQ(serialize_root(r).size() - before, 11u);
}

TEST_P(Corruption, ARepresentationWhoseGridStartsAtItsBoundsMinimumStoresNoOrigin) {
  // The kind byte's bit 7 stands for the grid origin's 12 bytes; either form parses back bit for bit.
  RootIndex r = root;
  Representation& rep = r.scene.representations[0];
  rep.grid.origin = rep.bounds.min;
  const std::vector<uint8_t> implied = serialize_root(r);
  EXPECT_EQ(parse_root(implied, "implied").scene.representations[0].grid.origin, rep.bounds.min);
  rep.grid.origin = rep.bounds.min - glm::vec3(0.25f, 0.0f, -0.5f);
  const std::vector<uint8_t> stored = serialize_root(r);
  EXPECT_EQ(stored.size() - implied.size(), 12u);
  EXPECT_EQ(parse_root(stored, "stored").scene.representations[0].grid.origin, rep.grid.origin);
}

TEST_P(Corruption, UnknownRepresentationKindBitsAreErrors) {
  RootIndex r = root;
  r.scene.representations[0].name = "kind probe";
  std::vector<uint8_t> raw = serialize_root(r);
  const std::string name = "kind probe";
  const auto at = std::search(raw.begin(), raw.end(), name.begin(), name.end());
  ASSERT_NE(at, raw.end());
  *(at - 2) |= 0x40;  // the kind byte, before the name's length
  std::string message;
  EXPECT_EQ(outcome(with_raw_root(raw), &message), Outcome::error);
  EXPECT_NE(message.find("representation kind"), std::string::npos) << message;
}

TEST_P(Corruption, HandWrittenRangesOutsideTheFileAreErrors) {
  for (const auto& [offset, size] :
       {std::pair<int64_t, uint64_t>{-1, 10}, {INT64_MAX, 10}, {5, UINT64_MAX}}) {
    ByteWriter w;
    w.u32(root.codec);
    w.u32(root.node_count);
    w.u64(0);
    w.string("");
    w.varint(1);  // one page
    w.svarint(offset), w.varint(size), w.varint(10), w.u64(0);
    std::string message;
    EXPECT_EQ(outcome(with_raw_root(w.bytes), &message), Outcome::error) << offset << " " << size;
    EXPECT_NE(message.find("range"), std::string::npos) << message;
  }
}

TEST_P(Corruption, CorruptedPagesReceivedFromElsewhereAreErrorsOrValidMeshes) {
  PackageReader reader(std::make_shared<MemorySource>(original));
  const std::vector<uint8_t> page = reader.read_page(0);
  std::vector<uint32_t> ids;
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    if (reader.node(id).page == 0) ids.push_back(id);
  }
  ASSERT_FALSE(ids.empty());
  // Stored bytes that fail their checksum are refused before zstd sees them.
  std::vector<uint8_t> stored(reader.root().pages[0].size);
  reader.source().read(reader.root().pages[0].offset, stored);
  stored[stored.size() / 2] ^= 1;
  EXPECT_THROW(reader.unpack_page(0, stored), Error);
  // Decoded page bytes (past the checksum) flipped everywhere: the codec's own checks hold, and an error
  // names the file, the node and its page.
  for (size_t at = 0; at < page.size(); ++at) {
    std::vector<uint8_t> bad = page;
    bad[at] ^= 0x5a;
    for (uint32_t id : ids) {
      try {
        DecodedNode d = reader.decode_node(id, bad);
        for (uint32_t i : d.mesh.indices) ASSERT_LT(i, d.mesh.vertex_count());
      } catch (const Error& e) {
        const std::string context = reader.source().name() + ": node " + std::to_string(id) + " (page 0)";
        ASSERT_EQ(std::string(e.what()).rfind(context, 0), 0u) << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace lodstream::test
