#include "package/node_codec.hpp"

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/traversal_codec.hpp"

namespace lodstream::package {

// Codec 3: the smallest of the three, and above the 25 M triangles per second per core that DESIGN.md
// requires of decoding. Whole bakes store 23-31 % fewer bytes than with codec 1 (refined_elephant 9.93
// -> 6.68 B per input triangle, city 10.21 -> 7.84). bench_package (refined_elephant meshlets, finest level,
// zstd 9; idle machine, medians of 7), decode with checksum + zstd: codec 3 34.3 M tri/s, codec 1 37.4
// (0.92x); codec only 45.6 vs 51.9. Callgrind, instructions per decoded triangle: codec only 233 vs codec 1's
// 253, with checksum and zstd 326 vs 326; codec 1's SIMD decoders retire more per cycle, codec 3 pays a
// data-dependent branch per connectivity symbol and zstd's Huffman stage over its residual planes.
const NodeCodec& default_node_codec() {
  return node_codec(TraversalCodec::kId);
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
