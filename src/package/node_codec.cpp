#include "package/node_codec.hpp"

#include "core/error.hpp"
#include "package/meshopt_codec.hpp"
#include "package/predictive_codec.hpp"
#include "package/traversal_codec.hpp"

namespace lodstream::package {

// Codec 1 until a smaller codec decodes at the 25 M triangles per second per core that DESIGN.md requires.
// bench_package (refined_elephant meshlets, finest level, zstd 9): codec 1 4.48 B/tri, codec 2 3.15, codec 3
// 2.81; whole bakes: codec 3 stores 23-31 % fewer bytes than codec 1 (refined_elephant 9.96 -> 6.90 B per
// input triangle, city 10.21 -> 7.84). Decode (checksum + zstd + codec): codec 3 at 0.91x codec 1 in the same
// loaded run (codec only 0.93x). Callgrind, instructions per decoded triangle: codec only 233 vs codec 1's
// 253, with checksum and zstd 326 vs 326; codec 1's SIMD decoders retire more per cycle, codec 3 pays a
// data-dependent branch per connectivity symbol and zstd's Huffman stage over its residual planes (about 27 %
// more zstd work than codec 1's pages). Codec 3 is at the floor where codec 1 decodes at 27.5 M/s or more.
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
