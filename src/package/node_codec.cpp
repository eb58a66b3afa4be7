#include "package/node_codec.hpp"

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/traversal_codec.hpp"

namespace lodstream::package {

// Codec 1 until codec 2 decodes at the 25 M triangles per second per core that DESIGN.md requires: codec 2
// stores 30 % fewer bytes but decodes at 0.6x codec 1's speed (bench_package, side by side, load 9: 20.7 vs
// 34.3 M tri/s with zstd). zstd costs both codecs about the same (8.4 / 8.8 ns per triangle); the gap is
// codec 2's own decode (40 vs 20 ns per triangle), over half of whose branch misses are the search for the
// triangle across the parallelogram's edge (callgrind --branch-sim).
const NodeCodec& default_node_codec() {
  return node_codec(MeshoptCodec::kId);
}

const NodeCodec& node_codec(uint32_t id) {
  static const MeshoptCodec meshopt;
  static const PredictiveCodec predictive;
  static const TraversalCodec traversal;
  if (id == MeshoptCodec::kId) return meshopt;
  if (id == PredictiveCodec::kId) return predictive;
  if (id == TraversalCodec::kId) return traversal;
  throw Error("unknown node codec id " + std::to_string(id));
}

}  // namespace lodstream::package
