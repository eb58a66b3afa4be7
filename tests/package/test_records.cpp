// Records (package/records.hpp): a page group's clusters welded into one node of codec 3. Each cluster comes
// back exactly (its triangles, positions and attributes), a vertex that several clusters share decodes to the
// same bits in each, the reader decodes a record once for its clusters in any order, and corrupted record
// bytes or fields are errors, never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <numeric>
#include <random>

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/quantized_node.hpp"
#include "package/reader.hpp"
#include "package/records.hpp"
#include "package/traversal_codec.hpp"
#include "package/traversal_connectivity.hpp"
#include "package_fixture.hpp"
#include "support/run.hpp"
#include "support/shapes.hpp"

namespace lodstream::test {
namespace {

using namespace package;

// A triangle as its three corners' position bits, rotated to start at the smallest (the codec may rotate).
using Corners = std::array<std::array<uint32_t, 3>, 3>;
std::vector<Corners> triangles_of(const Mesh& m) {
  std::vector<Corners> out;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    Corners c;
    for (int k = 0; k < 3; ++k) std::memcpy(c[k].data(), &m.positions[m.indices[3 * t + k]], 12);
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

struct Record {
  PositionGrid grid;
  std::vector<Mesh> clusters;
  std::vector<std::vector<uint8_t>> locked;
  RecordMesh welded;
  std::vector<uint8_t> bytes;
};

// Six chunks of 40 triangles of a UV sphere (normals, UVs, seams), snapped to the grid so that shift 0
// decodes every position exactly.
Record sphere_record(uint32_t shift) {
  Record r;
  Mesh sphere = uv_sphere(1.0f, 16, 32);
  r.grid = PositionGrid::for_bounds(sphere.bounds(), 14);
  r.grid.snap(sphere);
  std::vector<std::vector<uint8_t>> locked;
  std::vector<Mesh> chunks = split_into_chunks(sphere, 40, locked);
  r.clusters.assign(chunks.begin(), chunks.begin() + 6);
  r.locked.assign(locked.begin(), locked.begin() + 6);
  std::vector<const Mesh*> meshes;
  std::vector<std::span<const uint8_t>> spans;
  for (size_t c = 0; c < r.clusters.size(); ++c)
    meshes.push_back(&r.clusters[c]), spans.push_back(r.locked[c]);
  r.welded = weld_record(meshes, spans);
  NodeGeometry g;
  g.mesh = &r.welded.mesh;
  g.locked = r.welded.locked;
  g.position_shift = shift;
  g.normal_bits = 12;
  g.cluster_triangles = r.welded.cluster_triangles;
  r.bytes = TraversalCodec().encode(g, r.grid);
  return r;
}

TEST(Records, WeldingStoresASharedVertexOnce) {
  const Record r = sphere_record(0);
  size_t separate = 0;
  for (const Mesh& m : r.clusters) separate += m.vertex_count();
  EXPECT_LT(r.welded.mesh.vertex_count(), separate);  // neighbouring chunks share their borders
  for (size_t c = 0; c < r.clusters.size(); ++c) {
    EXPECT_EQ(r.welded.cluster_triangles[c], r.clusters[c].triangle_count());
  }
}

TEST(Records, EachClusterComesBackExactlyAndSharedVerticesAreIdentical) {
  const Record r = sphere_record(0);
  const DecodedNode record = TraversalCodec().decode(r.bytes, r.grid, "record");
  ASSERT_EQ(record_clusters(record), r.clusters.size());
  EXPECT_EQ(record.mesh.vertex_count(), r.welded.mesh.vertex_count());
  // (position, UV) bits -> normal bits over every cluster: a shared vertex decodes alike in each.
  std::map<std::array<uint32_t, 5>, std::array<uint32_t, 3>> normal_of;
  size_t shared = 0;
  for (uint32_t c = 0; c < r.clusters.size(); ++c) {
    const DecodedNode d = extract_cluster(record, c, "record");
    EXPECT_EQ(d.mesh.triangle_count(), r.clusters[c].triangle_count()) << c;
    EXPECT_EQ(d.mesh.vertex_count(), r.clusters[c].vertex_count()) << c;  // no duplicates within a chunk
    EXPECT_EQ(triangles_of(d.mesh), triangles_of(r.clusters[c])) << c;    // positions exact at shift 0
    ASSERT_EQ(d.mesh.normals.size(), d.mesh.vertex_count());
    ASSERT_EQ(d.mesh.uvs.size(), d.mesh.vertex_count());
    for (size_t v = 0; v < d.mesh.vertex_count(); ++v) {
      std::array<uint32_t, 5> key;
      std::array<uint32_t, 3> normal;
      std::memcpy(key.data(), &d.mesh.positions[v], 12);
      std::memcpy(key.data() + 3, &d.mesh.uvs[v], 8);
      std::memcpy(normal.data(), &d.mesh.normals[v], 12);
      const auto [it, added] = normal_of.emplace(key, normal);
      shared += !added;
      EXPECT_EQ(it->second, normal) << "cluster " << c << " vertex " << v;
    }
  }
  EXPECT_GT(shared, 20u);  // the chunks' borders
}

// Extracting into one DecodedNode (its arrays sized without clearing: they shrink, or grow by copies that
// the extraction overwrites) gives each cluster as extracting it alone does, in any order, whatever the node
// held before.
TEST(Records, ExtractingIntoOneNodeMatchesExtractingAlone) {
  const Record r = sphere_record(0);
  const DecodedNode record = TraversalCodec().decode(r.bytes, r.grid, "record");
  const uint32_t C = record_clusters(record);
  ASSERT_GE(C, 4u);
  DecodedNode into;
  into.mesh.positions.assign(3 * record.mesh.vertex_count(), glm::vec3(7.0f));
  into.mesh.normals.assign(5, glm::vec3(-1.0f));
  into.mesh.indices.assign(9 * record.mesh.indices.size(), 5u);
  std::vector<uint32_t> order;  // 0, C-1, 1, C-2, ...: sizes up and down
  for (uint32_t lo = 0, hi = C - 1; lo <= hi; ++lo, --hi) {
    order.push_back(lo);
    if (hi != lo) order.push_back(hi);
  }
  for (int pass = 0; pass < 2; ++pass) {
    for (uint32_t c : order) {
      extract_cluster(record, c, "record", into);
      const DecodedNode alone = extract_cluster(record, c, "record");
      EXPECT_EQ(into.mesh.indices, alone.mesh.indices) << c;
      EXPECT_EQ(into.mesh.positions, alone.mesh.positions) << c;
      EXPECT_EQ(into.mesh.normals, alone.mesh.normals) << c;
      EXPECT_EQ(into.mesh.uvs, alone.mesh.uvs) << c;
      EXPECT_EQ(into.index_end, alone.index_end) << c;
      EXPECT_EQ(into.mesh.vertex_count(), r.clusters[c].vertex_count()) << c;
    }
    std::reverse(order.begin(), order.end());
  }
}

// Cluster `cluster` of `record` as records.hpp defines it, computed the plain way: its triangles in order,
// its vertices numbered in order of first use by them, each attribute copied.
DecodedNode reference_cluster(const DecodedNode& record, uint32_t cluster) {
  size_t first = 0;
  for (uint32_t c = 0; c < cluster; ++c) first += record.cluster_triangles[c];
  const Mesh& in = record.mesh;
  DecodedNode out;
  out.mesh.material = in.material;
  std::map<uint32_t, uint32_t> number;
  for (size_t i = 3 * first; i < 3 * (first + record.cluster_triangles[cluster]); ++i) {
    const uint32_t v = in.indices[i];
    const auto [it, added] = number.emplace(v, uint32_t(number.size()));
    out.mesh.indices.push_back(it->second);
    if (!added) continue;
    out.mesh.positions.push_back(in.positions[v]);
    if (in.has_normals()) out.mesh.normals.push_back(in.normals[v]);
    if (in.has_uvs()) out.mesh.uvs.push_back(in.uvs[v]);
    if (in.has_colors()) out.mesh.colors.push_back(in.colors[v]);
    if (!record.vertex_data.empty()) out.vertex_data.push_back(record.vertex_data[v]);
  }
  out.index_end = uint32_t(number.size());
  return out;
}

// Every field of `d` equals `expected`'s (`what` names the node in a failure).
void expect_same_node(const DecodedNode& d, const DecodedNode& expected, uint32_t what) {
  EXPECT_EQ(d.mesh.indices, expected.mesh.indices) << what;
  EXPECT_EQ(d.mesh.positions, expected.mesh.positions) << what;
  EXPECT_EQ(d.mesh.normals, expected.mesh.normals) << what;
  EXPECT_EQ(d.mesh.uvs, expected.mesh.uvs) << what;
  EXPECT_EQ(d.mesh.colors, expected.mesh.colors) << what;
  EXPECT_EQ(d.mesh.material, expected.mesh.material) << what;
  EXPECT_EQ(d.vertex_data, expected.vertex_data) << what;
  EXPECT_EQ(d.extra, expected.extra) << what;
  EXPECT_EQ(d.cluster_triangles, expected.cluster_triangles) << what;
  EXPECT_EQ(d.first_vertex, expected.first_vertex) << what;
  EXPECT_EQ(d.index_end, expected.index_end) << what;
}

// The form given each cluster's first triangle (cluster_firsts, as the reader keeps them) extracts what the
// form that sums the counts does; a first triangle that would take the cluster past the record's triangles
// is an error, not a read past its indices.
TEST(Records, ExtractingFromGivenFirstTrianglesMatchesSummingThem) {
  const Record r = sphere_record(0);
  const DecodedNode record = TraversalCodec().decode(r.bytes, r.grid, "record");
  const uint32_t C = record_clusters(record);
  ASSERT_GE(C, 4u);
  std::vector<size_t> firsts = {9, 9};  // overwritten
  cluster_firsts(record, firsts);
  ASSERT_EQ(firsts.size(), C);
  size_t first = 0;
  DecodedNode given;
  for (uint32_t c = 0; c < C; ++c) {
    EXPECT_EQ(firsts[c], first) << c;
    first += record.cluster_triangles[c];
    extract_cluster(record, c, firsts[c], "record", given);
    expect_same_node(given, extract_cluster(record, c, "record"), c);
  }
  EXPECT_EQ(first, record.mesh.triangle_count());
  const size_t past = record.mesh.triangle_count() - record.cluster_triangles[C - 1] + 1;
  EXPECT_THROW(extract_cluster(record, C - 1, past, "record", given), Error);
  EXPECT_THROW(extract_cluster(record, 0, SIZE_MAX, "record", given), Error);
  EXPECT_THROW(extract_cluster(record, C, 0, "record", given), Error);
  DecodedNode single = record;  // a node of one cluster: one first triangle, 0
  single.cluster_triangles.clear();
  cluster_firsts(single, firsts);
  EXPECT_EQ(firsts, std::vector<size_t>{0});
}

// extract_cluster numbers a cluster's vertices in order of first use and keeps its triangles' order, on
// decoded records (most triangles meet at most their last corner first) and on records of random triangles
// (any corner first met, corners repeated within a triangle, clusters leaving the last vertex out or not,
// with and without normals and the other attributes), extracted into one node in a mixed order.
TEST(Records, ExtractionNumbersVerticesInFirstUseOrder) {
  const Record r = sphere_record(0);
  const DecodedNode decoded = TraversalCodec().decode(r.bytes, r.grid, "record");
  DecodedNode into;
  for (uint32_t c = 0; c < record_clusters(decoded); ++c) {
    extract_cluster(decoded, c, "record", into);
    expect_same_node(into, reference_cluster(decoded, c), c);
  }
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const uint32_t V = 1 + rng() % 40, C = 2 + rng() % 6;
    DecodedNode record;
    record.mesh.material = trial % 3;
    for (uint32_t v = 0; v < V; ++v) {
      record.mesh.positions.push_back({float(v), float(trial), 1.0f});
      if (trial % 4 != 1) record.mesh.normals.push_back({0.0f, float(v), 0.5f});
      if (trial % 2 == 0) record.mesh.uvs.push_back({float(v), 0.25f});
      if (trial % 5 == 0) record.mesh.colors.push_back({float(v), 0.0f, 1.0f, 1.0f});
      if (trial % 3 == 0) record.vertex_data.push_back(7 * v);
    }
    // Small clusters drawing from a part of the pool: some use the last vertex, some do not.
    const uint32_t reach = trial % 2 ? V : std::max(1u, V - 1);
    for (uint32_t c = 0; c < C; ++c) {
      const uint32_t triangles = 1 + rng() % 12;
      record.cluster_triangles.push_back(triangles);
      for (uint32_t k = 0; k < 3 * triangles; ++k) record.mesh.indices.push_back(rng() % reach);
    }
    std::vector<uint32_t> order(C);
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), rng);
    for (uint32_t c : order) {
      extract_cluster(record, c, "random", into);
      expect_same_node(into, reference_cluster(record, c), c);
    }
  }
}

TEST(Records, FreeVerticesKeepTheShiftsBoundAndLockedOnesStayExact) {
  const uint32_t shift = 3;
  const Record r = sphere_record(shift);
  const DecodedNode record = TraversalCodec().decode(r.bytes, r.grid, "record");
  // Every decoded position lies within sqrt(3)/2 (2^k + 1) steps of an original vertex of its cluster, and
  // each locked original is decoded exactly in its cluster.
  const float bound = 0.5f * std::sqrt(3.0f) * float((1 << shift) + 1) * r.grid.step * 1.001f;
  for (uint32_t c = 0; c < r.clusters.size(); ++c) {
    const DecodedNode d = extract_cluster(record, c, "record");
    for (const glm::vec3& p : d.mesh.positions) {
      float nearest = INFINITY;
      for (const glm::vec3& q : r.clusters[c].positions) nearest = std::min(nearest, glm::length(p - q));
      EXPECT_LE(nearest, bound);
    }
    for (size_t v = 0; v < r.clusters[c].vertex_count(); ++v) {
      if (!r.locked[c][v]) continue;
      EXPECT_NE(std::find(d.mesh.positions.begin(), d.mesh.positions.end(), r.clusters[c].positions[v]),
                d.mesh.positions.end())
          << "locked vertex " << v << " of cluster " << c;
    }
  }
}

TEST(Records, InvalidClusterCountsAndOtherCodecsAreRefused) {
  Record r = sphere_record(0);
  NodeGeometry g;
  g.mesh = &r.welded.mesh;
  std::vector<uint32_t> counts = r.welded.cluster_triangles;
  g.cluster_triangles = counts;
  EXPECT_THROW(MeshoptCodec().encode(g, r.grid), Error);
  EXPECT_THROW(PredictiveCodec().encode(g, r.grid), Error);
  counts[0] += 1;  // one more than the mesh holds
  EXPECT_THROW(TraversalCodec().encode(g, r.grid), Error);
  counts[0] -= 1, counts.push_back(0);  // an empty cluster
  g.cluster_triangles = counts;         // push_back may have moved them
  EXPECT_THROW(TraversalCodec().encode(g, r.grid), Error);
  std::vector<uint32_t> many(kMaxRecordClusters + 1, 1);  // more clusters than a record may hold
  Mesh strip;
  for (uint32_t t = 0; t < many.size(); ++t) {
    strip.positions.push_back({float(t), 0.0f, 0.0f});
    strip.indices.insert(strip.indices.end(), {0, t + 1, t + 2});
  }
  strip.positions.resize(many.size() + 2, glm::vec3(1.0f));
  NodeGeometry h;
  h.mesh = &strip;
  h.cluster_triangles = many;
  EXPECT_THROW(TraversalCodec().encode(h, PositionGrid::for_bounds(strip.bounds())), Error);
  const DecodedNode record = TraversalCodec().decode(r.bytes, r.grid, "record");
  try {
    extract_cluster(record, uint32_t(r.clusters.size()), "node 7");
    ADD_FAILURE() << "a cluster past the record's was extracted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("node 7: cluster 6 out of range", 0), 0u) << e.what();
  }
}

TEST(Records, TheDecoderPlacesEachClusterInItsRangeAndRefusesOtherCounts) {
  // The decoder writes each triangle straight into its cluster's range: the encoder's clustered indices
  // come back exactly, and counts that differ from the stream's (other splits of T, or not adding up to T)
  // are errors, never a write outside `indices`.
  const Record r = sphere_record(0);
  const RecordMesh& w = r.welded;
  const uint32_t T = uint32_t(w.mesh.triangle_count()), V = uint32_t(w.mesh.vertex_count());
  const TraversalCode code = encode_traversal(w.mesh.indices, V, w.cluster_triangles);
  auto decode = [&](std::span<const uint32_t> counts) {
    std::vector<uint32_t> indices(3 * size_t(T) + 3, UINT32_MAX), predictors(3 * (size_t(V) + 1));
    decode_traversal(code.symbols, code.references, T, V, indices.data(), predictors.data(), "node 5",
                     counts);
    EXPECT_EQ(indices.back(), UINT32_MAX) << "written past the triangles";
    indices.resize(3 * size_t(T));
    return indices;
  };
  EXPECT_EQ(decode(w.cluster_triangles), code.indices);
  auto refused = [&](std::vector<uint32_t> counts) {
    try {
      decode(counts);
      ADD_FAILURE() << "counts " << counts[0] << ", " << counts[1] << "... were accepted";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("node 5: corrupted connectivity (triangles per cluster", 0), 0u)
          << e.what();
    }
  };
  std::vector<uint32_t> moved = w.cluster_triangles;  // one triangle moved from cluster 1 to cluster 0
  moved[0] += 1, moved[1] -= 1;
  refused(moved);
  std::vector<uint32_t> more = w.cluster_triangles;  // adding up to T + 1
  more.back() += 1;
  refused(more);
}

TEST(Records, CorruptedRecordsAreErrorsOrValidRecords) {
  // Every byte of the header region set to several values, and random bytes flipped anywhere: decoding is
  // an Error, or a record whose clusters add up to its triangles and extract without fault.
  const Record r = sphere_record(2);
  auto check = [&](const std::vector<uint8_t>& bytes) {
    try {
      const DecodedNode d = TraversalCodec().decode(bytes, r.grid, "fuzz");
      size_t sum = 0;
      for (uint32_t t : d.cluster_triangles) sum += t;
      if (!d.cluster_triangles.empty()) {
        EXPECT_EQ(sum, d.mesh.triangle_count());
      }
      for (uint32_t c = 0; c < record_clusters(d); ++c) {
        const DecodedNode cluster = extract_cluster(d, c, "fuzz");
        for (uint32_t i : cluster.mesh.indices) ASSERT_LT(i, cluster.mesh.vertex_count());
      }
    } catch (const Error&) {
    }
  };
  for (size_t at = 0; at < std::min<size_t>(48, r.bytes.size()); ++at)
    for (uint8_t value : {0, 1, 2, 31, 32, 64, 127, 255}) {
      std::vector<uint8_t> bytes = r.bytes;
      bytes[at] = value;
      check(bytes);
    }
  std::mt19937 rng(3);
  std::uniform_int_distribution<size_t> position(0, r.bytes.size() - 1);
  for (int i = 0; i < 2000; ++i) {
    std::vector<uint8_t> bytes = r.bytes;
    bytes[position(rng)] ^= uint8_t(1 + rng() % 255);
    check(bytes);
  }
}

TEST(Records, TheReaderGivesEachClusterInAnyOrder) {
  // The test package's sphere page groups are records (codec 3): its clusters decode to the same meshes in
  // id order (one decode per record) and in reverse order (a decode per cluster).
  const auto file = temp_dir() / "records.lods";
  write_test_package(file, TraversalCodec::kId);
  PackageReader forward = PackageReader::open(file), backward = PackageReader::open(file);
  size_t in_records = 0;
  std::vector<DecodedNode> first(forward.node_count());
  for (uint32_t id = 0; id < forward.node_count(); ++id) {
    first[id] = forward.load_node(id);
    in_records += forward.node(id).cluster > 0;
  }
  EXPECT_GT(in_records, 4u);
  for (uint32_t id = backward.node_count(); id-- > 0;) {
    const DecodedNode d = backward.load_node(id);
    EXPECT_EQ(d.mesh.indices, first[id].mesh.indices) << id;
    EXPECT_EQ(d.mesh.positions, first[id].mesh.positions) << id;
    EXPECT_EQ(d.mesh.normals, first[id].mesh.normals) << id;
    EXPECT_EQ(d.mesh.uvs, first[id].mesh.uvs) << id;
  }
}

// Decoding every node into one DecodedNode (the bench's and a recycling client's path) gives each node as
// decoding it alone does, whatever the node held before (fields a node lacks are cleared), and reuses its
// buffers: after one pass over the nodes, the arrays are never reallocated.
TEST(Records, DecodingIntoOneNodeReusesItsBuffers) {
  const auto file = temp_dir() / "records_into.lods";
  write_test_package(file, TraversalCodec::kId);
  PackageReader reader = PackageReader::open(file), alone = PackageReader::open(file);
  DecodedNode into;
  for (uint32_t id = 0; id < reader.node_count(); ++id)
    reader.decode_node(id, reader.read_page(reader.node(id).page), into);
  const uint32_t* indices = into.mesh.indices.data();
  const glm::vec3* positions = into.mesh.positions.data();
  into.mesh.colors.assign(3, glm::vec4(1.0f));  // what a recycled node may hold and these nodes do not
  into.vertex_data.assign(3, 7u), into.extra.assign(2, 1), into.cluster_triangles.assign(2, 5u);
  into.first_vertex = 9;
  size_t in_records = 0;
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    reader.decode_node(id, reader.read_page(reader.node(id).page), into);
    const DecodedNode d = alone.load_node(id);
    in_records += reader.node(id).cluster > 0;
    expect_same_node(into, d, id);
    EXPECT_EQ(into.mesh.indices.data(), indices) << id;
    EXPECT_EQ(into.mesh.positions.data(), positions) << id;
  }
  EXPECT_GT(in_records, 4u);
}

}  // namespace
}  // namespace lodstream::test
