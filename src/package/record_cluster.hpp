// One cluster of a decoded record (node_codec.hpp, NodeGeometry::cluster_triangles): a page group's
// clusters stored as one node with one vertex pool, each cluster's triangles a consecutive range. What the
// reader returns for a cluster's node id, so that a record is invisible above the package: the cluster's
// triangles with its vertices compacted (numbered in first-use order), the same DecodedNode as a node of
// one cluster. A vertex that several clusters share decodes once, so it is bit-identical in each of them.
#pragma once

#include <cstdint>
#include <string>

#include "package/node_codec.hpp"

namespace lodstream::package {

// The number of clusters of a decoded record (1 for a node of one cluster).
inline uint32_t record_clusters(const DecodedNode& record) {
  return record.cluster_triangles.empty() ? 1u : uint32_t(record.cluster_triangles.size());
}

// Cluster `cluster` of `record`; of a node of one cluster (progressive steps included), the node itself (a
// copy). Throws lodstream::Error starting with `where` when the record has no such cluster. Cost: O(the
// cluster's triangles and vertices) plus a per-thread table of the record's vertex count.
DecodedNode extract_cluster(const DecodedNode& record, uint32_t cluster, const std::string& where);

}  // namespace lodstream::package
