// account_sizes (package/size_account.hpp): the parts it reports add up to the nodes' bytes, and it tells
// normals and other attributes, and codec 3's traversal symbols and references, apart for the codecs that
// store them apart.
#include <gtest/gtest.h>

#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/reader.hpp"
#include "package/size_account.hpp"
#include "package/traversal_codec.hpp"
#include "package_fixture.hpp"
#include "support/run.hpp"

namespace lodstream::test {
namespace {

using namespace package;

class SizeAccount : public ::testing::TestWithParam<uint32_t> {};

INSTANTIATE_TEST_SUITE_P(Codecs, SizeAccount,
                         ::testing::Values(MeshoptCodec::kId, PredictiveCodec::kId, TraversalCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(SizeAccount, PartsAddUpToTheNodesAndPagesToTheFile) {
  const auto file = temp_dir() / "account.lods";
  const TestPackage t = write_test_package(file, GetParam());
  PackageReader reader = PackageReader::open(file);
  const std::vector<LevelAccount> account = account_sizes(reader);

  // Per level from the records; a record of several clusters (codec 3: the sphere's page groups) counts its
  // bytes and its stored vertices (as decoded) once, at the level of its first cluster.
  std::map<uint32_t, LevelAccount> expected;
  size_t shared = 0;
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const NodeRecord& n = reader.node(id);
    LevelAccount& e = expected[n.level];
    ++e.nodes, e.triangles += n.triangles;
    if (n.cluster > 0) {
      ++shared;
      continue;
    }
    e.parts[0].raw += n.size;
    const std::vector<uint8_t> page = reader.read_page(n.page);
    e.vertices += reader.codec()
                      .decode(reader.node_bytes(id, page),
                              reader.scene().representations[n.representation].grid, "node")
                      .mesh.vertex_count();
  }
  EXPECT_EQ(shared > 0, GetParam() == TraversalCodec::kId);
  ASSERT_EQ(account.size(), expected.size());
  double page_bytes = 0.0, stored = 0.0;
  for (const Range& p : reader.root().pages) stored += p.size;
  for (const LevelAccount& a : account) {
    const LevelAccount& e = expected.at(a.level);
    EXPECT_EQ(a.nodes, e.nodes);
    EXPECT_EQ(a.triangles, e.triangles);
    EXPECT_EQ(a.vertices, e.vertices);
    uint64_t raw = 0;
    for (const PartBytes& b : a.parts) {
      raw += b.raw;
      EXPECT_EQ(b.raw == 0, b.compressed == 0);  // a part compresses to something exactly when it exists
    }
    EXPECT_EQ(raw, e.parts[0].raw) << "level " << a.level;
    EXPECT_GT(a.parts[uint32_t(NodePart::header)].raw, 0u);
    EXPECT_GT(a.parts[uint32_t(NodePart::positions)].raw, 0u);
    EXPECT_GT(a.parts[uint32_t(NodePart::connectivity)].raw, 0u);
    // Codec 3's traversal references (three at least per piece start) apart from its symbols; the other
    // codecs' connectivity is one stream.
    EXPECT_EQ(a.parts[uint32_t(NodePart::references)].raw > 0, GetParam() == TraversalCodec::kId);
    page_bytes += a.page_bytes;
  }
  EXPECT_NEAR(page_bytes, stored, 1e-6 * stored);  // every data page is shared out among the levels

  // The sphere has normals and UVs: codecs 2 and 3 store them apart from the positions, codec 1 interleaves.
  uint64_t normals = 0, attributes = 0;
  for (const LevelAccount& a : account)
    normals += a.parts[uint32_t(NodePart::normals)].raw,
        attributes += a.parts[uint32_t(NodePart::attributes)].raw;
  if (GetParam() == MeshoptCodec::kId) {
    EXPECT_EQ(normals, 0u);
    EXPECT_EQ(attributes, 0u);
  } else {
    EXPECT_GT(normals, 0u);
    EXPECT_GT(attributes, 0u);
  }
}

}  // namespace
}  // namespace lodstream::test
