#include "package_fixture.hpp"

#include "package/records.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include "package/meshopt_codec.hpp"
#include "package/records.hpp"
#include "support/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace lodstream::test {

using namespace package;

std::vector<Mesh> split_into_chunks(const Mesh& mesh, size_t triangles,
                                    std::vector<std::vector<uint8_t>>& locked) {
  std::vector<Mesh> chunks;
  using Key = std::tuple<float, float, float>;
  std::map<Key, std::set<size_t>> chunks_at;
  for (size_t first = 0; first < mesh.triangle_count(); first += triangles) {
    Mesh c;
    c.material = mesh.material;
    std::map<uint32_t, uint32_t> local;
    for (size_t t = first; t < std::min(first + triangles, mesh.triangle_count()); ++t) {
      for (int k = 0; k < 3; ++k) {
        uint32_t v = mesh.indices[3 * t + k];
        auto [it, fresh] = local.emplace(v, uint32_t(c.positions.size()));
        if (fresh) {
          c.positions.push_back(mesh.positions[v]);
          if (mesh.has_normals()) c.normals.push_back(mesh.normals[v]);
          if (mesh.has_uvs()) c.uvs.push_back(mesh.uvs[v]);
          if (mesh.has_colors()) c.colors.push_back(mesh.colors[v]);
          const glm::vec3& p = mesh.positions[v];
          chunks_at[{p.x, p.y, p.z}].insert(chunks.size());
        }
        c.indices.push_back(it->second);
      }
    }
    chunks.push_back(std::move(c));
  }
  locked.clear();
  for (const Mesh& c : chunks) {
    std::vector<uint8_t> flags;
    for (const glm::vec3& p : c.positions) flags.push_back(chunks_at[{p.x, p.y, p.z}].size() > 1);
    locked.push_back(std::move(flags));
  }
  return chunks;
}

TestPackage write_test_package(const std::filesystem::path& file, uint32_t codec) {
  TestPackage t;
  Mesh sphere = uv_sphere(2.0f, 12, 24);
  Mesh cube = cube_with_seams(3);
  cube.colors.clear();
  for (const glm::vec3& p : cube.positions) cube.colors.push_back(glm::vec4(p * 0.5f + 0.5f, 0.75f));
  cube.material = 1;

  t.scene.input_triangles = sphere.triangle_count() + cube.triangle_count();
  t.scene.metadata = R"({"test": true})";
  t.scene.materials.push_back(
      {Material{"skin", {0.8f, 0.7f, 0.6f, 1.0f}, "textures/skin.png", nullptr}, kNone});
  t.scene.materials.push_back(
      {Material{"crate", {0.5f, 0.5f, 0.5f, 1.0f}, "", nullptr}, 0});  // texture blob 0

  WriterOptions options;
  options.page_bytes = t.page_bytes = codec == MeshoptCodec::kId ? 2048 : 4096;
  options.codec = codec;
  options.nodes_per_index_page = 5;
  PackageWriter writer(file, options);
  const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 1, 2, 3, 4, 5};
  writer.add_blob(png);

  const Mesh* meshes[2] = {&sphere, &cube};
  for (uint32_t r = 0; r < 2; ++r) {
    Representation rep;
    rep.kind = r == 0 ? RepresentationKind::cluster_dag : RepresentationKind::progressive_mesh;
    rep.name = r == 0 ? "sphere" : "cube";
    rep.bounds = meshes[r]->bounds();
    rep.grid = PositionGrid::for_bounds(rep.bounds, 14);
    rep.levels = 4;
    std::vector<std::vector<uint8_t>> locked;
    std::vector<Mesh> chunks = split_into_chunks(*meshes[r], r == 0 ? 40 : 18, locked);
    const uint32_t first = uint32_t(t.records.size());
    // The sphere's page groups as records when the codec stores them (package/records.hpp).
    const bool records = r == 0 && node_codec(codec).max_record_clusters() >= 3;
    for (size_t i = 0; i < chunks.size(); ++i) {
      const uint32_t id = uint32_t(t.records.size());
      const uint32_t shift = uint32_t(i % 4);
      if (!records) {
        NodeGeometry g;
        g.mesh = &chunks[i];
        g.locked = locked[i];
        g.position_shift = shift;
        g.normal_bits = 12;
        writer.add_node(id, node_codec(codec).encode(g, rep.grid));
      } else if (i % 3 == 2 || i + 1 == chunks.size()) {  // the group's last chunk: its record
        const size_t group = i - i % 3;
        std::vector<const Mesh*> meshes;
        std::vector<std::span<const uint8_t>> group_locked;
        std::vector<uint32_t> ids;
        uint32_t smallest_shift = UINT32_MAX;
        for (size_t k = group; k <= i; ++k) {
          meshes.push_back(&chunks[k]), group_locked.push_back(locked[k]),
              ids.push_back(id - uint32_t(i - k));
          smallest_shift = std::min(smallest_shift, uint32_t(k % 4));
        }
        const RecordMesh record = weld_record(meshes, group_locked);
        NodeGeometry g;
        g.mesh = &record.mesh;
        g.locked = record.locked;
        g.position_shift = smallest_shift;
        g.normal_bits = 12;
        g.cluster_triangles = record.cluster_triangles;
        writer.add_record(ids, node_codec(codec).encode(g, rep.grid));
      }
      if (i % 3 == 2) writer.end_group();

      NodeRecord n;
      n.kind = (r == 0 && i == 0) ? NodeKind::hlod_proxy : NodeKind::cluster;
      n.representation = r;
      n.material = chunks[i].material;
      n.level = shift;
      n.triangles = uint32_t(chunks[i].triangle_count());
      Bounds b = chunks[i].bounds();
      n.sphere = {b.center(), 0.5f * b.diagonal()};
      n.error = 0.001f * float(shift);
      n.parent_error =
          i + 1 < chunks.size() ? 0.001f * float(shift + 1) : std::numeric_limits<float>::infinity();
      n.parent_sphere = {b.center(), b.diagonal()};
      if (i + 1 < chunks.size()) n.parents = {id + 1};
      if (i > 0) n.children = {id - 1, first};
      if (n.kind == NodeKind::hlod_proxy) n.objects = {0, 1};
      t.records.push_back(n);
      t.meshes.push_back(chunks[i]);
      t.locked.push_back(locked[i]);
      t.shifts.push_back(shift);
    }
    writer.end_group();
    rep.roots = {uint32_t(t.records.size() - 1)};
    t.scene.representations.push_back(rep);
  }
  t.scene.objects.push_back({"sphere_a", glm::mat4(1.0f), 0});
  glm::mat4 moved(1.0f);
  moved[3] = glm::vec4(5.0f, 0.0f, 0.0f, 1.0f);
  t.scene.objects.push_back({"sphere_b", moved, 0});
  t.scene.objects.push_back({"crate", glm::mat4(2.0f), 1});
  t.root_nodes = 3;
  t.written = writer.finish(t.scene, t.records, t.root_nodes);
  return t;
}

Mesh slid_sphere(uint32_t seed) {
  Mesh m = uv_sphere(1.0f, 24, 32);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-0.03f, 0.03f);
  for (glm::vec3& p : m.positions) {
    const glm::vec3 n = glm::normalize(p), move(d(rng), d(rng), d(rng));
    p = glm::normalize(p + move - glm::dot(move, n) * n);
  }
  return m;
}

void expect_near_input(const Mesh& decoded, const Mesh& input, float distance) {
  for (const glm::vec3& p : decoded.positions) {
    float nearest = INFINITY;
    for (const glm::vec3& q : input.positions) nearest = std::min(nearest, glm::length(p - q));
    EXPECT_LE(nearest, distance);
  }
}

}  // namespace lodstream::test
