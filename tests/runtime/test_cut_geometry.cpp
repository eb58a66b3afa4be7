#include <gtest/gtest.h>

#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <iterator>
#include <map>
#include <set>
#include <thread>

#include "core/error.hpp"
#include "core/image.hpp"
#include "package/reader.hpp"
#include "package/records.hpp"
#include "package/writer.hpp"
#include "runtime/cut_geometry.hpp"
#include "runtime/package_nodes.hpp"
#include "support/run.hpp"
#include "support/synthetic_dag.hpp"

using namespace lodstream;
using namespace lodstream::runtime;

namespace {

// A strip of `quads` quads covering [x0, x1] x [-0.25, 0.25] at z = 0.
Mesh strip(double x0, double x1, int quads) {
  Mesh m;
  for (int i = 0; i <= quads; ++i) {
    const float x = float(x0 + (x1 - x0) * i / quads);
    m.positions.push_back({x, -0.25f, 0.0f});
    m.positions.push_back({x, 0.25f, 0.0f});
  }
  for (uint32_t i = 0; i < uint32_t(quads); ++i) {
    const uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
    m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
  }
  return m;
}

// The synthetic DAG with real geometry: node i is a strip over its interval with (i % 3) + 1 quads per unit,
// in two objects (the second shifted 20 units along x), materials 0 and 1 on alternate nodes.
struct GeometryPackage {
  test::SyntheticDag dag = test::SyntheticDag::make();
  std::filesystem::path file = test::temp_dir() / "strips.lods";
  std::vector<glm::mat4> transforms{glm::mat4(1.0f),
                                    glm::translate(glm::mat4(1.0f), glm::vec3(20.0f, 0.0f, 0.0f))};

  // `blue_texture`: the blue material's texture embedded (a 3 x 2 PNG, blob 0) instead of referenced by path.
  // `records`: leaves 2k and 2k + 1 stored as one record (package/records.hpp), welded where they meet.
  explicit GeometryPackage(bool blue_texture = false, bool records = false) {
    package::PackageScene scene = dag.scene(transforms);
    Material red, blue;
    red.base_color = {1.0f, 0.0f, 0.0f, 1.0f};
    blue.base_color = {0.0f, 0.0f, 1.0f, 1.0f};
    blue.base_color_texture = "textures/blue.png";
    scene.materials = {{red, package::kNone}, {blue, package::kNone}};
    scene.representations[0].grid = package::PositionGrid::for_bounds(scene.representations[0].bounds);
    package::WriterOptions options;
    options.page_bytes = 1024;
    options.nodes_per_index_page = 8;
    package::PackageWriter writer(file, options);
    if (blue_texture) {
      const auto png = test::temp_dir() / "blue.png";
      save_png(Image(3, 2), png);
      std::ifstream in(png, std::ios::binary);
      scene.materials[1].texture_blob =
          writer.add_blob(std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {}));
    }
    std::vector<Mesh> meshes;
    for (uint32_t i = 0; i < dag.records.size(); ++i) {
      const auto [x0, x1] = dag.intervals[i];
      meshes.push_back(strip(x0, x1, int(x1 - x0) * int(i % 3 + 1)));
      dag.records[i].triangles = uint32_t(meshes[i].triangle_count());
      dag.records[i].material = i % 2;
    }
    const package::PositionGrid& grid = scene.representations[0].grid;
    for (uint32_t i = 0; i < dag.records.size(); ++i) {
      package::NodeGeometry geometry;
      if (records && dag.records[i].level == 0) {
        const Mesh* pair[2] = {&meshes[i], &meshes[i + 1]};
        const package::RecordMesh record = package::weld_record(pair, {});
        geometry.mesh = &record.mesh;
        geometry.cluster_triangles = record.cluster_triangles;
        const uint32_t ids[2] = {i, i + 1};
        writer.add_record(ids, package::default_node_codec().encode(geometry, grid));
        ++i;
      } else {
        geometry.mesh = &meshes[i];
        writer.add_node(i, package::default_node_codec().encode(geometry, grid));
      }
      writer.end_group();
    }
    writer.finish(scene, dag.records, 4);
  }
};

View view_of(glm::vec3 eye, glm::vec3 target) {
  Camera c;
  c.eye = eye;
  c.target = target;
  return View::of(c);
}

std::set<uint32_t> distinct_nodes(const Cut& cut) {
  std::set<uint32_t> s;
  for (const auto& d : cut.drawn) s.insert(d.node);
  return s;
}

}  // namespace

// The drawn nodes decode to their own geometry under their object's transform, each node once however many
// objects draw it; a frame decodes only what is new to it.
TEST(CutGeometry, DecodesTheDrawnNodesOnceAndPlacesThemByObject) {
  GeometryPackage p;
  package::PackageReader reader = package::PackageReader::open(p.file);
  ReaderNodes all(reader);
  CutGeometry geometry(reader, "/packages");

  const View far = view_of({8.0f, 2.0f, 60.0f}, {18.0f, 0.0f, 0.0f});
  const Cut coarse = select_cut(reader.scene(), all, far, {2.0});
  ASSERT_EQ(coarse.objects.size(), 2u);
  ASSERT_FALSE(coarse.drawn.empty());
  EXPECT_EQ(geometry.update(coarse, pages_from_reader(reader)), distinct_nodes(coarse).size());
  ASSERT_EQ(geometry.items().size(), coarse.drawn.size());
  uint64_t triangles = 0;
  for (size_t i = 0; i < coarse.drawn.size(); ++i) {
    const CutItem& item = geometry.items()[i];
    const uint32_t id = coarse.drawn[i].node;
    EXPECT_EQ(item.node, id);
    EXPECT_EQ(item.object, coarse.drawn[i].object);
    EXPECT_EQ(item.transform, p.transforms[item.object]);
    ASSERT_NE(item.mesh, nullptr);
    EXPECT_EQ(item.mesh->triangle_count(), p.dag.records[id].triangles);
    EXPECT_EQ(item.triangles.triangles, p.dag.records[id].triangles);
    EXPECT_EQ(item.material, id % 2);
    const Bounds b = item.mesh->bounds();
    EXPECT_NEAR(b.min.x, p.dag.intervals[id].first, 1e-2);
    EXPECT_NEAR(b.max.x, p.dag.intervals[id].second, 1e-2);
    triangles += item.mesh->triangle_count();
  }
  EXPECT_EQ(geometry.triangles(), triangles);
  EXPECT_EQ(geometry.update(coarse, pages_from_reader(reader)), 0u);  // nothing new

  const View near = view_of({-1.0f, 0.5f, 1.0f}, {8.0f, 0.0f, 0.0f});
  const Cut fine = select_cut(reader.scene(), all, near, {0.5});
  size_t fresh = 0;
  for (uint32_t id : distinct_nodes(fine)) fresh += !distinct_nodes(coarse).count(id);
  ASSERT_GT(fresh, 0u);
  EXPECT_EQ(geometry.update(fine, pages_from_reader(reader)), fresh);

  // Materials resolved against the package's folder.
  ASSERT_EQ(geometry.materials().size(), 2u);
  EXPECT_EQ(geometry.materials()[1].base_color_texture, "/packages/textures/blue.png");
  EXPECT_EQ(geometry.materials()[0].base_color, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
}

// The triangles of item `item` (its range of its mesh) as corner positions.
std::vector<glm::vec3> corners(const CutItem& item) {
  std::vector<glm::vec3> out;
  const uint32_t* f = item.mesh->indices.data() + 3 * size_t(item.triangles.first_triangle);
  for (size_t k = 0; k < 3 * size_t(item.triangles.triangles); ++k) out.push_back(item.mesh->positions[f[k]]);
  return out;
}

// A record's clusters are drawn as views into the record, decoded once: each item's range holds the
// cluster's own triangles (as the reader gives the cluster alone), ranges of the record's mesh; a record is
// kept, whole, while the cut draws any of its clusters, and its triangles are counted as held.
TEST(CutGeometry, DrawsClustersAsRangesOfTheirDecodedRecord) {
  GeometryPackage p(false, true);
  package::PackageReader reader = package::PackageReader::open(p.file),
                         alone = package::PackageReader::open(p.file);
  ReaderNodes all(reader);
  CutGeometry geometry(reader, {}, 0);
  const Cut fine = select_cut(reader.scene(), all, view_of({-1.0f, 0.5f, 1.0f}, {8.0f, 0.0f, 0.0f}), {0.5});
  std::map<uint64_t, uint64_t> triangles_of_record;  // by page and offset
  for (uint32_t id = 0; id < reader.node_count(); ++id)
    triangles_of_record[uint64_t(reader.node(id).page) << 32 | reader.node(id).offset] +=
        reader.node(id).triangles;
  std::set<uint64_t> records;
  for (uint32_t id : distinct_nodes(fine))
    records.insert(uint64_t(reader.node(id).page) << 32 | reader.node(id).offset);
  uint64_t record_triangles = 0;
  for (uint64_t r : records) record_triangles += triangles_of_record[r];
  EXPECT_EQ(geometry.update(fine, pages_from_reader(reader)), records.size());
  EXPECT_EQ(geometry.cached_records(), records.size());
  size_t in_records = 0;
  for (const CutItem& item : geometry.items()) {
    const package::NodeRecord& n = reader.node(item.node);
    const package::DecodedNode d = alone.load_node(item.node);
    std::vector<glm::vec3> expected;
    for (uint32_t v : d.mesh.indices) expected.push_back(d.mesh.positions[v]);
    EXPECT_EQ(corners(item), expected) << item.node;
    EXPECT_EQ(item.range, n.cluster);
    uint32_t first = 0;
    for (uint32_t c = 0; c < item.range; ++c) first += item.range_triangles[c];
    EXPECT_EQ(item.triangles.first_triangle, first);
    in_records += !item.range_triangles.empty();
  }
  EXPECT_GT(in_records, 2u);
  EXPECT_LT(records.size(), distinct_nodes(fine).size());  // some records draw both clusters
  EXPECT_EQ(geometry.held_triangles(), record_triangles);  // no idle record kept (budget 0)
}

// With no room for idle records, only the current cut's stay decoded (nodes of one cluster: a record each).
TEST(CutGeometry, DropsIdleMeshesBeyondTheBudget) {
  GeometryPackage p;
  package::PackageReader reader = package::PackageReader::open(p.file);
  ReaderNodes all(reader);
  CutGeometry geometry(reader, {}, 0);
  const Cut fine = select_cut(reader.scene(), all, view_of({-1.0f, 0.5f, 1.0f}, {8.0f, 0.0f, 0.0f}), {0.5});
  const Cut coarse =
      select_cut(reader.scene(), all, view_of({8.0f, 2.0f, 60.0f}, {18.0f, 0.0f, 0.0f}), {2.0});
  geometry.update(fine, pages_from_reader(reader));
  EXPECT_EQ(geometry.cached_records(), distinct_nodes(fine).size());
  geometry.update(coarse, pages_from_reader(reader));
  EXPECT_EQ(geometry.cached_records(), distinct_nodes(coarse).size());
}

// Nodes decoded into the buffers of evicted ones (fine, coarse, fine again with no room for idle meshes) come
// out as a fresh CutGeometry decodes them.
TEST(CutGeometry, DecodesIntoEvictedNodesBuffersAlike) {
  GeometryPackage p;
  package::PackageReader reader = package::PackageReader::open(p.file);
  ReaderNodes all(reader);
  CutGeometry recycling(reader, {}, 0), fresh(reader, {}, 0);
  const Cut fine = select_cut(reader.scene(), all, view_of({-1.0f, 0.5f, 1.0f}, {8.0f, 0.0f, 0.0f}), {0.5});
  const Cut coarse =
      select_cut(reader.scene(), all, view_of({8.0f, 2.0f, 60.0f}, {18.0f, 0.0f, 0.0f}), {2.0});
  for (const Cut* cut : {&fine, &coarse, &fine, &coarse}) recycling.update(*cut, pages_from_reader(reader));
  fresh.update(coarse, pages_from_reader(reader));
  ASSERT_EQ(recycling.items().size(), fresh.items().size());
  for (size_t i = 0; i < fresh.items().size(); ++i) {
    const Mesh &a = *recycling.items()[i].mesh, &b = *fresh.items()[i].mesh;
    EXPECT_EQ(a.indices, b.indices) << i;
    EXPECT_EQ(a.positions, b.positions) << i;
    EXPECT_EQ(a.normals, b.normals) << i;
    EXPECT_EQ(recycling.items()[i].material, fresh.items()[i].material) << i;
  }
}

// Pages from the client's cache, as transferred (stored) or unpacked; a drawn page that is not cached is an
// error naming it.
TEST(CutGeometry, ReadsPagesFromTheCache) {
  GeometryPackage p;
  package::PackageReader reader = package::PackageReader::open(p.file);
  for (uint32_t id = 0; id < reader.node_count(); ++id) reader.node(id);  // every index page
  const package::ContentHash hash = reader.header().content_hash;
  PageCache stored(1u << 20), unpacked(1u << 20);
  for (uint32_t page = 0; page < reader.root().pages.size(); ++page) {
    const package::Range& r = reader.root().pages[page];
    std::vector<uint8_t> bytes(r.size);
    reader.source().read(r.offset, bytes);
    stored.insert(hash, page, std::move(bytes));
    unpacked.insert(hash, page, reader.read_page(page));
  }
  PackageNodes nodes(reader, stored);
  const Cut cut = select_cut(reader.scene(), nodes, view_of({-1.0f, 0.5f, 1.0f}, {8.0f, 0.0f, 0.0f}), {0.5});
  ASSERT_TRUE(cut.converged());
  CutGeometry a(reader), b(reader), c(reader);
  a.update(cut, pages_from_cache(reader, stored, CachedPages::stored));
  b.update(cut, pages_from_cache(reader, unpacked, CachedPages::unpacked));
  c.update(cut, pages_from_reader(reader));
  ASSERT_EQ(a.items().size(), c.items().size());
  for (size_t i = 0; i < a.items().size(); ++i) {
    EXPECT_EQ(a.items()[i].mesh->positions, c.items()[i].mesh->positions);
    EXPECT_EQ(b.items()[i].mesh->indices, c.items()[i].mesh->indices);
  }
  PageCache empty(1u << 20);
  CutGeometry d(reader);
  try {
    d.update(cut, pages_from_cache(reader, empty, CachedPages::stored));
    FAIL() << "no error for a page that is not cached";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is drawn but not cached"), std::string::npos) << e.what();
  }
}

// An embedded texture is read in the constructor (`now`), or in the background from the first update that
// draws its material, the material untextured until then (`background`).
TEST(CutGeometry, ReadsEmbeddedTexturesNowOrInTheBackground) {
  GeometryPackage p(true);
  package::PackageReader reader = package::PackageReader::open(p.file);
  ReaderNodes all(reader);
  const Cut cut = select_cut(reader.scene(), all, view_of({-1.0f, 0.5f, 1.0f}, {8.0f, 0.0f, 0.0f}), {0.5});

  CutGeometry now(reader);
  ASSERT_NE(now.materials()[1].base_color_image, nullptr);
  EXPECT_EQ(now.materials()[1].base_color_image->width, 3);
  EXPECT_TRUE(now.materials()[1].base_color_texture.empty());
  EXPECT_EQ(now.materials()[0].base_color_image, nullptr);

  CutGeometry later(reader, {}, 2'000'000, TextureLoading::background);
  EXPECT_EQ(later.materials()[1].base_color_image, nullptr);
  EXPECT_EQ(later.textures_pending(), 0u);
  later.update(cut, pages_from_reader(reader));
  // The read runs on its own thread: poll (each update installs what has arrived).
  for (int i = 0; i < 1000 && later.textures_pending() > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    later.update(cut, pages_from_reader(reader));
  }
  EXPECT_EQ(later.textures_pending(), 0u);
  ASSERT_NE(later.materials()[1].base_color_image, nullptr);
  EXPECT_EQ(later.materials()[1].base_color_image->rgba, now.materials()[1].base_color_image->rgba);
  EXPECT_TRUE(later.warnings().empty());
}
