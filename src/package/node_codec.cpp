#include "package/node_codec.hpp"

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/traversal_codec.hpp"

namespace lodstream::package {

// Codec 1 until a smaller codec decodes at the 25 M triangles per second per core that DESIGN.md requires.
// bench_package (refined_elephant meshlets, finest level, zstd 9): codec 1 4.48 B/tri, codec 2 3.15, codec 3
// 2.81; whole bakes: codec 3 stores 31 % fewer bytes than codec 1 (refined_elephant 9.92 -> 6.84 B per input
// triangle). Decode (checksum + zstd + codec), codec 3 at about 0.71-0.78x codec 1 in the same loaded runs
// (codec 2 about 0.6x); callgrind: 471 instructions per triangle vs codec 1's 326 (meshoptimizer's decoders
// are SIMD), of which the traversal 117 and the predicted normals about 175. Codec 3 is at the floor only if
// codec 1 decodes at 33 M/s or more on the machine at hand.
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
