// Records (node_codec.hpp, NodeGeometry::cluster_triangles): a page group's clusters stored as one node
// with one vertex pool, each cluster's triangles a consecutive range. A cluster alone stores its border
// vertices again and predicts them from half their fan; in a record, a vertex that several of its clusters
// hold is stored and predicted once. Measured (bake, codec 3, records of one precision): elephant_1m
// 6,542,992 -> 5,462,790 B (-16.5 %; stored vertices per level-0 triangle 0.653 -> 0.559), elephant_5m
// 26,432,899 -> 22,003,743 (4.64 -> 3.87 B per input triangle), refined_elephant 519,852 -> 424,956,
// motorBike 2,323,447 -> 2,034,070, bunny 446,246 -> 374,365. Decoding a record's clusters one by one costs
// 1.17x the instructions of decoding them as separate nodes (callgrind, bench_package argument 4 vs 3,
// decode_node: 307 vs 263 per triangle; 344 before the decoder placed triangles straight into their
// clusters' ranges and the extraction stopped value-initialising its copies): the extraction's remap and
// copies.
//
// weld_record builds a record from clusters; extract_cluster gives one cluster back from a decoded record,
// what the reader returns for a cluster's node id, so that a record is invisible above the package: the
// cluster's triangles with its vertices compacted (numbered in first-use order), the same DecodedNode as a
// node of one cluster. A vertex that several clusters share decodes once, so it is bit-identical in each.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "package/node_codec.hpp"

namespace lodstream::package {

struct RecordMesh {
  Mesh mesh;                                // the clusters' triangles in cluster order, welded vertices
  std::vector<uint8_t> locked;              // per vertex: locked in any cluster that holds it
  std::vector<uint32_t> cluster_triangles;  // per cluster (NodeGeometry::cluster_triangles)
};

// Welds `clusters` (meshes with the same attributes; `locked[c]` per vertex of cluster c, or empty) on
// identical vertices: same bits of position, normal, UV and colour, so seams stay split; record vertices in
// order of first appearance. Cost: O(V + T) expected (core/representatives.hpp over the clusters' vertices,
// 56 bytes of scratch per vertex).
RecordMesh weld_record(std::span<const Mesh* const> clusters,
                       std::span<const std::span<const uint8_t>> locked);

// The number of clusters of a decoded record (1 for a node of one cluster).
inline uint32_t record_clusters(const DecodedNode& record) {
  return record.cluster_triangles.empty() ? 1u : uint32_t(record.cluster_triangles.size());
}

// Cluster `cluster` of `record`; of a node of one cluster (progressive steps included), the node itself (a
// copy). Throws lodstream::Error starting with `where` when the record has no such cluster. Cost: O(the
// cluster's triangles and vertices) plus a per-thread table of the record's vertex count.
DecodedNode extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where);
// The same into `out` (not `record`), every field of which it overwrites, reusing out's buffers: a caller
// that extracts many clusters into one DecodedNode allocates its arrays once, where a DecodedNode per cluster
// cost three allocations and frees (indices, positions, normals) and a copy of each gathered array
// (`bench decode --runs 1` under callgrind, whole program: refined_elephant 89.63 -> 88.76 M instructions,
// elephant_1m 1,072.7 -> 1,056.3 M). out's arrays are resized without value-initialisation and the indices
// renumbered straight from the record's: ~8 instructions a corner and ~9 a vertex (extract_cluster under
// the same callgrind runs: refined_elephant 8.50 -> 6.66 -> 5.05 M, elephant_1m 136.1 -> 106.4 -> 80.4 M,
// motorBike 23.66 -> 17.94 M; records.cpp tells the steps).
void extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where, DecodedNode& out);
// The same with the cluster's first triangle given (the sum of the triangle counts of the clusters before it,
// which the form above finds with cluster_firsts, O(C) a call: O(C^2) over a record's C clusters, where the
// reader keeps them per record: the city's `bench decode --runs 1` under callgrind, extract_cluster 260.7 ->
// 257.4 M instructions, cluster_firsts 0.8 M). Throws lodstream::Error starting with `where` when the
// cluster's triangles would end past the record's; a first_triangle that is not the sum extracts other
// triangles of the record.
void extract_cluster(const DecodedNode& record, uint32_t cluster, size_t first_triangle,
                     const std::string& where, DecodedNode& out);

// firsts[c] = the first triangle of cluster c of `record` (0 for a node of one cluster),
// record_clusters(record) entries, in a buffer the caller keeps. Cost: O(C).
void cluster_firsts(const DecodedNode& record, std::vector<size_t>& firsts);

}  // namespace lodstream::package
