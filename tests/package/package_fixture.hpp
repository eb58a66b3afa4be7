// A small multi-object package built in code for the package tests: two representations (a UV sphere with
// normals and UVs, a cube with seams and colours) cut into chunks of a few dozen triangles, one node per
// chunk (with codec 3, each page group of 3 sphere chunks is one record of 3 clusters, package/records.hpp,
// at its chunks' smallest shift), each chunk at its own position shift, with every vertex that two chunks
// share flagged as locked;
// three objects (two instances of the sphere). Written with small pages (2 KB raw for codec 1, 4 KB for codec
// 2, whose raw nodes are about twice as large) so that it has several data and index pages.
#pragma once

#include <filesystem>
#include <vector>

#include "core/mesh.hpp"
#include "package/writer.hpp"

namespace lodstream::test {

struct TestPackage {
  package::PackageScene scene;
  std::vector<package::NodeRecord> records;  // as given to the writer (page fields unset)
  std::vector<Mesh> meshes;                  // original geometry, one per node
  std::vector<std::vector<uint8_t>> locked;  // per node, per vertex
  std::vector<uint32_t> shifts;              // position shift per node
  uint32_t root_nodes = 0;
  size_t page_bytes = 0;  // the writer's raw page target
  package::WrittenPackage written;
};

// Nodes encoded with node codec `codec` (package/node_codec.hpp).
TestPackage write_test_package(const std::filesystem::path& file,
                               uint32_t codec = package::default_node_codec().id());

// Splits `mesh` into chunks of `triangles` consecutive triangles (compacted vertices); `locked` gets, per
// chunk vertex, whether another chunk holds a vertex at the same position.
std::vector<Mesh> split_into_chunks(const Mesh& mesh, size_t triangles,
                                    std::vector<std::vector<uint8_t>>& locked);

// A UV sphere (24 rings, 32 segments) whose vertices are moved along the surface by up to a third of an edge
// (random, from `seed`): irregular, but smooth, like a coarse level's clusters.
Mesh slid_sphere(uint32_t seed);

// Expects every position of `decoded` within `distance` of some position of `input` (a codec may reorder).
void expect_near_input(const Mesh& decoded, const Mesh& input, float distance);

}  // namespace lodstream::test
