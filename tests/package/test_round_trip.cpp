// Round trip of a multi-object package: scene, records, geometry within quantization error, locked vertices
// bit-identical across nodes, pages and index pages on demand, atomic writes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <tuple>

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/pair_rounding.hpp"
#include "package/predictive_codec.hpp"
#include "package/reader.hpp"
#include "package_fixture.hpp"
#include "support/run.hpp"

namespace lodstream::test {
namespace {

using namespace package;

std::vector<uint8_t> file_bytes(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// For each decoded vertex, the original vertex it came from (closest in position, then in attributes).
std::vector<uint32_t> match_vertices(const Mesh& original, const Mesh& decoded, float step) {
  std::vector<uint32_t> match(decoded.vertex_count());
  for (size_t d = 0; d < decoded.vertex_count(); ++d) {
    float best = INFINITY;
    for (size_t o = 0; o < original.vertex_count(); ++o) {
      glm::vec3 dp = (decoded.positions[d] - original.positions[o]) / step;
      float cost = glm::dot(dp, dp);
      if (original.has_normals())
        cost += glm::dot(decoded.normals[d] - original.normals[o], decoded.normals[d] - original.normals[o]);
      if (original.has_uvs())
        cost += 1e4f * glm::dot(decoded.uvs[d] - original.uvs[o], decoded.uvs[d] - original.uvs[o]);
      if (original.has_colors())
        cost += glm::dot(decoded.colors[d] - original.colors[o], decoded.colors[d] - original.colors[o]);
      if (cost < best) best = cost, match[d] = uint32_t(o);
    }
  }
  return match;
}

// Triangles as sorted list of index triples, each rotated so its smallest index comes first (keeps winding).
std::vector<std::array<uint32_t, 3>> canonical_triangles(const std::vector<uint32_t>& indices) {
  std::vector<std::array<uint32_t, 3>> tris;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    std::array<uint32_t, 3> a{indices[t], indices[t + 1], indices[t + 2]};
    std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
    tris.push_back(a);
  }
  std::sort(tris.begin(), tris.end());
  return tris;
}

class RoundTrip : public ::testing::TestWithParam<uint32_t> {
 protected:
  void SetUp() override {
    file = temp_dir() / "scene.lods";
    t = write_test_package(file, GetParam());
  }
  std::filesystem::path file;
  TestPackage t;
};

INSTANTIATE_TEST_SUITE_P(Codecs, RoundTrip, ::testing::Values(MeshoptCodec::kId, PredictiveCodec::kId),
                         [](const auto& info) { return "codec" + std::to_string(info.param); });

TEST_P(RoundTrip, SceneAndTablesSurvive) {
  PackageReader reader = PackageReader::open(file);
  EXPECT_EQ(reader.header().file_size, std::filesystem::file_size(file));
  EXPECT_EQ(reader.header().content_hash, t.written.content_hash);
  EXPECT_NO_THROW(reader.verify());
  const PackageScene& s = reader.scene();
  EXPECT_EQ(s.input_triangles, t.scene.input_triangles);
  EXPECT_EQ(s.metadata, t.scene.metadata);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].material.name, "skin");
  EXPECT_EQ(s.materials[0].material.base_color_texture, "textures/skin.png");
  EXPECT_EQ(s.materials[0].texture_blob, kNone);
  EXPECT_EQ(s.materials[1].material.base_color, t.scene.materials[1].material.base_color);
  ASSERT_EQ(s.materials[1].texture_blob, 0u);
  EXPECT_EQ(reader.read_blob(0), (std::vector<uint8_t>{0x89, 'P', 'N', 'G', 1, 2, 3, 4, 5}));
  ASSERT_EQ(s.objects.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(s.objects[i].name, t.scene.objects[i].name);
    EXPECT_EQ(s.objects[i].transform, t.scene.objects[i].transform);
    EXPECT_EQ(s.objects[i].representation, t.scene.objects[i].representation);
  }
  EXPECT_EQ(s.objects[0].representation, s.objects[1].representation);  // instances share one
  ASSERT_EQ(s.representations.size(), 2u);
  for (size_t r = 0; r < 2; ++r) {
    EXPECT_EQ(s.representations[r].kind, t.scene.representations[r].kind);
    EXPECT_EQ(s.representations[r].name, t.scene.representations[r].name);
    EXPECT_EQ(s.representations[r].grid.origin, t.scene.representations[r].grid.origin);
    EXPECT_EQ(s.representations[r].grid.step, t.scene.representations[r].grid.step);
    EXPECT_EQ(s.representations[r].bounds.max, t.scene.representations[r].bounds.max);
    EXPECT_EQ(s.representations[r].roots, t.scene.representations[r].roots);
  }
  EXPECT_GT(reader.root().pages.size(), 3u);
  EXPECT_GT(reader.root().index_pages.size(), 2u);
  EXPECT_EQ(t.written.pages, reader.root().pages.size());
}

TEST_P(RoundTrip, RecordsLoadOnDemand) {
  PackageReader reader = PackageReader::open(file);
  ASSERT_EQ(reader.node_count(), t.records.size());
  EXPECT_TRUE(reader.has_node(0));
  const uint32_t last = reader.node_count() - 1;
  EXPECT_FALSE(reader.has_node(last));
  EXPECT_NE(reader.index_page_of(last), kNone);
  // The writer stores the pairs rounded up (pair_rounding.hpp).
  std::vector<NodeRecord> rounded = t.records;
  round_pairs(rounded);
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const NodeRecord& n = reader.node(id);
    const NodeRecord& e = rounded[id];
    EXPECT_EQ(n.kind, e.kind);
    EXPECT_EQ(n.representation, e.representation);
    EXPECT_EQ(n.material, e.material);
    EXPECT_EQ(n.level, e.level);
    EXPECT_EQ(n.triangles, e.triangles);
    EXPECT_EQ(n.error, e.error);
    EXPECT_EQ(n.parent_error, e.parent_error);
    EXPECT_EQ(n.sphere.center, e.sphere.center);
    EXPECT_EQ(n.sphere.radius, e.sphere.radius);
    EXPECT_EQ(n.parent_sphere.center, e.parent_sphere.center);
    EXPECT_EQ(n.parent_sphere.radius, e.parent_sphere.radius);
    EXPECT_GE(n.error, t.records[id].error);
    EXPECT_TRUE(sphere_contains(n.sphere, t.records[id].sphere, 0.0));
    EXPECT_EQ(n.children, e.children);
    EXPECT_EQ(n.parents, e.parents);
    EXPECT_EQ(n.objects, e.objects);
    EXPECT_LE(n.offset + n.size, reader.root().pages[n.page].raw_size);
  }
  EXPECT_TRUE(reader.has_node(last));
  EXPECT_THROW(reader.node(reader.node_count()), Error);
}

TEST_P(RoundTrip, GroupsStayInOnePageAndPagesStayNearTheTarget) {
  PackageReader reader = PackageReader::open(file);
  // The fixture closes a group after every third node of a representation; each group fits in a page.
  for (uint32_t id = 0; id + 2 < reader.node_count(); ++id) {
    if (id % 3 == 0 && t.records[id].representation == t.records[id + 2].representation && id + 2 < 9) {
      EXPECT_EQ(reader.node(id).page, reader.node(id + 2).page) << id;
    }
  }
  for (const Range& p : reader.root().pages) EXPECT_LE(p.raw_size, t.page_bytes);
}

TEST_P(RoundTrip, GeometrySurvivesWithinQuantizationError) {
  PackageReader reader = PackageReader::open(file);
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const Mesh& original = t.meshes[id];
    DecodedNode d = reader.load_node(id);
    const PositionGrid& grid = reader.scene().representations[t.records[id].representation].grid;
    ASSERT_EQ(d.mesh.vertex_count(), original.vertex_count());
    ASSERT_EQ(d.mesh.triangle_count(), original.triangle_count());
    EXPECT_EQ(d.mesh.material, original.material);
    EXPECT_EQ(d.mesh.has_normals(), original.has_normals());
    EXPECT_EQ(d.mesh.has_uvs(), original.has_uvs());
    EXPECT_EQ(d.mesh.has_colors(), original.has_colors());
    std::vector<uint32_t> match = match_vertices(original, d.mesh, grid.step);
    const float coarse = std::ldexp(1.0f, int(t.shifts[id]));
    for (size_t v = 0; v < match.size(); ++v) {
      const uint32_t o = match[v];
      // Per axis: step/2 on the finest grid, plus 2^k * step / 2 for a free vertex rounded to a coarser one.
      const float bound = grid.step * (t.locked[id][o] ? 0.5f : 0.5f + 0.5f * coarse) * 1.01f;
      for (int a = 0; a < 3; ++a)
        EXPECT_LE(std::abs(d.mesh.positions[v][a] - original.positions[o][a]), bound);
      if (original.has_normals()) {
        // 12-bit octahedral: worst angular error about 2^(2-12) rad.
        EXPECT_GT(glm::dot(d.mesh.normals[v], glm::normalize(original.normals[o])), std::cos(0.001f));
        EXPECT_NEAR(glm::length(d.mesh.normals[v]), 1.0f, 1e-5f);
      }
      if (original.has_uvs()) {
        for (int a = 0; a < 2; ++a)
          EXPECT_NEAR(d.mesh.uvs[v][a], original.uvs[o][a], 1.0f / 65535.0f + 1e-6f);
      }
      if (original.has_colors()) {
        for (int a = 0; a < 4; ++a)
          EXPECT_NEAR(d.mesh.colors[v][a], original.colors[o][a], 0.5f / 255.0f + 1e-6f);
      }
    }
    std::vector<uint32_t> mapped(d.mesh.indices.size());
    for (size_t i = 0; i < mapped.size(); ++i) mapped[i] = match[d.mesh.indices[i]];
    EXPECT_EQ(canonical_triangles(mapped), canonical_triangles(original.indices)) << "node " << id;
  }
}

TEST_P(RoundTrip, LockedVerticesDecodeBitIdenticalAcrossNodes) {
  PackageReader reader = PackageReader::open(file);
  using Key = std::tuple<uint32_t, float, float, float>;  // representation, original position
  std::map<Key, std::vector<glm::vec3>> decoded_at;
  size_t shared = 0, across_shifts = 0;
  std::map<Key, std::set<uint32_t>> shifts_at;
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const Mesh& original = t.meshes[id];
    DecodedNode d = reader.load_node(id);
    const uint32_t r = t.records[id].representation;
    std::vector<uint32_t> match =
        match_vertices(original, d.mesh, reader.scene().representations[r].grid.step);
    for (size_t v = 0; v < match.size(); ++v) {
      if (!t.locked[id][match[v]]) continue;
      const glm::vec3& p = original.positions[match[v]];
      decoded_at[{r, p.x, p.y, p.z}].push_back(d.mesh.positions[v]);
      shifts_at[{r, p.x, p.y, p.z}].insert(t.shifts[id]);
    }
  }
  for (const auto& [key, positions] : decoded_at) {
    if (positions.size() < 2) continue;
    ++shared;
    across_shifts += shifts_at[key].size() > 1;
    for (const glm::vec3& p : positions) {
      EXPECT_EQ(std::memcmp(&p, &positions[0], sizeof p), 0)
          << "locked vertex decodes differently in two nodes";
    }
  }
  EXPECT_GT(shared, 50u);
  EXPECT_GT(across_shifts, 20u);  // shared between nodes at different precisions
}

TEST_P(RoundTrip, VerifyContentsDecodesEverything) {
  PackageReader reader = PackageReader::open(file);
  EXPECT_NO_THROW(reader.verify_contents());
}

TEST_P(RoundTrip, WritingTwiceGivesTheSameBytes) {
  std::filesystem::path again = temp_dir() / "again.lods";
  TestPackage t2 = write_test_package(again, GetParam());
  EXPECT_EQ(t2.written.content_hash, t.written.content_hash);
  EXPECT_EQ(file_bytes(again), file_bytes(file));
}

TEST(Writer, AnUnfinishedWriteLeavesNoFile) {
  std::filesystem::path dir = temp_dir();
  {
    PackageWriter w(dir / "broken.lods");
    const std::vector<uint8_t> bytes(100, 7);
    w.add_node(0, bytes);
    w.end_group();
    EXPECT_FALSE(std::filesystem::exists(dir / "broken.lods"));
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

// Pages are compressed as tasks while nodes are still added (writer.hpp): many more pages than are queued at
// once come back in page order, each node in its own page, and a writer dropped with pages in flight leaves
// no file.
TEST(Writer, PagesCompressedWhileAddingAreWrittenInPageOrder) {
  const std::filesystem::path dir = temp_dir();
  PackageScene scene;
  scene.materials.resize(1);
  scene.representations.resize(1);
  WriterOptions options;
  options.page_bytes = 1024;
  constexpr uint32_t kNodes = 300;  // one page each
  auto bytes_of = [](uint32_t id) {
    std::vector<uint8_t> b(1000);
    for (size_t i = 0; i < b.size(); ++i) b[i] = uint8_t(id * 131 + i * (id % 7 + 1));
    return b;
  };
  {
    PackageWriter w(dir / "many.lods", options);
    for (uint32_t id = 0; id < kNodes; ++id) w.add_node(id, bytes_of(id)), w.end_group();
    EXPECT_EQ(w.finish(scene, std::vector<NodeRecord>(kNodes), 1).pages, kNodes);
  }
  PackageReader reader = PackageReader::open(dir / "many.lods");
  for (uint32_t id = 0; id < kNodes; ++id) {
    ASSERT_EQ(reader.node(id).page, id);
    const std::vector<uint8_t> page = reader.read_page(id);
    const std::span<const uint8_t> bytes = reader.node_bytes(id, page);
    EXPECT_EQ(std::vector<uint8_t>(bytes.begin(), bytes.end()), bytes_of(id)) << id;
  }
  {
    PackageWriter w(dir / "dropped.lods", options);
    for (uint32_t id = 0; id < kNodes; ++id) w.add_node(id, bytes_of(id)), w.end_group();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "dropped.lods"));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);  // many.lods alone
}

TEST(Writer, RejectsInconsistentNodesAndLeavesNoFile) {
  std::filesystem::path dir = temp_dir();
  PackageScene scene;
  scene.materials.resize(1);
  scene.representations.resize(1);
  const std::vector<uint8_t> bytes(10, 1);
  {
    PackageWriter w(dir / "a.lods");
    w.add_node(0, bytes);
    EXPECT_THROW(w.add_node(0, bytes), Error);
  }
  {
    PackageWriter w(dir / "b.lods");
    w.add_node(1, bytes);
    EXPECT_THROW(w.finish(scene, std::vector<NodeRecord>(2), 0), Error);  // node 0 has no bytes
  }
  {
    PackageWriter w(dir / "c.lods");
    w.add_node(0, bytes);
    std::vector<NodeRecord> nodes(1);
    nodes[0].children = {5};  // no such node
    EXPECT_THROW(w.finish(scene, nodes, 1), Error);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace lodstream::test
